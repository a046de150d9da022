"""A policy's memory of its task's expert loops (``--memory loops``): what training computes
over a recorded episode is what flight computes step by step, the state is reset at each
episode and carried within one, and the memory reaches the action linearly."""

import numpy as np
import pytest
import torch

from gymfg_il.envs.flight import FlightSpec
from gymfg_il.errors import ConfigError
from gymfg_il.learning.bc import train_bc
from gymfg_il.learning.config import TrainConfig
from gymfg_il.learning.data import load_frames
from gymfg_il.learning.memory import remembered
from gymfg_il.policies.agent import PolicyAgent
from gymfg_il.policies.configuration import DatasetInfo
from gymfg_il.policies.configuration_mlp import MLPConfig
from gymfg_il.policies.memory import LOOPS, NAMES, LoopMemoryRecipe, names_of
from gymfg_il.rollout import Rollout


@pytest.fixture(scope="module")
def remembering(tiny_dataset, tmp_path_factory):
    out = tmp_path_factory.mktemp("memory") / "policy"
    cfg = TrainConfig(
        dataset=tiny_dataset, out=out, epochs=3, policy=MLPConfig(hidden=[32], memory="loops")
    )
    train_bc(cfg)
    return out


def fly(agent, seeds, steps=60):
    """Each seed's observations and actions, ``steps`` steps of the altitude task."""
    env = FlightSpec.solo(task="altitude", episode_time_s=steps / 10).make_env()
    flown = []
    for seed in seeds:
        trajectory = Rollout(env, [agent]).episode(seed).solo
        flown.append((trajectory.observations, trajectory.actions))
    return flown


def test_a_recorded_episode_and_the_same_steps_flown_give_the_same_memory(tiny_dataset):
    frames = load_frames(tiny_dataset)
    spec, _ = frames.flight()
    recipe = LoopMemoryRecipe.for_flight(spec.to_dict(), frames.observation_names)
    obs = frames.obs[frames.episode == frames.episode[0]]
    whole = recipe.new().over(obs)
    stepped = recipe.new()
    assert np.array_equal(whole, np.stack([stepped(row) for row in obs]))
    assert np.array_equal(recipe.new().over(obs), whole)  # a fresh memory starts alike
    assert whole.shape == (len(obs), len(NAMES)) and np.abs(whole[-1, :2]).max() > 0
    memorised = remembered(frames, MLPConfig(memory="loops"))
    assert memorised.observation_names[-len(NAMES) :] == list(NAMES)
    assert np.array_equal(memorised.obs[: len(obs), -len(NAMES) :], whole)


def test_flight_reproduces_training_memory_and_resets_it_each_episode(remembering):
    from gymfg_il.policies.checkpoint import load_policy

    agent = PolicyAgent.load(remembering)
    assert agent.meta["memory_names"] == list(NAMES)
    assert agent.observation_names[-1] == "altitude_ft_error_integral"  # the env's own
    (obs_a, act_a), (obs_b, act_b) = fly(agent, [3, 4])
    # the actions recomputed at once over the whole episode, as training sees it
    policy, _ = load_policy(remembering)
    recipe = policy.recipe()
    for obs, act in ((obs_a, act_a), (obs_b, act_b)):
        rows = np.asarray(obs, dtype=np.float32)
        x = torch.as_tensor(np.c_[rows, recipe.new().over(rows)])
        with torch.no_grad():
            again = policy.action_norm.inverse(policy.forward(x)).double().numpy()
        # one float32 ulp or so apart: MKL sums a one-row product in another order than a
        # many-row one (tests/conftest.py, STEP_VS_WINDOW_ATOL); the memory itself is exact
        assert np.abs(np.clip(again, -1, 1)[:, :3] - act[:, :3]).max() <= 1e-6
        with torch.no_grad():  # without its memory the policy flies otherwise
            x[:, -len(NAMES) :] = 0.0
            forgot = policy.action_norm.inverse(policy.forward(x)).double().numpy()
        assert np.abs(np.clip(forgot, -1, 1)[:, :3] - act[:, :3]).max() > 1e-3
    # the second episode flown after the first equals it flown by a fresh agent
    ((_, fresh),) = fly(PolicyAgent.load(remembering), [4])
    assert np.array_equal(fresh, act_b)


def test_the_memory_reaches_the_action_linearly(remembering):
    from gymfg_il.policies.checkpoint import load_policy

    policy, _ = load_policy(remembering)
    k = len(NAMES)
    x = torch.randn(5, policy.n_obs)
    a, b = torch.zeros(5, policy.n_obs), torch.zeros(5, policy.n_obs)
    a[:, -k:], b[:, -k:] = torch.randn(5, k) * 50, torch.randn(5, k) * 50
    with torch.no_grad():
        f = policy.forward
        assert torch.allclose(f(x + a + b) - f(x + a), f(x + b) - f(x), atol=1e-4)


