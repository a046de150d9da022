"""The collect command, driven as a user would: real processes, real files, real kills."""

import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from gymfg_il import collect
from gymfg_il.collectors.config import CollectConfig
from gymfg_il.envs import FlightSpec
from gymfg_il.errors import ConfigError

ENV = {**os.environ, "HF_HUB_OFFLINE": "1", "PYTHONUNBUFFERED": "1"}


@pytest.mark.slow
def test_recipe_runs_and_options_override(tmp_path, capsys):
    recipe = tmp_path / "r.toml"
    recipe.write_text(
        '[collector]\ntask = "pitch"\nepisodes = 5\nepisode_time_s = 10.0\n'
        f'out = "{tmp_path / "from-recipe"}"\n'
    )
    assert collect.main([str(recipe), "--episodes", "2", "--no-progress"]) == 0
    out = capsys.readouterr().out
    assert "dataset" in out and "2 episodes" in out
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    ds = LeRobotDataset("x/y", root=tmp_path / "from-recipe" / "dataset")
    assert ds.num_episodes == 2 and ds.fps == 10


def test_bundled_recipes_are_valid():
    from pathlib import Path

    recipes = sorted(Path(__file__).resolve().parents[2].glob("collectors/*.toml"))
    assert recipes
    for path in recipes:
        assert CollectConfig.from_recipe(path).episodes >= 1


@pytest.mark.parametrize(
    "text, match",
    [
        ("[collector]\ntask = 'altitud'\n", "unknown task"),
        ("[collector]\nagent_hz = 7\n", "agent_hz=7"),
        ("[collector]\nepisodes = 0\nnoise = -1\n", "2 problems"),
        ("[collector]\ncolour = 'red'\n", "unknown keys"),
        ("collector = 3\n", "no \\[collector\\] table"),
        ("[collector\n", "not valid TOML"),
    ],
)
def test_bad_recipes_say_what_is_wrong(tmp_path, text, match):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(ConfigError, match=match):
        CollectConfig.from_recipe(path)


def test_recover_of_missing_or_foreign_folders(tmp_path, capsys):
    assert collect.main(["recover", str(tmp_path / "nope")]) == 2
    (tmp_path / "foreign").mkdir()
    (tmp_path / "foreign" / "notes.txt").write_text("mine")
    assert collect.main(["recover", str(tmp_path / "foreign")]) == 2
    err = capsys.readouterr().err
    assert "nothing to recover" in err
    assert (
        collect.main(
            ["autopilot", "--out", str(tmp_path / "foreign"), "--episodes", "1", "--no-progress"]
        )
        == 2
    )
    assert "not a collection session" in capsys.readouterr().err
    assert sorted(p.name for p in (tmp_path / "foreign").iterdir()) == ["notes.txt"]


def test_corrupt_log_is_a_clear_error(tmp_path, capsys):
    (tmp_path / "logs").mkdir()
    (tmp_path / "logs" / "session-x.mcap").write_bytes(os.urandom(4000))
    assert collect.main(["recover", str(tmp_path)]) == 2
    assert "not a readable GymFG trajectory log" in capsys.readouterr().err


@pytest.mark.slow
def test_sigkill_at_random_moments_loses_no_completed_episode(tmp_path):
    """Kill real collector processes at random moments; recover must keep every episode the
    collector reported as saved (it reports only after the episode is durable)."""
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    rng = np.random.default_rng(12345)
    out = tmp_path / "session"
    reported_total = 0
    for trial in range(3):
        cmd = [
            sys.executable,
            "-m",
            "gymfg_il.collect",
            "autopilot",
            "--out",
            str(out),
            "--episodes",
            "40",
            "--episode-time",
            "10",
            "--seed",
            str(100 * trial),
            "--no-progress",
        ]
        with open(tmp_path / f"stdout{trial}", "w") as stdout:
            proc = subprocess.Popen(cmd, stdout=stdout, stderr=subprocess.DEVNULL, env=ENV)
            time.sleep(float(rng.uniform(1.5, 4.0)))
            proc.send_signal(signal.SIGKILL)
            proc.wait()
        reported = (tmp_path / f"stdout{trial}").read_text().count("saved")
        reported_total += reported
        assert collect.main(["recover", str(out)]) == 0
        ds = LeRobotDataset("x/y", root=out / "dataset")
        assert ds.num_episodes >= reported_total  # nothing reported as saved was lost
        assert len(ds) == ds.num_episodes * 100
    assert reported_total > 0
    assert not list(tmp_path.glob("session/dataset.*"))  # no half-built copies left behind


def test_replay_into_a_view_sends_every_step_and_checks_every_state(tmp_path, capsys):
    import socket

    out = tmp_path / "session"
    argv = ["autopilot", "--out", str(out), "--episodes", "1", "--episode-time", "2"]
    assert collect.main([*argv, "--no-progress"]) == 0
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as view:
        view.bind(("127.0.0.1", 0))
        port = view.getsockname()[1]
        assert collect.main(["replay", str(out), "--view", str(port)]) == 0
        view.settimeout(0.5)
        packets = []
        while True:
            try:
                packets.append(view.recv(2048))
            except TimeoutError:
                break
    assert "ego: 20 steps, identical" in capsys.readouterr().out
    assert len(packets) == 21 and {len(p) for p in packets} == {408}  # the reset, then 20 steps


