"""DAgger: the policy flies, the expert (the task's controller) labels every state the policy
visits, the labelled episodes join the dataset (source ``dagger`` and the iteration are
recorded per episode), and the policy is trained again on the aggregate. The session starts
from a copy of the policy's dataset and links those episodes' logs into its ``logs/``
(``datasets.episode_logs``), so `collect recover` rebuilds every episode of the aggregate."""

from __future__ import annotations

import logging
import shutil
from collections.abc import Callable
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any, Literal

from gymfg_il.collectors.session import DATASET, LOGS, record_session
from gymfg_il.datasets import lerobot_api as lr
from gymfg_il.datasets.episode_logs import link_base_logs
from gymfg_il.datasets.videos import IMAGE_PREFIX
from gymfg_il.envs.flight import FlightSpec
from gymfg_il.errors import ConfigError
from gymfg_il.learning.config import TrainConfig, validation_words
from gymfg_il.rollout.agents import AgentSpec
from gymfg_il.workers import Workers

log = logging.getLogger(__name__)


@dataclass
class DaggerConfig:
    """DAgger rounds from a trained policy (``collect dagger``).

    Attributes:
        policy: checkpoint to start from; it flies its own flight spec (aircraft, task and
            options, rate, episode time).
        out: session folder: logs/, dataset/ (the aggregate), policy-<k>/.
        expert: who labels the visited states: the task's controller.
        iterations: rounds of fly / label / aggregate / retrain.
        episodes: episodes per round.
        seed: seed of the first episode (the rounds take the seeds that follow).
        epochs: training epochs per round (default: the policy's own).
        workers: worker processes flying episodes.
        ray: fly the episodes on a Ray cluster instead: auto, local or HOST:PORT (results
            identical to one worker).
    """

    policy: Path
    out: Path
    expert: Literal["controller"] = "controller"
    iterations: int = 3
    episodes: int = 10
    seed: int = 2000
    epochs: int | None = None
    workers: int = 1
    ray: str | None = None

    def __post_init__(self) -> None:
        self.policy, self.out = Path(self.policy), Path(self.out)
        bad = [
            f"{k}={getattr(self, k)!r}"
            for k in ("iterations", "episodes", "workers")
            if not isinstance(getattr(self, k), int) or getattr(self, k) < 1
        ]
        if self.epochs is not None and self.epochs < 1:
            bad.append(f"epochs={self.epochs!r}")
        if bad:
            raise ConfigError(f"dagger: {', '.join(bad)} must be integers >= 1")

    def run(
        self, on_iteration: Callable[[DaggerIteration], None] | None = None
    ) -> list[DaggerIteration]:
        """``run_dagger`` with these settings."""
        overrides = {"epochs": self.epochs} if self.epochs else {}
        return run_dagger(
            self.policy, self.out, self.iterations, self.episodes, self.seed, self.workers,
            overrides, on_iteration, self.ray,
        )  # fmt: skip


@dataclass
class DaggerIteration:
    iteration: int
    policy_return: float  # mean return of the policy while it collected
    episodes: int
    dataset_episodes: int
    policy: Path
    val_loss: float

    @property
    def validation(self) -> str:
        """The retrained policy's validation loss in words (``validation_words``)."""
        return validation_words(self.val_loss)


