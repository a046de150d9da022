"""Autopilot demonstrations exported to Minari, opened with Minari's own loader and compared
with the LeRobot dataset (stock LeRobotDataset) and the session's log; the recovered env is
the one the episodes were flown in."""

import shutil

import numpy as np
import pytest

from gymfg_il import collect
from gymfg_il.collectors.autopilot import collect_autopilot
from gymfg_il.collectors.config import CollectConfig
from gymfg_il.errors import ConfigError
from gymfg_il.export.minari import MinariConfig, export_dataset
from gymfg_il.recording.reader import read_log

minari = pytest.importorskip("minari")
NAME = "gymfg/roll-c172p-v0"


def _session(out, noise):
    cfg = CollectConfig(
        aircraft="c172p", task="roll", episodes=2, episode_time_s=3.0, seed=11, noise=noise,
        out=out,
    )  # fmt: skip
    collect_autopilot(cfg)
    return out


@pytest.fixture(scope="module")
def noisy(tmp_path_factory):
    """Two 3 s roll episodes with the default DART noise: flown actions differ from labels."""
    return _session(tmp_path_factory.mktemp("minari") / "run", None)  # the task's own


def test_minari_opens_the_export_and_recovers_the_env_it_was_flown_in(noisy, tmp_path, monkeypatch):
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    summary = export_dataset(noisy, NAME, tmp_path / "minari")
    assert (summary.episodes, summary.steps, summary.env_id) == (2, 60, "GymFG/Roll-v0")
    monkeypatch.setenv("MINARI_DATASETS_PATH", str(tmp_path / "minari"))
    data = minari.load_dataset(NAME)
    assert data.total_episodes == 2 and data.total_steps == 60
    lerobot = LeRobotDataset("x/y", root=noisy / "dataset")
    log = read_log(next((noisy / "logs").glob("*.mcap")))
    table = lerobot.hf_dataset.with_format("numpy")
    for ep, logged in zip(data.iterate_episodes(), log.complete_episodes, strict=True):
        rows = np.flatnonzero(table["episode_index"] == ep.id)
        obs = np.stack(table["observation.state"][rows])
        assert ep.observations.shape == (31, 13) and ep.actions.shape == (30, 4)
        assert np.array_equal(ep.observations[:30], obs)  # the dataset's, bit for bit
        assert np.array_equal(ep.infos["label"][:30], np.stack(table["action"][rows]))
        flown = logged.steps["ego"].action
        assert np.array_equal(ep.actions, flown.astype(np.float32))  # what the env flew
        assert not np.allclose(ep.actions, ep.infos["label"][:30])  # noise: not the labels
        assert np.allclose(ep.rewards, np.stack(table["next.reward"][rows]).ravel(), rtol=1e-6)
        assert np.array_equal(ep.rewards, logged.steps["ego"].reward)
        assert not ep.terminations.any() and ep.truncations.tolist() == [False] * 29 + [True]
    seeds = [m["seed"] for m in data.storage.get_episode_metadata([0, 1])]
    assert seeds == [11, 12]

    env = data.recover_environment()
    try:
        assert env.spec.id == "GymFG/Roll-v0"
        kwargs = env.spec.kwargs
        assert (kwargs["aircraft"], kwargs["task"], kwargs["agent_hz"]) == ("c172p", "roll", 10)
        assert kwargs["episode_time_s"] == 3.0 and kwargs["dynamic"] is False
        assert env.observation_space == data.observation_space
        assert env.action_space == data.action_space
        assert (
            list(env.unwrapped.observation_names)
            == lerobot.meta.features["observation.state"]["names"]
        )
        first = next(iter(data.iterate_episodes()))
        obs, _ = env.reset(seed=seeds[0])
        assert np.array_equal(obs, first.observations[0])
        after, reward, terminated, truncated, _ = env.step(first.actions[0])
        # the stored action is float32; the flown one float64: one step apart by rounding only
        assert np.allclose(after, first.observations[1], rtol=1e-5, atol=1e-5)
        assert reward == pytest.approx(first.rewards[0], rel=1e-5)
        assert not terminated and not truncated
    finally:
        env.close()


def test_the_cli_exports_a_clean_dataset_folder_without_its_logs(tmp_path, capsys):
    session = _session(tmp_path / "clean", 0.0)
    alone = tmp_path / "alone"
    shutil.copytree(session / "dataset", alone)  # no logs beside it: labels are the actions
    root = tmp_path / "minari"
    argv = ["export", "minari", str(alone), "--name", "gymfg/clean-v1", "--root", str(root)]
    assert collect.main(argv) == 0
    assert f"under {root}: 2 episodes, 60 steps, env GymFG/Roll-v0" in capsys.readouterr().out
    assert (root / "gymfg" / "clean-v1" / "data").is_dir()
    assert collect.main(argv) == 2  # once only
    assert "already exists" in capsys.readouterr().err


