"""Evaluations during a PPO run (``Judge``): each actor is saved as a checkpoint and flown on
the held-out seeds by ``evaluation.runner.evaluate``, the code ``eval`` runs, so every point of
the curve is what ``eval --policy`` would report; and the curve's plot.

The curve is the first ``eval_episodes`` seeds' success; the kept actor is chosen on more
(``select_episodes``, those seeds and the next ones): a success rate on a few episodes spreads
as widely as the actors differ, and the best of many such draws is mostly the luckiest."""

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
    """One evaluation of the actor's mean action: on the curve's held-out seeds (``success``,
    ``mean_return``, ``crashed``) and on all the seeds the kept actor is chosen on
    (``chosen_on`` episodes: ``select_success``, ``select_return``)."""

    step: int
    success: float
    mean_return: float
    crashed: int
    wall_s: float
    select_success: float
    select_return: float
    chosen_on: int


class Judge:
    """Evaluates actors on the held-out seeds, each saved as a checkpoint first, so that
    every point of the curve is what ``eval --policy`` would report for it."""

    def __init__(
        self,
        flight: FlightSpec,
        seeds: list[int],
        start: Start,
        folder: Path,
        began: float,
        more: list[int] | None = None,
        workers: Any = 1,
        keep_all: bool = False,
    ) -> None:
        """``seeds``: the curve's; ``more``: the further seeds the kept actor is chosen on;
        ``workers``: processes (or a ``workers.Workers`` pool) to fly them on; ``keep_all``:
        every evaluated actor stays in ``folder``/checkpoints/step-N."""
        self.flight, self.seeds, self.start, self.folder = flight, seeds, start, folder
        self.more, self.workers, self.began = list(more or []), workers, began
        self.keep_all = keep_all
        self.best: tuple[tuple[float, float], int, Any] | None = None  # score, step, actor

    def _fly(self, step: int, agent: Any, more: bool = True) -> EvalPoint:
        from gymfg_il.evaluation.metrics import summarize
        from gymfg_il.evaluation.runner import evaluate

        seeds = self.seeds + (self.more if more else [])
        rows, traces = evaluate(self.flight, {"agent": agent}, seeds, self.workers)
        f = self.flight
        curve: dict[str, Any] = summarize(
            "agent", f.task_label, f.aircraft, traces["agent"][: len(self.seeds)]
        )
        return EvalPoint(
            step,
            float(curve["success_rate"]),
            float(curve["mean_return"]),
            int(curve["terminated"]),
            time.perf_counter() - self.began,
            float(rows[0]["success_rate"]),
            float(rows[0]["mean_return"]),
            len(seeds),
        )

    def controller(self) -> EvalPoint:
        """The controller on the curve's seeds (its line on the plot)."""
        from gymfg_il.rollout.agents import AgentSpec

        return self._fly(0, AgentSpec.controller(), more=False)

    def __call__(self, actor: Any, step: int, more: bool = True) -> EvalPoint:
        """``actor`` evaluated at env ``step``, on the curve's seeds and (``more``) the
        further ones; the best so far on all of them is kept (``best``)."""
        from gymfg_il.policies.checkpoint import save_policy
        from gymfg_il.rollout.agents import AgentSpec

        path = self.folder / ("checkpoints" if self.keep_all else "") / f"step-{step}"
        module = as_ppo(actor)
        meta = {**meta_of(self.start), "name": path.name, "spec": self.flight.to_dict()}
        save_policy(
            module, path, meta, stats_of(module, "obs_norm"), stats_of(module, "action_norm")
        )
        point = self._fly(step, AgentSpec.policy(path), more)
        if not self.keep_all:
            shutil.rmtree(path, ignore_errors=True)
        score = (point.select_success, point.select_return)
        if self.best is None or score > self.best[0]:
            self.best = (score, step, module)
        return point


def choose(keep: str, judge: Judge, curve: list[EvalPoint], last: Any) -> tuple[EvalPoint, Any]:
    """(the kept actor's evaluation, the actor) for ``PPORunConfig.keep``, ``last`` the actor
    after the last update (evaluated last in ``curve``)."""
    if keep == "last":
        return curve[-1], last
    assert judge.best is not None
    _, step, actor = judge.best
    return next(p for p in curve if p.step == step), actor


def plot_curve(
    curve: list[EvalPoint],
    controller: EvalPoint,
    title: str,
    path: Path,
    kept: EvalPoint | None = None,
) -> None:
    """Evaluated success and return against env steps, with the start (the first point) and
    the controller on the same seeds as lines; the success on all the seeds the kept actor is
    chosen on, where those are more, and the kept actor (``kept``, on those seeds) marked."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    steps = [p.step for p in curve]
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.6))
    panels = (
        ("success", "select_success", "success (held-out seeds)"),
        ("mean_return", "select_return", "mean return"),
    )
    for ax, (key, chosen_key, label) in zip(axes, panels, strict=True):
        scale = 100 if key == "success" else 1
        values = [scale * getattr(p, key) for p in curve]
        ax.plot(steps, values, marker="o", label=f"policy ({controller.chosen_on} seeds)")
        more = [p for p in curve if p.chosen_on > controller.chosen_on]
        if len(more) > 1:
            chosen = [scale * getattr(p, chosen_key) for p in more]
            label = f"on {more[0].chosen_on} seeds"
            ax.plot([p.step for p in more], chosen, marker=".", alpha=0.7, label=label)
        if kept is not None:
            mark = scale * getattr(kept, chosen_key)
            ax.plot([kept.step], [mark], marker="*", markersize=14, color="red", label="kept")
        ax.axhline(values[0], color="grey", linestyle="--", label="start")
        expert = scale * getattr(controller, key)
        ax.axhline(expert, color="green", linestyle=":", label="controller")
        ax.set_xlabel("env steps")
        ax.set_ylabel(label + (" %" if key == "success" else ""))
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)