def test_a_recipe_is_an_autopilot_or_a_manual_config(tmp_path):
    from pathlib import Path

    from gymfg_il.collectors.config import ManualConfig

    recipes = Path(__file__).resolve().parents[2] / "collectors"
    manual = CollectConfig.from_recipe(recipes / "manual-keyboard.toml")
    assert isinstance(manual, ManualConfig) and manual.keyboard["rate"] == 1.5
    assert manual.flight() == FlightSpec.solo("c172p", "altitude", agent_hz=30)
    auto = CollectConfig.from_recipe(recipes / "sample.toml")
    assert type(auto) is CollectConfig and auto.flight().task_kwargs["target_range"]
    path = tmp_path / "r.toml"
    path.write_text('[collector]\ntask = "roll"\ndevice = "mouse"\n')
    with pytest.raises(ConfigError, match=r"unknown keys \['device'\] \(manual sessions only"):
        CollectConfig.from_recipe(path)
    path.write_text('[collector]\nkind = "human"\n')
    with pytest.raises(ConfigError, match="kind='human': choose autopilot or manual"):
        CollectConfig.from_recipe(path)


def test_recipe_overrides_take_each_kind_its_own_flags(capsys):
    from pathlib import Path

    recipes = Path(__file__).resolve().parents[2] / "collectors"
    args = collect.parse_args([str(recipes / "manual-keyboard.toml"), "--fps", "10"])
    assert args.agent_hz == 10 and "noise" not in vars(args) and "gusts" not in vars(args)
    assert collect.main([str(recipes / "sample.toml"), "--device", "mouse"]) == 2
    assert "apply to manual recipes" in capsys.readouterr().err
    assert collect.main([str(recipes / "manual-keyboard.toml"), "--workers", "2"]) == 2
    assert "apply to autopilot recipes" in capsys.readouterr().err
    # a person is not perturbed: --noise is the synthetic pilot's (tests/collectors/
    # test_recoveries.py flies it)
    assert collect.main([str(recipes / "manual-keyboard.toml"), "--noise", "0.1"]) == 2
    assert "add --pilot synthetic" in capsys.readouterr().err


def test_running_a_recipe_again_remakes_its_dataset_instead_of_doubling_it(tmp_path, capsys):
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    recipe = tmp_path / "r.toml"
    out = tmp_path / "s"
    recipe.write_text(
        f'[collector]\ntask = "roll"\nepisodes = 2\nepisode_time_s = 3.0\nout = "{out}"\n'
    )
    assert collect.main([str(recipe), "--no-progress"]) == 0
    assert collect.main([str(recipe), "--no-progress"]) == 0
    assert "nothing to fly" in capsys.readouterr().out
    assert LeRobotDataset("x/y", root=tmp_path / "s" / "dataset").num_episodes == 2
    assert collect.main([str(recipe), "--episodes", "3", "--no-progress"]) == 0  # one more
    assert LeRobotDataset("x/y", root=tmp_path / "s" / "dataset").num_episodes == 3


def test_a_dataset_made_at_another_noise_is_named_before_its_seeds_fly_again(tmp_path, caplog):
    # the heading's own noise was 0.1 before 2026-11-29: the same command now flies at 0.2
    base = ["autopilot", "--task", "heading", "--episodes", "1", "--episode-time", "2"]
    base += ["--out", str(tmp_path / "s"), "--no-progress"]
    assert collect.main([*base, "--noise", "0.1"]) == 0
    caplog.clear()
    assert collect.main([*base, "--noise", "0.1"]) == 0  # the same: nothing flies, no warning
    assert "flown with noise" not in caplog.text
    assert collect.main(base) == 0
    assert "flown with noise 0.1; these fly with 0.2 (the task's own)" in caplog.text
    assert "pass --noise 0.1 to re-make those instead" in caplog.text


def test_an_untrimmed_dataset_takes_no_trimmed_episodes(tmp_path):
    from gymfg_il.collectors.session import check_appendable
    from gymfg_il.envs import FlightSpec
    from gymfg_il.errors import ConfigError

    out = tmp_path / "s"
    argv = ["autopilot", "--task", "roll", "--episodes", "1", "--episode-time", "2"]
    assert collect.main([*argv, "--out", str(out), "--no-progress"]) == 0
    trimmed = FlightSpec.solo("c172p", "roll")
    names = trimmed.build_teams()[0].roster[0][1]().observation_names
    check_appendable(out, names, 10, trimmed)  # the same flight: fine
    with pytest.raises(ConfigError, match=r"trimmed starts.*new --out"):
        check_appendable(out, names, 10, trimmed.replace(trimmed_starts=False))