def test_memory_needs_one_solo_flight_and_whole_episodes(tiny_dataset, caplog):
    frames = load_frames(tiny_dataset)
    frames.episodes = {}  # no flight spec
    with pytest.raises(ConfigError, match="--memory none"):
        remembered(frames, MLPConfig(memory="vertical"))
    assert remembered(frames, MLPConfig()) is frames  # auto: nothing, and says so
    assert "remembers nothing" in caplog.text
    frames = load_frames(tiny_dataset)
    frames.frame = frames.frame + 1  # no episode starts at frame 0
    with pytest.raises(ConfigError, match="frame 0"):
        remembered(frames, MLPConfig(memory="loops"))
    with pytest.raises(ConfigError, match="memory"):
        MLPConfig(memory="forever")
    with pytest.raises(ConfigError, match="frames hold the memory 'none'"):
        MLPConfig(memory="loops").for_data(DatasetInfo(["a"], 10, None))


def test_auto_remembers_the_vertical_loops_and_says_which(tiny_dataset):
    frames = remembered(load_frames(tiny_dataset), MLPConfig())
    assert frames.observation_names[-2:] == list(names_of("vertical"))
    spec, _ = frames.flight()
    config = MLPConfig().for_data(DatasetInfo(frames.observation_names, 10, spec))
    assert config.memory == "vertical" and config.stateful
    assert config.memory_observation == frames.observation_names[:-2]
    assert MLPConfig(memory="none").for_data(DatasetInfo(["a"], 10, None)).to_dict() == {
        "type": "mlp",
        "hidden": [256, 256],
        "dropout": 0.0,
        "memory": "none",
    }


def test_the_vertical_loops_alone_integrate_as_the_whole_autopilot_does(tiny_dataset):
    frames = load_frames(tiny_dataset)
    spec, _ = frames.flight()
    recipe = LoopMemoryRecipe.for_flight(spec.to_dict(), frames.observation_names)
    obs = frames.obs[frames.episode == frames.episode[0]]
    whole = recipe.new("loops").over(obs)[:, :2]  # climb and pitch, every loop run
    alone = recipe.new("vertical")
    assert alone.vertical_only and not recipe.new("loops").vertical_only
    assert np.array_equal(alone.over(obs), whole)


def test_the_expert_gains_are_how_the_experts_action_moves_with_each_integral(tiny_dataset):
    frames = load_frames(tiny_dataset)
    spec, _ = frames.flight()
    recipe = LoopMemoryRecipe.for_flight(spec.to_dict(), frames.observation_names)
    obs = frames.obs[frames.episode == frames.episode[0]]
    memory = recipe.new("loops")
    gains = memory.expert_gains()
    assert gains.shape == (4, len(NAMES)) and np.count_nonzero(gains) == 4  # no slip target
    for k, pid in enumerate(memory.pids):
        if not gains[:, k].any():
            continue
        moved = []
        for nudge in (0.0, 0.5):  # the same steps, one integral set a little further
            memory.reset()
            for row in obs[:20]:
                memory(row)
            pid.integral += nudge
            moved.append(memory.pilot.act(obs[20]))
        # measured on the expert itself, unsaturated: its action moves by the gain times it
        assert np.allclose((moved[1] - moved[0]) / 0.5, gains[:, k], atol=1e-6), (k, moved)


@pytest.mark.parametrize(
    ("task", "loops", "summed"),
    [
        ("pitch", ("climb", "pitch"), {"pitch": "pitch_deg_error_integral"}),
        ("approach", LOOPS["loops"], {"speed": "airspeed_kts_error_integral"}),
    ],
)
def test_a_remembered_error_the_observation_also_sums_is_read_once(tmp_path, task, loops, summed):
    """The pitch task sums its pitch error, the approach its airspeed error, which the
    memory's loops also integrate: a clone of the autopilot reads them through the expert's
    terms alone, the network's column of the task's sum held at zero through training, so
    the action does not move with it (reading both, the f15's approach clones cancelled the
    term through the sum and flew 57-65 kt fast)."""
    from gymfg_il.collectors.autopilot import record_autopilot
    from gymfg_il.collectors.config import CollectConfig
    from gymfg_il.datasets.from_logs import build_from_logs
    from gymfg_il.policies.checkpoint import load_policy

    cfg = CollectConfig(
        task=task, episodes=2, episode_time_s=20, noise=0.05, seed=1000, out=tmp_path
    )
    build_from_logs([record_autopilot(cfg).log], tmp_path / "dataset")
    out = tmp_path / "policy"
    train = TrainConfig(
        dataset=tmp_path / "dataset", out=out, epochs=3, policy=MLPConfig(hidden=[32])
    )
    train_bc(train)
    policy, meta = load_policy(out)
    names = meta["observation_names"]
    memory = policy.recipe().new(policy.config.memory)
    assert memory.loops == loops
    assert memory.pilot.observed_integrals == {k: names.index(v) for k, v in summed.items()}
    ((loop, name),) = summed.items()
    first = policy.net[0].weight.detach().numpy()
    assert not first[:, names.index(name)].any()
    assert np.abs(first[:, names.index(name.removesuffix("_integral"))]).min() > 0  # learned
    std = policy.action_norm.std.numpy().reshape(-1, 1)
    expert = memory.expert_gains() * memory.scales[None, :] / std
    assert np.abs(expert[:, loops.index(loop)]).max() > 1  # the loop's term: the one read
    learned = policy.integral.weight.detach().numpy()
    assert np.allclose(learned, expert, atol=0.05 * np.abs(expert).max())
    policy.eval()
    frames = load_frames(tmp_path / "dataset")
    row = frames.obs[50]
    moved = row.copy()
    moved[names.index(name)] += 500.0
    same = [policy.step(x)[0] for x in (row, moved)]
    assert np.array_equal(same[0], same[1])


