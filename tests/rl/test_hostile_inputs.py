"""Hostile inputs to ``train ppo`` (red team, issue 52): settings stable-baselines3 or
gymnasium would stop on are one line "error: ..." with exit status 2 before anything is
loaded or flown, the result never lands in (or replaces) the starting policy's folder, and a
killed run's scratch folder is cleared by the next run."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest

from gymfg_il.errors import ConfigError
from gymfg_il.rl.config import PPORunConfig
from gymfg_il.train import main

pytest.importorskip("stable_baselines3")

ROOT = Path(__file__).resolve().parents[2]
KILL_DEADLINE_S = 300  # a loaded 2-core machine imports torch slowly; only a failure waits


def one_error(capsys, *needles):
    err = capsys.readouterr().err
    assert "Traceback" not in err and err.startswith("error: "), err
    for needle in needles:
        assert needle in err, err


@pytest.fixture
def nothing_loaded(monkeypatch):
    """Fails the test if the run gets as far as loading its starting policy."""

    def loaded(cfg):
        raise AssertionError(f"the run loaded {cfg.init} before refusing")

    monkeypatch.setattr("gymfg_il.rl.start.starting_policy", loaded)


@pytest.fixture
def nothing_flown(monkeypatch):
    """Fails the test if the run gets as far as its first evaluation."""
    from gymfg_il.rl.judge import Judge

    def flown(*args, **kwargs):
        raise AssertionError("an evaluation began before the run was refused")

    monkeypatch.setattr(Judge, "__init__", flown)


def _ppo(bc_policy, out, *more):
    return ["ppo", "--init", str(bc_policy), "--out", str(out), "--no-progress", *more]


@pytest.mark.parametrize(
    ("flags", "needle"),
    [
        (["--rollout-steps", "1", "--envs", "1"], "rollout_steps=1 x envs=1 is a rollout of 1"),
        (["--envs", "3", "--rollout-steps", "100"], "batch_size=512 must divide a rollout"),
    ],
)
def test_a_rollout_stable_baselines3_refuses_is_refused_first(
    bc_policy, tmp_path, capsys, nothing_loaded, flags, needle
):
    assert main(_ppo(bc_policy, tmp_path / "ppo", *flags)) == 2
    one_error(capsys, needle, "give --")
    assert not (tmp_path / "ppo").exists()


def test_the_batch_must_divide_the_rollout(bc_policy):
    with pytest.raises(ConfigError, match=r"batch_size=512 .* 300 samples .* --batch-size 300"):
        PPORunConfig(init=bc_policy, envs=3, rollout_steps=100)
    with pytest.raises(ConfigError, match=r"batch_size=64 .* 300 samples .* --batch-size 60"):
        PPORunConfig(init=bc_policy, envs=3, rollout_steps=100, batch_size=64)
    with pytest.raises(ConfigError, match=r"rollout of 1 sample; .* --rollout-steps 2"):
        PPORunConfig(init=bc_policy, envs=1, rollout_steps=1, batch_size=2)
    assert PPORunConfig(init=bc_policy, envs=3, rollout_steps=100, batch_size=60).rollout == 300
    assert PPORunConfig(init=bc_policy, envs=2, rollout_steps=1, batch_size=2).rollout == 2


LAST = 2**32 - 1  # the largest seed


@pytest.mark.parametrize(
    ("flags", "needle"),
    [
        (["--seed", "-1"], "seed=-1"),
        (["--eval-seed", "-1"], "eval_seed=-1"),
        (["--seed", str(2**32)], f"seed={2**32}"),
        (["--eval-seed", str(2**32)], f"eval_seed={2**32}"),
        # the envs' and the held-out episodes' seeds follow the first
        (["--seed", str(LAST), "--envs", "2"], f"env 1 starts from seed {2**32}"),
        (["--eval-seed", str(LAST), "--keep", "last", "--eval-episodes", "2"], "episode 1 has"),
        (["--eval-seed", str(LAST - 2)], f"episode 63 has seed {2**32 + 60}"),  # 64 to choose on
    ],
)
def test_every_seed_is_held_to_the_seed_rule(
    bc_policy, tmp_path, capsys, nothing_loaded, flags, needle
):
    assert main(_ppo(bc_policy, tmp_path / "ppo", *flags)) == 2
    one_error(capsys, needle, "0 <= seed < 2**32")


def test_the_last_seeds_are_taken(bc_policy):
    cfg = PPORunConfig(init=bc_policy, seed=LAST - 1, envs=2, eval_seed=LAST - 63)
    assert (cfg.seed + cfg.n_envs - 1, cfg.eval_seed + cfg.chosen_on - 1) == (LAST, LAST)


def _inside(bc_policy, tmp_path, layout):
    """(init, out) laid out as ``layout`` says, the starting policy a copy of ``bc_policy``."""
    if layout == "init inside out":  # a step checkpoint of an earlier run to the same out
        init, out = tmp_path / "run/checkpoints/step-0", tmp_path / "run"
    else:
        init = tmp_path / "bc"
        out = {"same": init, "out inside init": init / "ppo", "a link to init": tmp_path / "link"}
        out = out[layout]
    shutil.copytree(bc_policy, init)
    if layout == "a link to init":
        out.symlink_to(init, target_is_directory=True)
    return init, out


@pytest.mark.parametrize("layout", ["same", "out inside init", "a link to init", "init inside out"])
def test_out_never_lands_in_or_over_the_starting_policy(
    bc_policy, tmp_path, capsys, nothing_flown, layout
):
    init, out = _inside(bc_policy, tmp_path, layout)
    before = {p.name: p.read_bytes() for p in init.iterdir()}
    flags = ["--steps", "64", "--envs", "1", "--rollout-steps", "64", "--batch-size", "64"]
    assert main(_ppo(init, out, *flags)) == 2
    inside = "--init" if layout == "init inside out" else "--out"
    one_error(capsys, inside, "give an --out")
    assert {p.name: p.read_bytes() for p in init.iterdir()} == before
    assert [p.name for p in tmp_path.glob(".*")] == []  # no staging folder either


def test_the_default_out_is_held_apart_too(bc_policy, tmp_path, monkeypatch, nothing_flown):
    from gymfg_il.rl.run import train_ppo

    shutil.copytree(bc_policy, tmp_path / "bc")
    monkeypatch.chdir(tmp_path / "bc")  # the default out, policies/ppo-..., lies inside it
    cfg = PPORunConfig(
        init=Path("."), steps=64, envs=1, rollout_steps=64, batch_size=64, critic_warmup=0
    )
    with pytest.raises(ConfigError, match=r"--out policies/ppo-altitude-c172p lies inside"):
        train_ppo(cfg)
    assert not (tmp_path / "bc/policies").exists()


def _scratch(where):
    return sorted(where.glob("gymfg-ppo-*"))


def _kill_when_scratched(argv, tmp):
    """Start ``train ppo`` with its temp folder in ``tmp``; SIGKILL it (and its env and
    evaluation processes) once its scratch folder holds a file; the scratch folder."""
    env = {**os.environ, "TMPDIR": str(tmp), "HF_HUB_OFFLINE": "1", "SDL_VIDEODRIVER": "dummy"}
    run = subprocess.Popen(
        [sys.executable, "-m", "gymfg_il.train", *argv],
        cwd=ROOT,  # this checkout's gymfg_il
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        start_new_session=True,  # its own process group, killed whole
    )
    deadline = time.monotonic() + KILL_DEADLINE_S
    try:
        while not any(p.is_file() for d in _scratch(tmp) for p in d.rglob("*")):
            assert run.poll() is None, run.communicate()[1].decode()[-2000:]
            assert time.monotonic() < deadline, "the run never wrote to its scratch folder"
            time.sleep(0.05)  # polls a subprocess's progress: no event to wait on
    finally:
        os.killpg(run.pid, signal.SIGKILL)
        run.communicate()
    return _scratch(tmp)


@pytest.mark.slow
def test_a_killed_runs_scratch_folder_is_cleared_by_the_next_run(bc_policy, tmp_path, monkeypatch):
    from gymfg_il.rl.run import train_ppo

    tmp = tmp_path / "tmp"
    tmp.mkdir()
    tiny = ["--envs", "1", "--rollout-steps", "64", "--batch-size", "64", "--eval-episodes", "1"]
    tiny += ["--select-episodes", "1", "--eval-every", "64", "--checkpoints"]
    argv = ["ppo", "--init", str(bc_policy), "--out", str(tmp_path / "a"), "--steps", "100000"]
    left = _kill_when_scratched([*argv, *tiny], tmp)
    assert len(left) == 1 and list(left[0].rglob("*"))  # what the kill leaves, with files in it
    live = subprocess.Popen(["sleep", "600"])  # a run still going (its pid's process lives)
    try:
        kept = [tmp / f"gymfg-ppo-{live.pid}-live", tmp / "gymfg-ppo-others", tmp / "notes"]
        for folder in kept:
            folder.mkdir()
        monkeypatch.setattr(tempfile, "tempdir", str(tmp))  # this process's temp folder
        cfg = PPORunConfig(
            init=bc_policy, out=tmp_path / "b", steps=64, envs=1, rollout_steps=64,
            batch_size=64, eval_episodes=1, select_episodes=1, eval_every=64, critic_warmup=0,
        )  # fmt: skip
        train_ppo(cfg)
        assert (tmp_path / "b/config.json").is_file()
        assert _scratch(tmp) == sorted(kept[:2]) and kept[2].is_dir()  # the killed run's went
    finally:
        live.kill()
        live.wait()


def test_only_the_folders_of_dead_runs_are_cleared(tmp_path):
    from gymfg_il.rl.folders import clear_killed_runs

    gone = subprocess.Popen(["true"])
    gone.wait()  # a pid whose process has ended
    dead = tmp_path / f"gymfg-ppo-{gone.pid}-dead"
    (dead / "tensorboard").mkdir(parents=True)
    (dead / "tensorboard/events").write_text("x")
    target = tmp_path / "elsewhere"
    target.mkdir()
    link, file = tmp_path / f"gymfg-ppo-{gone.pid}-link", tmp_path / f"gymfg-ppo-{gone.pid}-file"
    link.symlink_to(target, target_is_directory=True)
    file.write_text("not a folder")
    mine, odd = tmp_path / f"gymfg-ppo-{os.getpid()}-mine", tmp_path / "gymfg-ppo-12x-odd"
    for folder in (mine, odd):
        folder.mkdir()
    assert clear_killed_runs(tmp_path) == [dead]
    assert sorted(tmp_path.iterdir()) == sorted([target, link, file, mine, odd])
