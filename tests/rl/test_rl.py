"""PPO fine-tuning (``train ppo``): the actor starts as the cloned policy, a short run saves a
policy that eval flies, a seeded run repeats, and what cannot be fine-tuned is refused."""

from __future__ import annotations

import json

import numpy as np
import pytest
import torch

from gymfg_il.errors import ConfigError
from gymfg_il.learning.bc import train_bc
from gymfg_il.learning.config import TrainConfig
from gymfg_il.policies.factory import make_config
from gymfg_il.rl.config import PPORunConfig

pytest.importorskip("stable_baselines3")


def _argv(bc_policy, out, *more):
    """``train ppo``'s command line for ``_short``'s run."""
    return [
        "ppo", "--init", str(bc_policy), "--out", str(out), "--steps", "1024", "--envs", "2",
        "--rollout-steps", "256", "--batch-size", "128", "--epochs", "2", "--eval-every", "1024",
        "--eval-episodes", "2", "--select-episodes", "4", "--critic-warmup", "256", "--seed", "3",
        "--no-progress", *more,
    ]  # fmt: skip


def _short(bc_policy, out, **changes):
    settings = dict(
        init=bc_policy, out=out, steps=1024, envs=2, rollout_steps=256, batch_size=128,
        epochs=2, eval_every=1024, eval_episodes=2, select_episodes=4, critic_warmup=256,
        seed=3,
    )  # fmt: skip
    return PPORunConfig(**{**settings, **changes})


def test_the_actor_starts_as_the_cloned_policy(bc_policy, tmp_path):
    from stable_baselines3.common.vec_env import DummyVecEnv

    from gymfg_il.policies.agent import PolicyAgent
    from gymfg_il.rl.envs import make_env
    from gymfg_il.rl.model import make_model
    from gymfg_il.rl.start import starting_policy, stats_of

    cfg = _short(bc_policy, tmp_path / "ppo")
    start = starting_policy(cfg)
    action = stats_of(start.module, "action_norm")
    spec = start.flight.to_dict()
    venv = DummyVecEnv([lambda: make_env(spec, action["mean"], action["std"])])
    try:
        model = make_model(cfg, venv, start.module, tmp_path / "tb", "cpu", start.flight.agent_hz)
        env = start.flight.make_env()
        bc = PolicyAgent.load(bc_policy)
        for seed in (5, 6, 7):
            obs, _ = env.reset(seed=seed)
            batch = torch.as_tensor(obs[None], dtype=torch.float32)
            mean = model.policy.get_distribution(batch).distribution.mean
            assert torch.equal(mean, bc.policy(batch))  # bit for bit, normalised
            normalised, _ = model.policy.predict(obs, deterministic=True)
            raw = venv.envs[0].env.action(normalised)  # Monitor(NormalizedActions(env))
            np.testing.assert_allclose(raw, np.clip(bc.act(obs), *_bounds(env)), atol=1e-5)
        env.close()
    finally:
        venv.close()


def test_normalised_actions_are_numpys_arithmetic_bit_for_bit():
    from gymfg_il.envs.flight import FlightSpec
    from gymfg_il.rl.envs import normalized_actions

    mean = np.array([0.01, -0.05, 0.002, 0.7])
    std = np.array([0.1, 0.2, 1e-9, 0.1])  # a constant control: its spread counts as 1
    env = normalized_actions(FlightSpec.solo("c172p", "altitude").make_env(), mean, std)
    held = np.where(std < 1e-6, 1.0, std)
    rng = np.random.default_rng(0)
    for action in rng.normal(size=(2000, 4)).astype(np.float32):
        # the fast path (four Python floats) gives numpy's doubles exactly
        assert env.action(action).tobytes() == (action.astype(np.float64) * held + mean).tobytes()
    batch = rng.normal(size=(3, 4)).astype(np.float32)  # anything else: numpy's own way
    np.testing.assert_array_equal(env.action(batch), batch * held + mean)
    assert env.action([0.0, 0.0, 0.0, 0.0]).tolist() == mean.tolist()
    env.close()


def _bounds(env):
    return env.action_space.low, env.action_space.high