def test_training_starts_the_memory_at_the_expert_and_holds_it_there(remembering):
    """The still-air data barely moves the integrals, so the layer they reach the action
    through stays where it starts: the expert's integral terms, in normalised units."""
    from gymfg_il.policies.checkpoint import load_policy

    policy, _ = load_policy(remembering)
    memory = policy.recipe().new("loops")
    std = policy.action_norm.std.numpy().reshape(-1, 1)
    expert = memory.expert_gains() * memory.scales[None, :] / std
    learned = policy.integral.weight.detach().numpy()
    assert np.abs(expert).max() > 5  # terms that a layer started at zero would not reach
    assert np.allclose(learned, expert, atol=0.05 * np.abs(expert).max())
    assert np.allclose(policy.obs_norm.std.numpy()[-len(NAMES) :], memory.scales)


def test_anyone_elses_memory_is_learned_from_the_data(tiny_dataset, tmp_path):
    """A person's trim is not the expert's integral: the same frames said to be a synthetic
    pilot's give a memory measured in its spread in the data, and a layer that starts from
    nothing rather than from the expert's terms."""
    from gymfg_il.policies.checkpoint import load_policy

    frames = load_frames(tiny_dataset)
    frames.episodes["gymfg/source"] = ["synthetic"] * len(frames.episodes["gymfg/source"])
    spread = remembered(frames, MLPConfig(memory="loops")).obs[:, -len(NAMES) :].std(0)
    out = tmp_path / "policy"
    cfg = TrainConfig(
        dataset=tiny_dataset, out=out, epochs=3, policy=MLPConfig(hidden=[32], memory="loops")
    )
    train_bc(cfg, frames=frames)
    policy, _ = load_policy(out)
    spread = np.where(spread > 0, spread, 1.0)  # the slip loop's: none (the normaliser's 1)
    assert np.allclose(policy.obs_norm.std.numpy()[-len(NAMES) :], spread, rtol=1e-5)
    assert np.abs(policy.integral.weight.detach().numpy()).max() < 5  # expert's: up to ~80


@pytest.mark.parametrize(
    ("task", "anyone", "expert"),
    [
        ("altitude", "vertical", "vertical"),
        ("heading", "none", "loops"),
        ("heading dynamic", "none", "none"),
        ("roll", "none", "none"),
        ("turn", "vertical", "loops"),
        ("climb-turn", "vertical", "loops"),
        ("approach", "vertical", "loops"),
        ("formation", "none", "none"),
    ],
)
def test_each_task_says_what_its_clones_remember_by_demonstrator(task, anyone, expert):
    name, *dynamic = task.split()
    env = (
        FlightSpec.solo(task=name, dynamic=bool(dynamic)).make_env()
        if name != "formation"
        else None
    )
    if env is None:
        from gymfg_il.tasks.formation import FormationTask

        chosen = (FormationTask().memory(), FormationTask().memory(by_expert=True))
    else:
        chosen = (env.task.memory(), env.task.memory(by_expert=True))
        env.close()
    assert chosen == (anyone, expert)


def test_the_expert_labels_the_autopilots_demonstrations_and_daggers_rounds(tiny_dataset):
    from gymfg_il.learning.memory import by_expert

    frames = load_frames(tiny_dataset)
    n = len(frames.episodes["gymfg/source"])
    assert by_expert(frames)
    for sources, expert in ((["dagger"] * n, True), (["autopilot"] * (n - 1) + ["human"], False)):
        frames.episodes["gymfg/source"] = sources
        assert by_expert(frames) is expert, sources
