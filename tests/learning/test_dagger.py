"""DAgger improves on plain BC trained from too few demonstrations."""

import numpy as np

from gymfg_il.collectors.autopilot import record_autopilot
from gymfg_il.collectors.config import CollectConfig
from gymfg_il.collectors.dagger import run_dagger
from gymfg_il.datasets.from_logs import build_from_logs
from gymfg_il.evaluation.parallel import fly_many
from gymfg_il.learning.bc import TrainConfig, train_bc
from gymfg_il.learning.data import load_frames
from gymfg_il.parallel import AgentSpec, EnvSpec


def test_dagger_beats_plain_bc(tmp_path):
    # two clean demonstrations: BC never sees how to recover from its own deviations
    demo = CollectConfig(
        task="heading", episodes=2, episode_time_s=40, seed=1000, out=tmp_path / "demo"
    )
    build_from_logs([record_autopilot(demo).log], tmp_path / "demo" / "dataset")
    bc = train_bc(
        TrainConfig(
            dataset=tmp_path / "demo" / "dataset",
            out=tmp_path / "bc",
            epochs=40,
            val_fraction=0.0,
            seed=0,
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
    spec = EnvSpec("heading", "c172p", episode_time_s=40)
    seeds = range(5)
    bc_return = np.mean([e.total_return for e in fly_many(spec, AgentSpec.policy(bc.out), seeds)])
    dagger_return = np.mean(
        [e.total_return for e in fly_many(spec, AgentSpec.policy(history[-1].policy), seeds)]
    )
    assert dagger_return > bc_return
    frames = load_frames(tmp_path / "dagger" / "dataset")
    assert frames.episodes["gymfg/source"].count("dagger") == 8
    assert sorted(set(frames.episodes["gymfg/iteration"])) == [0, 1, 2]