@pytest.mark.slow
def test_a_short_fine_tune_saves_a_policy_that_eval_flies(bc_policy, tmp_path):
    from safetensors.torch import load_file

    from gymfg_il.envs.flight import FlightSpec
    from gymfg_il.evaluation.config import EvalConfig
    from gymfg_il.evaluation.runner import evaluate, run_eval
    from gymfg_il.rl.judge import EvalPoint
    from gymfg_il.rollout.agents import AgentSpec
    from gymfg_il.train import main

    out = tmp_path / "ppo"
    assert main(_argv(bc_policy, out, "--turbulence", "light", "--checkpoints")) == 0
    config = json.loads((out / "config.json").read_text())
    curve = [EvalPoint(**p) for p in config["rl"]["curve"]]
    assert config["rl"]["steps"] >= 1024
    assert [p.step for p in curve] == [0, 1024]
    assert config["type"] == "ppo" and config["policy"]["hidden"] == [256, 256]
    assert config["spec"]["turbulence"] == "light"
    assert config["rl"]["init"] == str(bc_policy) and config["train"]  # DAgger retrains on it
    assert config["rl"]["settings"]["actor_lr"] == 1e-4  # the rate applied, not None
    assert (out / "curve.png").stat().st_size > 1000
    assert list((out / "tensorboard").rglob("events.out.tfevents.*"))
    # the best evaluation's actor is kept (the start's, where nothing beat it), chosen on the
    # curve's two seeds and the next two: the start's point is the BC policy's on each
    best = max(curve, key=lambda p: (p.select_success, p.select_return))
    kept_entry = {"which": "best", "step": best.step, "chosen_on": 4}
    assert config["rl"]["kept"] == {**kept_entry, "select_success": best.select_success}
    flight = FlightSpec.from_dict(config["spec"])  # the run's: in light turbulence
    for seeds, success, mean_return in (
        ([7000, 7001], curve[0].success, curve[0].mean_return),
        ([7000, 7001, 7002, 7003], curve[0].select_success, curve[0].select_return),
    ):
        rows, _ = evaluate(flight, {"bc": AgentSpec.policy(bc_policy)}, seeds)
        assert (rows[0]["success_rate"], rows[0]["mean_return"]) == (success, mean_return)
    kept = load_file(str(out / "model.safetensors"))
    start = load_file(str(bc_policy / "model.safetensors"))
    assert set(kept) == set(start)
    same = all(torch.equal(kept[k], start[k]) for k in start)
    assert same == (best.step == 0)
    # every evaluated actor kept, as asked: the kept one among them, the start as it was
    steps = sorted(int(p.name.split("-")[1]) for p in (out / "checkpoints").iterdir())
    assert steps == [p.step for p in curve]
    for step, want in ((best.step, kept), (0, start)):
        saved = load_file(str(out / "checkpoints" / f"step-{step}" / "model.safetensors"))
        assert all(torch.equal(saved[k], want[k]) for k in want)
    # eval flies it beside the policy it started from, in the weather the flags give
    run = run_eval(EvalConfig(policy=[out, bc_policy], episodes=2, seed=9000, turbulence="none"))
    assert [r["agent"] for r in run.rows] == ["controller", "policy:ppo", "policy:bc"]
    assert run.flight.turbulence == "none"
    assert any("different weather" in n and "as asked" in n for n in run.notes)


@pytest.mark.slow
def test_a_seeded_run_repeats(bc_policy, tmp_path):
    from safetensors.torch import load_file

    from gymfg_il.evaluation.runner import evaluate
    from gymfg_il.rl.run import train_ppo
    from gymfg_il.rollout.agents import AgentSpec

    runs, results = [], []
    for name, seed in (("a", 3), ("b", 3), ("c", 4)):
        cfg = _short(bc_policy, tmp_path / name, eval_every=10_000, seed=seed)
        cfg.keep = "last"
        results.append(train_ppo(cfg))
        runs.append(load_file(str(tmp_path / name / "model.safetensors")))
    # the last point of the curve is the saved actor's (after the last update)
    last = results[0].curve[-1]
    assert last.step == results[0].steps == results[0].kept_step
    seeds = list(range(cfg.eval_seed, cfg.eval_seed + cfg.eval_episodes))
    rows, _ = evaluate(_flight(bc_policy), {"a": AgentSpec.policy(tmp_path / "a")}, seeds)
    assert (rows[0]["success_rate"], rows[0]["mean_return"]) == (last.success, last.mean_return)
    start = load_file(str(bc_policy / "model.safetensors"))
    assert all(torch.equal(runs[0][k], runs[1][k]) for k in runs[0])
    assert not all(torch.equal(runs[0][k], runs[2][k]) for k in runs[0])  # the seed matters
    assert not all(torch.equal(runs[0][k], start[k]) for k in start)  # the actor learnt


