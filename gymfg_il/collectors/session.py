"""Recording sessions: an actor flies seeded episodes (optionally with DART noise), an expert
labels every visited state, and every step goes to the session's MCAP log in seed order.

Episodes are flown on worker processes when asked (``workers``); the log is written by this
process as results arrive in seed order, so it is identical to a one-worker session.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from gymfg_il.errors import ConfigError
from gymfg_il.parallel import AgentSpec, EnvSpec, Workers, kept, map_seeds, release_kept
from gymfg_il.recording.writer import TrajectoryWriter

LOGS, DATASET = "logs", "dataset"
_LOW, _HIGH = np.array([-1.0, -1.0, -1.0, 0.0]), np.ones(4)


@dataclass
class FlownEpisode:
    """Everything one episode logs (picklable, so workers can return it)."""

    seed: int
    target: float | None
    initial_state: dict[str, float]
    task: dict[str, Any]
    observations: np.ndarray
    states: np.ndarray
    executed: np.ndarray
    labels: np.ndarray
    rewards: np.ndarray
    terminated: bool
    outcome: str

    @property
    def total_return(self) -> float:
        return float(self.rewards.sum())


def fly_and_label(
    env_spec: EnvSpec, actor: AgentSpec, expert: AgentSpec | None, noise: float, seed: int
) -> FlownEpisode:
    """Fly one episode: ``actor`` chooses (plus Gaussian noise on the surfaces), ``expert``
    labels each visited state (the actor's own clean action when there is no expert)."""

    def build() -> tuple[Any, Any, Any]:
        env = env_spec.make()
        return env, actor.make(env), expert.make(env) if expert else None

    key = repr((env_spec, actor.key(), expert.key() if expert else None))
    env, pilot, teacher = kept(key, build)
    rng = np.random.default_rng([seed, 7919])
    obs, info = env.reset(seed=seed)
    pilot.reset(seed)
    if teacher is not None:
        teacher.reset(seed)
    slot = env.world.slots[0]
    initial = dict(zip(("lat_deg", "lon_deg", "altitude_ft"), slot.state[:3].tolist(), strict=True))
    observations, states, executed, labels, rewards = [], [], [], [], []
    terminated = truncated = False
    step_info: dict[str, Any] = {}
    while not (terminated or truncated):
        clean = np.clip(np.asarray(pilot.act(obs), dtype=np.float64), _LOW, _HIGH)
        label = clean if teacher is None else np.clip(teacher.act(obs), _LOW, _HIGH)
        action = clean
        if noise:
            action = clean.copy()
            action[:3] += rng.normal(0.0, noise, 3)
            action = np.clip(action, _LOW, _HIGH)
        if teacher is not None and hasattr(teacher, "track"):
            # the expert's integrators follow what was really flown, or the observed ones
            teacher.track(action, from_observation=True)
        observations.append(obs)
        obs, reward, terminated, truncated, step_info = env.step(action)
        states.append(slot.state)
        executed.append(action)
        labels.append(label)
        rewards.append(reward)
    outcome = step_info.get("reason", "terminated") if terminated else "time limit"
    return FlownEpisode(
        seed,
        info["target"],
        initial,
        env.task.describe(),
        np.array(observations),
        np.array(states),
        np.array(executed),
        np.array(labels),
        np.array(rewards),
        bool(terminated),
        outcome,
    )


def session_record(env_spec: EnvSpec, source: str, noise: float, **extra: Any) -> dict[str, Any]:
    env = env_spec.make()
    try:
        doc = (type(env.task).__doc__ or env.task.name).strip().splitlines()[0]
        return {
            "env": {
                "task": env_spec.task,
                "aircraft": env_spec.aircraft,
                "dynamic": env_spec.dynamic,
                "task_kwargs": env_spec.task_kwargs,
                "agent_hz": env_spec.agent_hz,
                "sim_hz": 120,
                "episode_time_s": env_spec.episode_time_s,
            },
            "aircraft": env.aircraft.model,
            "task": env.task.name,
            "task_description": f"{doc} ({env.aircraft.model})",
            "observation_names": list(env.observation_names),
            "agent_hz": env_spec.agent_hz,
            "sim_hz": 120,
            "source": source,
            "noise": noise,
            **extra,
        }
    finally:
        env.close()


def check_out_folder(out: Path) -> None:
    """``out`` must be new, empty, or a session folder (``logs/``, ``dataset/``, policies)."""
    if out.exists() and not out.is_dir():
        raise ConfigError(f"--out {out} is a file; give a folder")
    if out.is_dir():
        foreign = sorted(
            p.name
            for p in out.iterdir()
            if p.name not in (LOGS, DATASET)
            and not p.name.startswith(DATASET + ".")
            and not p.name.startswith("policy-")
        )
        if foreign:
            raise ConfigError(
                f"--out {out} holds {foreign[:5]}, which are not a collection session's; give a "
                "new folder or one made by `collect` (logs/, dataset/)"
            )


def check_appendable(out: Path, observation_names: Sequence[str], fps: int) -> None:
    """Refuse, before flying anything, to collect data the existing dataset cannot take."""
    root = out / DATASET
    if not (root / "meta" / "info.json").is_file():
        return
    from lerobot.datasets.dataset_metadata import LeRobotDatasetMetadata

    from gymfg_il.datasets.features import check_compatible, dataset_features

    meta = LeRobotDatasetMetadata("gymfg/check", root=root)
    check_compatible(meta.features, dataset_features(observation_names), str(root))
    if meta.fps != fps:
        raise ConfigError(f"the dataset at {root} is at {meta.fps} fps, not {fps}")


def new_log_path(out: Path, tag: str = "session") -> Path:
    stamp = time.strftime("%Y%m%d-%H%M%S")
    return out / LOGS / f"{tag}-{stamp}-{os.getpid()}-{time.time_ns() % 10**6:06d}.mcap"


@dataclass
class SessionResult:
    log: Path
    episodes: list[FlownEpisode]

    @property
    def steps(self) -> int:
        return sum(len(e.rewards) for e in self.episodes)

    @property
    def returns(self) -> list[float]:
        return [e.total_return for e in self.episodes]


def record_session(
    env_spec: EnvSpec,
    actor: AgentSpec,
    expert: AgentSpec | None,
    seeds: Sequence[int],
    out: Path,
    source: str,
    noise: float = 0.0,
    workers: int | Workers = 1,
    iteration: int = 0,
    progress: Callable[[int, float], None] | None = None,
) -> SessionResult:
    """Fly one episode per seed and log them to a new MCAP log under ``out/logs``."""
    check_out_folder(out)
    record = session_record(env_spec, source, noise, iteration=iteration)
    check_appendable(out, record["observation_names"], env_spec.agent_hz)
    path = new_log_path(out, source)
    episodes: list[FlownEpisode] = []
    try:
        with TrajectoryWriter(path, record, ["ego"], 1.0 / env_spec.agent_hz) as writer:
            for i, ep in enumerate(
                map_seeds(fly_and_label, (env_spec, actor, expert, noise), seeds, workers)
            ):
                writer.start_episode(
                    seed=ep.seed,
                    task=ep.task,
                    target=ep.target,
                    initial_state=ep.initial_state,
                    source=source,
                    iteration=iteration,
                )
                n = len(ep.rewards)
                for k in range(n):
                    writer.log_step(
                        "ego",
                        k + 1,
                        ep.states[k],
                        ep.observations[k],
                        ep.executed[k],
                        ep.labels[k],
                        ep.rewards[k],
                        terminated=ep.terminated and k == n - 1,
                        truncated=not ep.terminated and k == n - 1,
                    )
                writer.end_episode(outcome=ep.outcome, steps=n, interventions=0)
                episodes.append(ep)
                if progress is not None:
                    progress(i, ep.total_return)
    finally:
        release_kept()
    return SessionResult(path, episodes)
