"""``train ppo``'s settings: the flight options as every command takes them, PPO's own from
``hyperparams.toml`` per task, a run whose actor would never learn refused, and a start line
that says what the run will do."""

from __future__ import annotations

import pytest

from gymfg_il.errors import ConfigError
from gymfg_il.rl import hyperparams
from gymfg_il.rl.config import PPORunConfig
from gymfg_il.train import ppo_plan

pytest.importorskip("stable_baselines3")


def test_from_scratch_every_flight_option_is_the_runs(monkeypatch):
    from gymfg_il.rl import start

    monkeypatch.setattr(start, "SCRATCH_SEEDS", (0,))  # one controller flight: quicker
    cfg = PPORunConfig(
        task="heading", aircraft="c172p", dynamic=True, episode_time_s=20.0, agent_hz=20,
        turbulence="light", wind_kt=5.0, hidden=[16],
    )  # fmt: skip
    flight = start.starting_policy(cfg).flight
    assert (flight.task, flight.aircraft, flight.dynamic) == ("heading", "c172p", True)
    assert (flight.episode_time_s, flight.agent_hz) == (20.0, 20)
    assert (flight.turbulence, flight.wind_kt) == ("light", 5.0)


def test_a_fine_tune_flies_the_policys_flight_with_the_options_given(bc_policy):
    from gymfg_il.rl.start import starting_policy

    own = starting_policy(PPORunConfig(init=bc_policy))
    assert own.notes == [] and own.flight.episode_time_s == 30.0  # the demonstrations'
    changed = starting_policy(
        PPORunConfig(init=bc_policy, episode_time_s=45.0, turbulence="moderate", task="altitude")
    )
    assert changed.flight == own.flight.replace(episode_time_s=45.0, turbulence="moderate")
    assert [n.split("; ")[1] for n in changed.notes] == [
        "training it with episode_time_s=45.0 as asked",
        "training it with turbulence='moderate' as asked",
    ]  # the task asked is its own: no note
    moving = starting_policy(PPORunConfig(init=bc_policy, dynamic=True))  # the same variables
    assert moving.flight.dynamic and moving.module.n_obs == own.module.n_obs


def test_a_flight_observed_otherwise_than_the_policy_is_refused(bc_policy):
    from gymfg_il.rl.start import _check_observation, starting_policy

    start = starting_policy(PPORunConfig(init=bc_policy))
    names = list(start.meta["observation_names"])
    _check_observation(PPORunConfig(init=bc_policy), start.flight, start.meta)  # its own
    other = {**start.meta, "observation_names": names[:-1]}
    with pytest.raises(ConfigError, match=rf"observes {len(names) - 1} variables .* asked obs"):
        _check_observation(PPORunConfig(init=bc_policy), start.flight, other)


def test_a_run_whose_actor_would_never_learn_is_refused(bc_policy):
    # 8 envs x 512: a rollout of 4,096 steps; the critic warms up over the first rollout
    with pytest.raises(
        ConfigError, match=r"steps=4,096: the actor would never learn.*--steps 8,192"
    ):
        PPORunConfig(init=bc_policy, envs=8, steps=4096)
    with pytest.raises(ConfigError, match=r"--steps 40,960 or more, or a shorter --critic-warmup"):
        PPORunConfig(init=bc_policy, envs=8, steps=30_000, critic_warmup=35_000)
    cfg = PPORunConfig(init=bc_policy, envs=8, steps=8192)
    assert (cfg.warmup_steps, cfg.actor_steps, cfg.least_steps()) == (4096, 4096, 8192)
    assert PPORunConfig(init=bc_policy, envs=8, steps=4096, critic_warmup=0).actor_steps == 4096
    # the default: a tenth of the run, at most 20,000 steps; the actor learns from the rest
    long = PPORunConfig(init=bc_policy, envs=8, steps=1_000_000)
    assert (long.warmup_steps, long.actor_steps) == (20_000, 245 * 4096 - 5 * 4096)


def test_the_start_line_says_what_the_run_does(bc_policy):
    from gymfg_il.rl.start import starting_policy

    cfg = PPORunConfig(init=bc_policy, envs=8, steps=8192, eval_episodes=4, select_episodes=8)
    line = ppo_plan(cfg, starting_policy(cfg).flight)
    assert line == (
        "PPO on altitude on c172p in still air: 8,192 env steps on 8 env(s); the critic alone "
        "learns from the first 4,096, the actor too from the next 4,096; evaluated at the "
        "start and at the end on seeds 7000..7003 (the curve), the kept actor the best on "
        "seeds 7000..7007"
    )
    windy = PPORunConfig(init=bc_policy, envs=2, turbulence="moderate", wind_kt=10.0)
    line = ppo_plan(windy, starting_policy(windy).flight)
    assert "in moderate turbulence and a 10 kt wind: 1,000,000 env steps on 2 env(s)" in line
    assert "evaluated every 50,000 env steps and at the end on seeds 7000..7015" in line


def test_ppos_settings_come_from_the_tasks_table_and_the_flags_win(
    bc_policy, tmp_path, monkeypatch
):
    assert hyperparams.table(None) == hyperparams.table("altitude")  # no table of its own
    assert hyperparams.table(None)["batch_size"] == 512
    original = hyperparams.HYPERPARAMS.read_text()
    own = tmp_path / "hyperparams.toml"
    own.write_text(original + "\n[altitude]\nbatch_size = 256\n")
    monkeypatch.setattr(hyperparams, "HYPERPARAMS", own)
    # the policy flies the altitude: its table's batch, the rest the default's
    cfg = PPORunConfig(init=bc_policy, envs=2)
    assert (cfg.ppo.batch_size, cfg.ppo.rollout_steps, cfg.batch_size) == (256, 512, None)
    assert PPORunConfig(init=bc_policy, envs=2, batch_size=128).ppo.batch_size == 128
    assert PPORunConfig(task="heading", aircraft="c172p", envs=2).ppo.batch_size == 512
    own.write_text("[default]\nbatch_size = 256\nlearning_rate = 1e-3\n")
    with pytest.raises(ConfigError, match=r"\[default\] learning_rate: no setting of PPO's"):
        hyperparams.table("altitude")
    own.write_text(original.replace("epochs = 10", 'epochs = "ten"'))
    with pytest.raises(ConfigError, match=r"epochs='ten': want int"):
        PPORunConfig(init=bc_policy, envs=2)


def test_the_closing_line_reports_the_saved_actor_not_the_last_evaluated(tmp_path):
    """A run that kept its start (no checkpoint beat it) said "success 81% -> 75%", the last
    evaluation's: the line gives the saved actor's figures, and the last evaluation beside."""
    from gymfg_il.rl.judge import EvalPoint
    from gymfg_il.rl.saving import PPOResult
    from gymfg_il.train import ppo_outcome

    def point(step, success, ret):
        return EvalPoint(step, success, ret, 0, 0.0, success, ret, 64)

    curve = [point(0, 0.8125, 900.0), point(50_000, 0.5, 700.0), point(100_000, 0.75, 880.0)]
    kept = PPOResult(tmp_path, 100_000, 60.0, curve, point(0, 0.875, 950.0), [], curve[0])
    line = ppo_outcome(kept)
    assert "success 81% -> 81% (the saved actor; controller 88%)" in line
    assert "900.0 -> 900.0 (controller 950.0); the last evaluation, step 100,000: 75%" in line
    last = PPOResult(tmp_path, 100_000, 60.0, curve, point(0, 0.875, 950.0), [], curve[-1])
    assert ppo_outcome(last).endswith("return 900.0 -> 880.0 (controller 950.0)")