def test_stable_baselines3s_own_sampler_trains_the_same_way(bc_policy, tmp_path):
    from safetensors.torch import load_file

    from gymfg_il.rl.run import train_ppo

    cfg = _short(bc_policy, tmp_path / "sb3", sampler="sb3", eval_every=10_000, keep="last")
    result = train_ppo(cfg)
    assert [p.step for p in result.curve] == [0, 1024] and result.steps == 1024
    saved = load_file(str(tmp_path / "sb3" / "model.safetensors"))
    start = load_file(str(bc_policy / "model.safetensors"))
    assert not all(torch.equal(saved[k], start[k]) for k in start)  # the actor learnt
    settings = json.loads((tmp_path / "sb3" / "config.json").read_text())["rl"]["settings"]
    assert settings["sampler"] == "sb3" and settings["batch_size"] == 128


def _flight(bc_policy):
    from gymfg_il.rl.start import starting_policy

    return starting_policy(PPORunConfig(init=bc_policy)).flight


@pytest.mark.slow
def test_the_critic_warms_up_before_the_actor_moves(bc_policy, tmp_path):
    from stable_baselines3.common.vec_env import DummyVecEnv

    from gymfg_il.rl.envs import make_env
    from gymfg_il.rl.model import make_model
    from gymfg_il.rl.start import starting_policy, stats_of

    cfg = PPORunConfig(
        init=bc_policy, envs=1, rollout_steps=64, batch_size=32, epochs=2, critic_warmup=128,
        seed=1,
    )  # fmt: skip
    start = starting_policy(cfg)
    action = stats_of(start.module, "action_norm")
    spec = start.flight.to_dict()
    venv = DummyVecEnv([lambda: make_env(spec, action["mean"], action["std"], 0.2)])
    model = make_model(cfg, venv, start.module, tmp_path / "tb", "cpu", start.flight.agent_hz)

    def weights(module):
        return [p.detach().clone() for p in module.parameters()]

    def same(before, module):
        return all(torch.equal(a, b) for a, b in zip(before, weights(module), strict=True))

    actor, critic = weights(model.policy.action_net), weights(model.policy.value_net)
    model.learn(128)  # two rollouts, both begun inside the warm-up
    assert same(actor, model.policy.action_net)
    assert not same(critic, model.policy.value_net)
    model.learn(192, reset_num_timesteps=False)  # past it: the actor moves
    assert not same(actor, model.policy.action_net)
    venv.close()


def test_the_anchor_lets_go_within_150k_steps_unless_told(bc_policy):
    # half of a short run; a long run is not held at its start for half its length
    spans = [PPORunConfig(init=bc_policy, steps=n).anchor_span for n in (100_000, 300_000)]
    assert spans == [50_000, 150_000]
    assert PPORunConfig(init=bc_policy, steps=1_000_000).anchor_span == 150_000
    assert PPORunConfig(init=bc_policy, steps=10**6, anchor_steps=500_000).anchor_span == 500_000


def test_a_fine_tuned_actor_learns_at_a_third_of_the_critics_rate(bc_policy):
    # 1e-4 against 3e-4: at the critic's rate, runs in turbulence fell below their start
    assert PPORunConfig(init=bc_policy).actor_rate == 1e-4
    assert PPORunConfig(init=bc_policy, actor_lr=3e-4).actor_rate == 3e-4
    scratch = PPORunConfig(task="altitude", aircraft="c172p")
    assert scratch.actor_rate == scratch.ppo.lr == 3e-4  # a fresh actor has nothing to keep


def test_the_discount_looks_as_far_ahead_in_seconds_at_every_rate(bc_policy):
    cfg = PPORunConfig(init=bc_policy)
    assert cfg.discounts(10) == (0.99, 0.95)  # the 10 Hz defaults, as they always were
    gamma, lam = cfg.discounts(30)
    # after one second, a reward counts as much at 30 Hz as at 10 Hz
    assert gamma**30 == pytest.approx(0.99**10) and lam**30 == pytest.approx(0.95**10)
    assert gamma == pytest.approx(0.99665, abs=1e-5)
    given = PPORunConfig(init=bc_policy, gamma=0.98, gae_lambda=0.9)
    assert given.discounts(30) == (0.98, 0.9)
    with pytest.raises(ConfigError, match=r"gamma=1\.5"):
        PPORunConfig(init=bc_policy, gamma=1.5)


