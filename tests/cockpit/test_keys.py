"""#53: every key a person uses (the session's and the flying keys of the keyboard bindings,
and what the mouse and a joystick do) is in ``collect manual --help`` and in the manual
guide's table, both built from the bindings (``cockpit.inputs.keys``), so neither drifts."""

from __future__ import annotations

import argparse
import dataclasses
import re
from pathlib import Path

import pytest

from gymfg_il import collect
from gymfg_il.cockpit.inputs.keys import COMMAND_KEYS, key_label, keys_help, keys_markdown
from gymfg_il.manual.bindings import JoystickBindings, KeyboardBindings

GUIDE = Path(__file__).resolve().parents[2] / "docs/guides/manual.md"
# the keys a newcomer looked for and did not find (#53), as the help and the guide name them
LOOKED_FOR = ("Up arrow", "Left arrow", "Page Up", "Page Down", "Home", "End", "Insert", "Delete")


def bound_keys(kb: KeyboardBindings) -> dict[str, list[str]]:
    """Every key list of the keyboard bindings, by field, and the session's keys."""
    keys = {f.name: getattr(kb, f.name) for f in dataclasses.fields(kb)}
    keys = {name: value for name, value in keys.items() if isinstance(value, list)}
    for key, command in COMMAND_KEYS.items():
        keys.setdefault(command, []).append(key)
    return keys


def manual_help(monkeypatch) -> str:
    class Parsed(Exception):
        pass

    def grab(self, args=None, namespace=None):
        if self.prog.endswith(" manual"):
            raise Parsed(self.format_help())
        return original(self, args, namespace)

    original = argparse.ArgumentParser.parse_known_args
    monkeypatch.setattr(argparse.ArgumentParser, "parse_known_args", grab)
    with pytest.raises(Parsed) as parsed:
        collect.main(["manual", "--help"])
    return str(parsed.value)


def guide_table() -> str:
    """The table under the guide's "Keys" heading: its first run of table lines."""
    lines = GUIDE.read_text().split("\n## Keys\n", 1)[1].splitlines()
    first = next(i for i, line in enumerate(lines) if line.startswith("|"))
    end = next(i for i in range(first, len(lines)) if not lines[i].startswith("|"))
    return "".join(line + "\n" for line in lines[first:end])


def test_key_names_read_as_on_the_keyboard():
    names = ["[4]", "enter", "up", "page up", "home", "delete", "escape", "f1", ",", "e"]
    labels = ["keypad 4", "keypad Enter", "Up arrow", "Page Up", "Home", "Delete", "Esc", "F1"]
    assert [key_label(n) for n in names] == [*labels, ",", "E"]


def test_every_bound_key_and_device_is_in_collect_manual_help(monkeypatch):
    text = manual_help(monkeypatch)
    flat = " ".join(text.split())
    for looked_for in LOOKED_FOR:
        assert re.search(rf"\b{looked_for}\b", text), looked_for
    missing = {
        field: [key_label(k) for k in keys if key_label(k) not in flat]
        for field, keys in bound_keys(KeyboardBindings()).items()
    }
    assert not {field: keys for field, keys in missing.items() if keys}, text
    for thing in ("mouse pointer", "joystick axes", "FlightGear's cockpit"):
        assert thing in flat
    for button in JoystickBindings().buttons:
        assert f"joystick button {button}" in flat
    assert keys_help() in text  # all of it, built from the bindings


def test_the_help_follows_rebound_keys():
    text = keys_help(KeyboardBindings(throttle_up=["w"], trim_nose_down=["[+]"]))
    assert re.search(r"^ +W +throttle up", text, re.M)
    assert re.search(r"^ +keypad \+ +elevator trim, nose down", text, re.M)
    assert "Page Up" not in text


def test_the_guide_holds_the_bindings_key_table():
    table = guide_table()
    for field, keys in bound_keys(KeyboardBindings()).items():
        for key in keys:
            assert f"`{key_label(key)}`" in table, f"{field}: {key} is not in the guide's table"
    assert table == keys_markdown(), (
        "docs/guides/manual.md's keys table differs from the bindings: replace it with "
        "python -c 'from gymfg_il.cockpit.inputs.keys import keys_markdown; "
        "print(keys_markdown())'"
    )