def run_dagger(
    policy: Path,
    out: Path,
    iterations: int = 3,
    episodes: int = 10,
    seed: int = 2000,
    workers: int = 1,
    train_overrides: dict[str, Any] | None = None,
    on_iteration: Callable[[DaggerIteration], None] | None = None,
    ray: str | None = None,
) -> list[DaggerIteration]:
    """``iterations`` rounds of fly / label / aggregate / retrain, starting from ``policy``."""
    from gymfg_il.datasets.from_logs import build_from_logs
    from gymfg_il.learning.bc import train_bc

    if iterations < 1 or episodes < 1:
        raise ConfigError("iterations and episodes must be >= 1")
    meta = AgentSpec.policy(policy).meta()
    flight = _own_flight(policy, meta)
    root = out / DATASET
    if not root.exists():
        _start_session(Path(meta.get("dataset", "")), out)
    cameras = _cameras(root)
    current = Path(policy)
    history = []
    # one pool for every round, forked before training starts threads in this process
    with Workers(min(workers, episodes), ray=ray) as pool:
        for it in range(1, iterations + 1):
            seeds = range(seed + (it - 1) * episodes, seed + it * episodes)
            session = record_session(
                flight, AgentSpec.policy(current), AgentSpec.controller(), seeds, out,
                "dagger", workers=pool, iteration=it, **cameras,
            )  # fmt: skip
            report = build_from_logs(sorted((out / LOGS).glob("*.mcap")), root)
            cfg = retrain_config(meta, root, out / f"policy-{it}", train_overrides)
            result = train_bc(cfg)
            current = result.out
            step = DaggerIteration(
                it,
                sum(session.returns) / len(session.returns),
                len(session.episodes),
                report.total_episodes,
                current,
                result.val_loss[-1],
            )
            history.append(step)
            if on_iteration is not None:
                on_iteration(step)
    return history


def _own_flight(policy: Path, meta: dict[str, Any]) -> FlightSpec:
    """The flight ``policy`` was trained for (``meta``: its config.json), which DAgger flies."""
    if not meta.get("spec"):
        raise ConfigError(
            f"{policy} records no flight spec (trained on a dataset made before gymfg-il 0.2); "
            "DAgger flies the policy's own flight: rebuild the dataset with `collect recover` "
            "and train again"
        )
    return FlightSpec.from_dict(meta["spec"])


def _start_session(base: Path, out: Path) -> None:
    """Start the session ``out`` from a copy of the policy's dataset ``base``, with the logs
    of its episodes linked into ``out``'s logs/, so `collect recover` rebuilds every episode."""
    if not (base / "meta" / "info.json").is_file():
        raise ConfigError(f"the policy's dataset {base} is gone; DAgger aggregates onto it")
    out.mkdir(parents=True, exist_ok=True)
    unlinked = link_base_logs(base, out / LOGS)
    shutil.copytree(base, out / DATASET)
    if unlinked:
        log.warning(
            "%d episode(s) of %s have no log to take along; `collect recover %s` cannot "
            "rebuild them: %s",
            len(unlinked),
            base,
            out,
            "; ".join(unlinked[:5]),
        )


def _cameras(root: Path) -> dict[str, Any]:
    """The camera settings of the rounds' sessions: a camera dataset stays one, the new
    rounds drawing the same views at the same size as the dataset at ``root``."""
    root_meta = lr.open_metadata(root)
    cameras = root_meta.video_keys
    views = [k.removeprefix(IMAGE_PREFIX) for k in cameras]
    size = int(root_meta.features[cameras[0]]["shape"][0]) if cameras else 128
    return {"images": views, "image_size": size}


def retrain_config(
    meta: dict[str, Any], dataset: Path, out: Path, overrides: dict[str, Any] | None = None
) -> TrainConfig:
    """The run that trains the policy of ``meta`` (its config.json) again on ``dataset``: its
    type and settings (config.json's ``policy``) and the run's settings (``train``, of which
    checkpoints written before the policy registry also listed policy settings, left out
    here), with ``overrides``."""
    from gymfg_il.policies.factory import policy_type

    settings = dict(meta["policy"])
    config = policy_type(settings.get("type", meta["type"])).config
    if config.retrains_as:  # made by RL (PPO's): trained again as the network it is
        config = policy_type(config.retrains_as).config
    policy = config.from_dict(settings)
    known = {f.name for f in fields(TrainConfig)} - {"policy", "dataset", "out"}
    run = {k: v for k, v in meta.get("train", {}).items() if k in known}
    return TrainConfig(**{**run, **(overrides or {})}, policy=policy, dataset=dataset, out=out)