def test_the_kept_actor_is_chosen_on_the_curves_seeds_and_more(bc_policy):
    assert PPORunConfig(init=bc_policy).chosen_on == 64  # 16 spreads ~10 points
    assert PPORunConfig(init=bc_policy, eval_episodes=100).chosen_on == 100
    assert PPORunConfig(init=bc_policy, keep="last").chosen_on == 16  # nothing to choose
    with pytest.raises(ConfigError, match="select_episodes=8 must be >= eval_episodes=16"):
        PPORunConfig(init=bc_policy, select_episodes=8)


def test_what_cannot_be_fine_tuned_is_refused(bc_policy, tiny_dataset, tmp_path):
    from gymfg_il.rl.start import starting_policy

    with pytest.raises(ConfigError, match="--init POLICY"):
        PPORunConfig()
    with pytest.raises(ConfigError, match="keeps the policy's own task"):
        starting_policy(PPORunConfig(init=bc_policy, task="heading"))
    with pytest.raises(ConfigError, match=r"--agent-hz 30: .* flies agent_hz 10"):
        starting_policy(PPORunConfig(init=bc_policy, agent_hz=30))
    # a policy whose state is not an MLP's memory (a recurrent state, a chunk's queue)
    for kind, settings in (("gru", {"hidden": 8}), ("chunk", {"hidden": [8], "chunk": 2})):
        out = tmp_path / kind
        policy = make_config(kind, **settings)
        train_bc(TrainConfig(dataset=tiny_dataset, out=out, epochs=1, policy=policy))
        with pytest.raises(ConfigError, match=f"{kind} policy; PPO fine-tunes MLP .*--memory"):
            starting_policy(PPORunConfig(init=out))


def test_a_ppo_policy_retrains_as_an_mlp(bc_policy):
    from gymfg_il.learning.dagger import retrain_config
    from gymfg_il.policies.configuration_mlp import MLPConfig

    meta = json.loads((bc_policy / "config.json").read_text())
    meta["policy"]["type"] = meta["type"] = "ppo"
    cfg = retrain_config(meta, bc_policy, bc_policy.parent / "again")
    assert type(cfg.policy) is MLPConfig and cfg.policy.hidden == [256, 256]


def test_train_bc_does_not_offer_ppo():
    from gymfg_il.train import build_parser

    p = build_parser()
    with pytest.raises(SystemExit):
        p.parse_args(["bc", "--policy", "ppo"])
    assert p.parse_args(["ppo", "--init", "x"]).algorithm == "ppo"


@pytest.mark.slow
def test_the_success_bonus_follows_the_verdict_eval_gives(bc_policy):
    from gymfg_il.evaluation.runner import evaluate
    from gymfg_il.rl.envs import make_env
    from gymfg_il.rl.start import starting_policy
    from gymfg_il.rollout.agents import AgentSpec

    flight = starting_policy(PPORunConfig(init=bc_policy)).flight  # 30-s altitude episodes
    env = make_env(flight.to_dict(), [0.0] * 4, [1.0] * 4, success_bonus=0.5)  # raw actions
    seeds = [10, 11, 12]
    outcomes = set()
    for spec in (AgentSpec.controller(), AgentSpec.policy(bc_policy)):
        pilot = spec.make(env.unwrapped)
        rows, _ = evaluate(flight, {"agent": spec}, seeds)
        for seed, episode in zip(seeds, rows[0]["per_episode"], strict=True):
            obs, _ = env.reset(seed=seed)
            pilot.reset(seed)
            if hasattr(pilot, "start_from"):  # the controller starts from the trim, as flown
                pilot.start_from(env.unwrapped.world.slots[0].action)
            rewards, done = [], False
            while not done:
                obs, reward, terminated, truncated, info = env.step(pilot.act(obs))
                rewards.append(reward)
                done = terminated or truncated
            assert info["is_success"] == episode["success"], (spec, seed)
            bonus = 0.5 * len(rewards) if episode["success"] else 0.0
            assert sum(rewards) == pytest.approx(episode["total_return"] + bonus, abs=1e-6)
            outcomes.add(episode["success"])
    assert outcomes == {True, False}  # both ways were checked