def test_the_export_names_who_made_it_and_with_what_code(tmp_path, capsys, monkeypatch):
    from importlib.metadata import metadata, version

    session = _session(tmp_path / "clean", 0.0)
    root = tmp_path / "minari"
    argv = ["export", "minari", str(session), "--root", str(root)]
    assert collect.main([*argv, "--name", "gymfg/plain-v0"]) == 0
    package = metadata("gymfg-il")["Author"]
    assert package == "GymFG-IL contributors"  # pyproject's authors
    out = capsys.readouterr().out
    assert f"author {package} (not set: --author-email, --code-permalink)" in out
    given = [
        "--author", "Ada", "--author", "Grace", "--author-email", "ada@example.org",
        "--code-permalink", "https://example.org/gymfg-il/tree/abc123",
    ]  # fmt: skip
    assert collect.main([*argv, "--name", "gymfg/credited-v0", *given]) == 0
    assert "not set" not in capsys.readouterr().out
    monkeypatch.setenv("MINARI_DATASETS_PATH", str(root))
    plain = minari.load_dataset("gymfg/plain-v0").storage.metadata
    assert plain["author"] == {package} and "author_email" not in plain  # none invented
    assert "code_permalink" not in plain
    pins = [f"gymfg-il=={version('gymfg-il')}", f"jsbsim=={version('jsbsim')}"]
    assert plain["requirements"] == pins
    credited = minari.load_dataset("gymfg/credited-v0").storage.metadata
    assert credited["author"] == {"Ada", "Grace"}
    assert credited["author_email"] == {"ada@example.org"}
    assert credited["code_permalink"] == "https://example.org/gymfg-il/tree/abc123"


def test_what_cannot_be_exported_says_why(noisy, tmp_path):
    alone = tmp_path / "alone"
    shutil.copytree(noisy / "dataset", alone)
    with pytest.raises(ConfigError, match=r"flown with noise 0\.1: its flown actions are only"):
        export_dataset(alone, NAME, tmp_path / "m")
    assert not (tmp_path / "m" / "gymfg" / "roll-c172p-v0").exists()
    with pytest.raises(ConfigError, match="no LeRobot dataset at"):
        export_dataset(tmp_path / "nowhere", NAME, tmp_path / "m")
    with pytest.raises(ConfigError, match="a Minari dataset id is"):
        MinariConfig(noisy, "roll")


def test_a_team_run_is_refused_by_name(tmp_path):
    from gymfg_il import Team
    from gymfg_il.agent import RandomAgent
    from gymfg_il.aircraft import c172p
    from gymfg_il.collectors.commands import recover
    from gymfg_il.envs import OfflineEnv
    from gymfg_il.recording.recorder import Recorder
    from gymfg_il.tasks import ReachStaticTargetAltitudeTask

    # two aircraft alike (same model, task, settings): one flight spec, but flown together
    pair = Team(
        "pair",
        [(c172p(c), ReachStaticTargetAltitudeTask) for c in ("lead", "wing")],
        episode_time_s=1,
    )
    env = Recorder(OfflineEnv(), tmp_path)
    pilot = RandomAgent(0.2)
    env.reset(pair, seed=0)
    done = False
    while not done:
        *_, terminated, truncated, _ = env.step(np.hstack([pilot.act(None)] * 2))
        done = terminated or truncated
    env.close()
    assert recover(tmp_path) == 0
    with pytest.raises(ConfigError, match="holds team-run episodes \\(lead, wing flew beside"):
        export_dataset(tmp_path, NAME, tmp_path / "m")


def test_episodes_flown_in_two_airs_are_refused_not_reflown_in_one(tmp_path):
    # a policy keeps the first episodes' flight (learning.frames.flight_of); an export that
    # re-flies every episode in one env cannot
    out = _session(tmp_path / "run", None)
    rough = CollectConfig(
        aircraft="c172p", task="roll", episodes=1, episode_time_s=3.0, seed=40,
        turbulence="moderate", out=out,
    )  # fmt: skip
    collect_autopilot(rough)
    with pytest.raises(ConfigError, match=r"2 weathers.*export the episodes of one air"):
        export_dataset(out, NAME, tmp_path / "minari")
