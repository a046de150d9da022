"""DAgger improves on plain BC trained from too few demonstrations."""

import numpy as np
import pytest

from gymfg_il.collectors.autopilot import record_autopilot
from gymfg_il.collectors.config import CollectConfig
from gymfg_il.datasets.from_logs import build_from_logs
from gymfg_il.envs.flight import FlightSpec
from gymfg_il.learning.bc import train_bc
from gymfg_il.learning.config import TrainConfig
from gymfg_il.learning.dagger import run_dagger
from gymfg_il.learning.data import load_frames
from gymfg_il.policies.configuration_mlp import MLPConfig
from gymfg_il.rollout import AgentSpec, fly_many


@pytest.mark.slow
def test_dagger_beats_plain_bc(tmp_path):
    # two clean demonstrations: BC never sees how to recover from its own deviations
    demo = CollectConfig(
        task="heading",
        episodes=2,
        episode_time_s=40,
        seed=1000,
        noise=0.0,
        out=tmp_path / "demo",
    )
    build_from_logs([record_autopilot(demo).log], tmp_path / "demo" / "dataset")
    bc = train_bc(
        TrainConfig(
            dataset=tmp_path / "demo" / "dataset",
            out=tmp_path / "bc",
            epochs=40,
            val_fraction=0.0,
            seed=0,
            policy=MLPConfig(memory="none"),  # DAgger's own gain, not the memory's
        )
    )
    history = run_dagger(
        bc.out,
        tmp_path / "dagger",
        iterations=2,
        episodes=4,
        seed=2000,
        train_overrides={"epochs": 40},
    )
    spec = FlightSpec.solo("c172p", "heading", episode_time_s=40)
    seeds = range(5)
    bc_return = np.mean([e.total_return for e in fly_many(spec, AgentSpec.policy(bc.out), seeds)])
    dagger_return = np.mean(
        [e.total_return for e in fly_many(spec, AgentSpec.policy(history[-1].policy), seeds)]
    )
    assert dagger_return > bc_return
    frames = load_frames(tmp_path / "dagger" / "dataset")
    assert frames.episodes["gymfg/source"].count("dagger") == 8
    assert sorted(set(frames.episodes["gymfg/iteration"])) == [0, 1, 2]


def test_dagger_flies_the_policys_own_flight(tmp_path):
    from gymfg_il.collectors.autopilot import collect_autopilot
    from gymfg_il.recording.reader import read_log

    demo = CollectConfig(
        task="altitude",
        episodes=2,
        episode_time_s=7,
        agent_hz=20,
        task_kwargs={"target_range": [-300.0, 300.0], "tolerance": 20.0},
        seed=1000,
        out=tmp_path / "demo",
    )
    collect_autopilot(demo)
    bc = train_bc(TrainConfig(dataset=tmp_path / "demo" / "dataset", out=tmp_path / "bc", epochs=1))
    history = run_dagger(
        bc.out, tmp_path / "dagger", iterations=1, episodes=2, train_overrides={"epochs": 1}
    )
    (log_path,) = (tmp_path / "dagger" / "logs").glob("dagger-*.mcap")
    log = read_log(log_path)
    assert log.spec == demo.flight()  # episode time, rate and task options all kept
    for ep in log.complete_episodes:
        steps = ep.steps["ego"]
        assert len(steps) == 7 * 20
        start = ep.start_of("ego")
        assert abs(start["target"] - start["initial_state"]["altitude_ft"]) <= 300
    assert log.aircraft("ego")["task"]["tolerance"] == 20.0
    retrained = AgentSpec.policy(history[-1].policy).meta()
    assert FlightSpec.from_dict(retrained["spec"]) == demo.flight()


@pytest.mark.slow
def test_recover_rebuilds_every_episode_of_a_dagger_session_and_names_what_it_cannot(
    tmp_path, capsys
):
    import json
    import os
    import shutil

    from gymfg_il import collect
    from gymfg_il.datasets import lerobot_api as lr
    from gymfg_il.datasets.episode_logs import dataset_refs

    demo = CollectConfig(task="altitude", episodes=3, episode_time_s=3, out=tmp_path / "demo")
    (base_log,) = [record_autopilot(demo).log]
    build_from_logs([base_log], tmp_path / "demo" / "dataset")
    bc = train_bc(TrainConfig(dataset=tmp_path / "demo" / "dataset", out=tmp_path / "bc", epochs=1))
    session = tmp_path / "dagger"
    run_dagger(bc.out, session, iterations=1, episodes=2, train_overrides={"epochs": 1})
    linked = session / "logs" / base_log.name
    assert os.path.samefile(linked, base_log)  # a hard link, not a second copy
    record = json.loads((session / "logs" / "base-episodes.json").read_text())
    assert [e["log_episode"] for e in record["episodes"]] == [0, 1, 2]

    def summary(root):
        meta = lr.open_metadata(root)
        return meta.total_episodes, meta.total_frames, list(meta.episodes["length"])

    made, made_refs = summary(session / "dataset"), dataset_refs(session / "dataset")
    assert made[0] == 5  # 3 base + 2 DAgger episodes
    shutil.move(session / "dataset", tmp_path / "made")
    assert collect.main(["recover", str(session)]) == 0
    assert summary(session / "dataset") == made  # every episode, in the same order
    assert dataset_refs(session / "dataset") == made_refs

    linked.unlink()  # the base log gone: recover names each episode it held
    capsys.readouterr()
    assert collect.main(["recover", str(session)]) == 1
    err = capsys.readouterr().err
    assert "3 episode(s) are kept from the dataset as it was, but no log" in err
    for k in range(3):
        assert f"dataset episode {k}: {base_log.name} episode {k} (ego): log missing" in err
    shutil.rmtree(session / "dataset")
    assert collect.main(["recover", str(session)]) == 1
    err = capsys.readouterr().err
    assert "3 episode(s) are lost" in err and f"{base_log.name} episode 2 (ego)" in err
    assert summary(session / "dataset")[0] == 2  # the DAgger episodes alone


@pytest.mark.slow  # a DAgger run
def test_dagger_flies_a_recurrent_policy_with_its_state_carried_and_reset(
    tiny_gru, tmp_path, carried_state
):
    from gymfg_il.policies.agent import PolicyAgent
    from gymfg_il.recording.reader import read_log

    history = run_dagger(
        tiny_gru, tmp_path / "dagger", iterations=1, episodes=2, train_overrides={"epochs": 1}
    )
    (log_path,) = (tmp_path / "dagger" / "logs").glob("dagger-*.mcap")
    episodes = read_log(log_path).complete_episodes
    policy = PolicyAgent.load(tiny_gru).policy
    assert len(episodes) == 2
    for episode in episodes:  # one kept agent flew both, the expert labelled every step
        steps = episode.steps["ego"]
        carried_state(policy, steps.observation, steps.action)
        assert np.abs(steps.label - steps.action).max() > 0.01
    assert PolicyAgent.load(history[-1].policy).stateful  # retrained as the GRU it was
