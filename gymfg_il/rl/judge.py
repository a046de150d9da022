"""Evaluations during a PPO run (``Judge``): each actor is saved as a checkpoint and flown on
the held-out seeds by ``evaluation.runner.evaluate``, the code ``eval`` runs, so every point of
the curve is what ``eval --policy`` would report; and the curve's plot."""

from __future__ import annotations

import shutil
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from gymfg_il.envs.flight import FlightSpec
from gymfg_il.rl.start import Start, as_ppo, meta_of, stats_of


@dataclass
class EvalPoint:
    """One evaluation of the actor's mean action on the held-out seeds."""

    step: int
    success: float
    mean_return: float
    crashed: int
    wall_s: float


class Judge:
    """Evaluates actors on the held-out seeds, each saved as a checkpoint first, so that
    every point of the curve is what ``eval --policy`` would report for it."""

    def __init__(
        self, flight: FlightSpec, seeds: list[int], start: Start, folder: Path, began: float
    ) -> None:
        self.flight, self.seeds, self.start, self.folder = flight, seeds, start, folder
        self.began = began
        self.best: tuple[tuple[float, float], int, Any] | None = None  # score, step, actor

    def _point(self, step: int, row: dict[str, Any]) -> EvalPoint:
        return EvalPoint(
            step,
            float(row["success_rate"]),
            float(row["mean_return"]),
            int(row["terminated"]),
            time.perf_counter() - self.began,
        )

    def controller(self) -> EvalPoint:
        from gymfg_il.evaluation.runner import evaluate
        from gymfg_il.rollout.agents import AgentSpec

        rows, _ = evaluate(self.flight, {"controller": AgentSpec.controller()}, self.seeds)
        return self._point(0, rows[0])

    def __call__(self, actor: Any, step: int) -> EvalPoint:
        from gymfg_il.evaluation.runner import evaluate
        from gymfg_il.policies.checkpoint import save_policy
        from gymfg_il.rollout.agents import AgentSpec

        path = self.folder / f"step-{step}"
        module = as_ppo(actor)
        meta = {**meta_of(self.start), "name": path.name, "spec": self.flight.to_dict()}
        save_policy(
            module, path, meta, stats_of(module, "obs_norm"), stats_of(module, "action_norm")
        )
        rows, _ = evaluate(self.flight, {"policy": AgentSpec.policy(path)}, self.seeds)
        shutil.rmtree(path, ignore_errors=True)
        point = self._point(step, rows[0])
        score = (point.success, point.mean_return)
        if self.best is None or score > self.best[0]:
            self.best = (score, step, module)
        return point


def plot_curve(curve: list[EvalPoint], controller: EvalPoint, title: str, path: Path) -> None:
    """Evaluated success and return against env steps, with the start (the first point) and
    the controller on the same seeds as lines."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    steps = [p.step for p in curve]
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.6))
    for ax, key, label in zip(
        axes, ("success", "mean_return"), ("success (held-out seeds)", "mean return"), strict=True
    ):
        values = [getattr(p, key) for p in curve]
        if key == "success":
            values = [100 * v for v in values]
        ax.plot(steps, values, marker="o", label="policy")
        first = values[0]
        expert = getattr(controller, key) * (100 if key == "success" else 1)
        ax.axhline(first, color="grey", linestyle="--", label="start")
        ax.axhline(expert, color="green", linestyle=":", label="controller")
        ax.set_xlabel("env steps")
        ax.set_ylabel(label + (" %" if key == "success" else ""))
        ax.grid(alpha=0.3)
    axes[0].legend()
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)
