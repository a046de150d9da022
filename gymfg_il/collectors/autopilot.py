"""Autopilot demonstrations: the task's controller flies seeded episodes, every step is
logged to MCAP, and the session's episodes become a LeRobot dataset."""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from gymfg_il.collectors.config import CollectConfig
from gymfg_il.controllers.autopilot import controller_for
from gymfg_il.envs.single import AircraftEnv
from gymfg_il.errors import ConfigError
from gymfg_il.recording.writer import TrajectoryWriter

LOGS, DATASET = "logs", "dataset"


def make_env(cfg: CollectConfig) -> AircraftEnv:
    return AircraftEnv(
        cfg.task,
        cfg.aircraft,
        dynamic=cfg.dynamic,
        task_kwargs=cfg.task_kwargs,
        agent_hz=cfg.agent_hz,
        episode_time_s=cfg.episode_time_s,
    )


def env_spec(cfg: CollectConfig) -> dict[str, Any]:
    """What rebuilds the env exactly (for replay)."""
    return {
        "task": cfg.task,
        "aircraft": cfg.aircraft,
        "dynamic": cfg.dynamic,
        "task_kwargs": cfg.task_kwargs,
        "agent_hz": cfg.agent_hz,
        "sim_hz": 120,
        "episode_time_s": cfg.episode_time_s,
    }


def session_record(cfg: CollectConfig, env: AircraftEnv, source: str) -> dict[str, Any]:
    doc = (type(env.task).__doc__ or env.task.name).strip().splitlines()[0]
    return {
        "env": env_spec(cfg),
        "aircraft": env.aircraft.model,
        "task": env.task.name,
        "task_description": f"{doc} ({env.aircraft.model})",
        "observation_names": list(env.observation_names),
        "agent_hz": cfg.agent_hz,
        "sim_hz": 120,
        "source": source,
        "noise": cfg.noise,
    }


def check_out_folder(out: Path) -> None:
    """``out`` must be new, empty, or a session folder (``logs/``, ``dataset/``)."""
    if out.exists() and not out.is_dir():
        raise ConfigError(f"--out {out} is a file; give a folder")
    if out.is_dir():
        foreign = sorted(
            p.name
            for p in out.iterdir()
            if p.name not in (LOGS, DATASET) and not p.name.startswith(DATASET + ".")
        )
        if foreign:
            raise ConfigError(
                f"--out {out} holds {foreign[:5]}, which are not a collection session's; give a "
                "new folder or one made by `collect` (logs/, dataset/)"
            )


def check_appendable(out: Path, env: AircraftEnv, cfg: CollectConfig) -> None:
    """Refuse, before flying anything, to collect data the existing dataset cannot take."""
    root = out / DATASET
    if not (root / "meta" / "info.json").is_file():
        return
    from lerobot.datasets.dataset_metadata import LeRobotDatasetMetadata

    from gymfg_il.datasets.features import check_compatible, dataset_features

    meta = LeRobotDatasetMetadata("gymfg/check", root=root)
    check_compatible(meta.features, dataset_features(env.observation_names), str(root))
    if meta.fps != cfg.agent_hz:
        raise ConfigError(f"the dataset at {root} is at {meta.fps} fps, not {cfg.agent_hz}")


def new_log_path(out: Path) -> Path:
    stamp = time.strftime("%Y%m%d-%H%M%S")
    return out / LOGS / f"session-{stamp}-{os.getpid()}-{time.time_ns() % 10**6:06d}.mcap"


@dataclass
class SessionResult:
    log: Path
    episodes: int
    steps: int
    returns: list[float]


def record_autopilot(
    cfg: CollectConfig,
    log_path: Path | None = None,
    progress: Callable[[int, float], None] | None = None,
) -> SessionResult:
    """Fly ``cfg.episodes`` controller episodes and log them (no dataset yet)."""
    check_out_folder(cfg.out)
    env = make_env(cfg)
    check_appendable(cfg.out, env, cfg)
    pilot = controller_for(
        env.task, env.aircraft.model, env.dt, env.aircraft.profile.cruise_throttle
    )
    path = log_path or new_log_path(cfg.out)
    noise_rng = np.random.default_rng(cfg.seed + 7919)
    returns: list[float] = []
    steps_total = 0
    with TrajectoryWriter(path, session_record(cfg, env, "autopilot"), ["ego"], env.dt) as writer:
        for i in range(cfg.episodes):
            seed = cfg.seed + i
            obs, info = env.reset(seed=seed)
            pilot.reset(seed)
            slot = env.world.slots[0]
            writer.start_episode(
                seed=seed,
                task=env.task.describe(),
                target=info["target"],
                initial_state=dict(
                    zip(("lat_deg", "lon_deg", "altitude_ft"), slot.state[:3].tolist(), strict=True)
                ),
                source="autopilot",
            )
            total, done, step = 0.0, False, 0
            terminated = truncated = False
            step_info: dict[str, Any] = {}
            while not done:
                label = np.clip(pilot.act(obs), [-1, -1, -1, 0], 1)
                executed = label
                if cfg.noise:
                    executed = label.copy()
                    executed[:3] += noise_rng.normal(0.0, cfg.noise, 3)
                    executed = np.clip(executed, [-1, -1, -1, 0], 1)
                next_obs, reward, terminated, truncated, step_info = env.step(executed)
                step += 1
                writer.log_step(
                    "ego", step, slot.state, obs, executed, label, reward, terminated, truncated
                )
                obs = next_obs
                total += reward
                done = terminated or truncated
            outcome = step_info.get("reason", "terminated") if terminated else "time limit"
            writer.end_episode(outcome=outcome, steps=step, interventions=0)
            returns.append(total)
            steps_total += step
            if progress is not None:
                progress(i, total)
    env.close()
    return SessionResult(path, cfg.episodes, steps_total, returns)
