"""The web protocol's checks and the invites, without a server."""

from __future__ import annotations

import re
import stat

import pytest

from gymfg_il.errors import ConfigError
from gymfg_il.manual.bindings import KeyboardBindings
from gymfg_il.manual.synthetic import key_codes
from gymfg_il.web.invites import SEED_BLOCK, find, invites, names_from
from gymfg_il.web.protocol import (
    KEYS,
    MAX_RATE_HZ,
    ProtocolError,
    RateLimit,
    decode,
    hello,
    inputs,
)


def test_every_key_a_page_may_send_is_a_pygame_key_and_every_default_binding_is_allowed():
    assert set(key_codes()) >= KEYS
    bound = KeyboardBindings()
    for name in ("aileron_left", "elevator_down", "rudder_right", "throttle_up", "trim_nose_up",
                 "trim_rudder_left", "center"):  # fmt: skip
        assert set(getattr(bound, name)) <= KEYS, name


def test_a_good_input_parses_into_checked_events():
    message = decode(
        b'{"type": "input", "seq": 3, "at": 12.5, "frame": 7, "events": [["down", "page up"],'
        b' ["mouse", 450, 350.5], ["pad", 1], ["axis", 2, -0.25], ["button", 4, 1]]}'
    )
    parsed = inputs(message, 2)
    assert (parsed.seq, parsed.at, parsed.frame) == (3, 12.5, 7)
    assert parsed.events == (
        ("down", "page up"), ("mouse", 450.0, 350.5), ("pad", 1), ("axis", 2, -0.25),
        ("button", 4, 1),
    )  # fmt: skip
    with pytest.raises(ProtocolError, match="seq"):
        inputs(message, 3)  # the same number again


def test_hello_names_its_device_and_refuses_a_token_of_the_wrong_shape():
    assert hello({"type": "hello", "invite": "a" * 32}).device == "keyboard"
    with pytest.raises(ProtocolError, match="device"):
        hello({"type": "hello", "invite": "a" * 32, "device": "wheel"})
    with pytest.raises(ProtocolError, match="no such invite"):
        hello({"type": "hello", "invite": "a/b" * 10})
    with pytest.raises(ProtocolError, match="unknown field"):
        hello({"type": "hello", "invite": "a" * 32, "path": "/etc"})


def test_the_rate_limit_allows_a_second_of_burst_then_the_rate():
    limit = RateLimit()
    for _ in range(MAX_RATE_HZ):
        limit.take(0.0)
    with pytest.raises(ProtocolError, match="messages a second"):
        limit.take(0.0)
    limit = RateLimit()
    for k in range(10 * MAX_RATE_HZ):  # at the rate: never refused
        limit.take(k / MAX_RATE_HZ)


def test_invites_are_kept_private_and_the_same_on_a_second_start(tmp_path):
    names = tmp_path / "pilots.txt"
    names.write_text("Ada  # the first\n\nGrace\n")
    made = invites(tmp_path / "out", names_from(names), 100)
    assert [(i.name, i.seed) for i in made] == [("Ada", 100), ("Grace", 100 + SEED_BLOCK)]
    path = tmp_path / "out" / "invites.json"
    assert stat.S_IMODE(path.stat().st_mode) == 0o600
    again = invites(tmp_path / "out", ["Ada", "Grace"], 100)
    assert [i.token for i in again] == [i.token for i in made]
    assert find(again, made[1].token) == again[1] and find(again, "x" * 32) is None
    assert made[0].link("http://h:1") == f"http://h:1/fly#invite={made[0].token}"


@pytest.mark.parametrize(
    "text, said",
    [("", "no names"), ("Ada\nAda\n", "named twice"), ("a|b\n", "'|'"), ("x" * 300, "characters")],
)
def test_a_bad_invites_file_is_refused_with_what_is_wrong(tmp_path, text, said):
    path = tmp_path / "pilots.txt"
    path.write_text(text)
    with pytest.raises(ConfigError, match=said):
        names_from(path)


@pytest.mark.parametrize(
    "field, value, said",
    [("pilots", 0, "pilots=0"), ("port", 70000, "port=70000"), ("host", "", "host=''"),
     ("noise", 0.1, "not perturbed")],
)  # fmt: skip
def test_a_web_config_names_what_is_wrong_and_the_fix(tmp_path, field, value, said):
    from gymfg_il.web.config import WebConfig

    with pytest.raises(ConfigError, match=re.escape(said)):
        WebConfig(out=tmp_path, **{field: value})


def test_sessions_checking_one_folder_at_once_never_refuse_one_another(tmp_path):
    """Eight pilots' sessions start together on one folder: each one's write check (a file
    of a moment) is neither another's nor a foreign file to another."""
    import threading

    from gymfg_il.collectors.session import check_out_folder

    failures: list[Exception] = []

    def check() -> None:
        for _ in range(200):
            try:
                check_out_folder(tmp_path)
            except Exception as err:  # collected, asserted below
                failures.append(err)

    threads = [threading.Thread(target=check) for _ in range(8)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not failures, failures[:3]
    (tmp_path / "notes.txt").write_text("mine")
    with pytest.raises(ConfigError, match=r"notes\.txt"):
        check_out_folder(tmp_path)
