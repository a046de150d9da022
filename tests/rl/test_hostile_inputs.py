"""Hostile inputs to ``train ppo`` (red team, issue 52): settings stable-baselines3 or
gymnasium would stop on are one line "error: ..." with exit status 2 before anything is
loaded or flown, the result never lands in (or replaces) the starting policy's folder, and a
killed run's scratch folder is cleared by the next run."""

from __future__ import annotations

import pytest

from gymfg_il.errors import ConfigError
from gymfg_il.rl.config import PPORunConfig
from gymfg_il.train import main

pytest.importorskip("stable_baselines3")


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
