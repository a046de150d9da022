"""Running an evaluation: every agent flies the same seeded cases of one flight
(``evaluate``), each gets a row of scores (``evaluation.metrics``), and ``run_eval`` writes
the JSON rows and the plots asked for."""

from __future__ import annotations

import json
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from gymfg_il.envs.flight import FlightSpec
from gymfg_il.errors import ConfigError
from gymfg_il.evaluation.config import EvalConfig
from gymfg_il.evaluation.metrics import summarize
from gymfg_il.evaluation.plan import plan
from gymfg_il.evaluation.report import shares
from gymfg_il.evaluation.trace import Trace, trace_of
from gymfg_il.rollout.agents import AgentSpec
from gymfg_il.rollout.seeded import fly_many
from gymfg_il.workers import Workers


@dataclass
class EvalRun:
    """What an evaluation flew and found."""

    flight: FlightSpec
    rows: list[dict[str, Any]]
    traces: dict[str, list[Trace]]
    notes: list[str]
    written: list[Path] = field(default_factory=list)


def add_ratios(rows: list[dict[str, Any]]) -> None:
    """Each agent's mean return and success rate as a share of the controller's (first row):
    ``return_ratio`` and ``success_ratio``, None where the controller's is zero."""
    for row in rows:
        row.update(shares(row, rows[0]))


def evaluate(
    flight: FlightSpec,
    agents: Mapping[str, AgentSpec],
    seeds: Sequence[int],
    workers: int | Workers = 1,
    progress: Callable[[str], None] | None = None,
) -> tuple[list[dict[str, Any]], dict[str, list[Trace]]]:
    """Fly every agent on ``seeds`` of ``flight``: a row each (the first agent's is the
    reference of the ratios), and the traces for the plots. ``progress(name)`` is called
    after every episode."""
    rows, traces = [], {}
    for name, agent in agents.items():
        tick = (lambda _episode, name=name: progress(name)) if progress else None
        episodes = fly_many(flight, agent, seeds, workers, progress=tick)
        gusty = flight.gusty
        traces[name] = [trace_of(e, gusty=gusty) for e in episodes]
        row = summarize(name, flight.task_label, flight.aircraft, traces[name])
        row.update(
            agent_hz=flight.agent_hz,
            episode_time_s=flight.episode_time_s,
            spec=flight.to_dict(),
        )
        rows.append(row)
    add_ratios(rows)
    return rows, traces


def run_eval(
    cfg: EvalConfig, progress: Callable[[int], Callable[[str], None]] | None = None
) -> EvalRun:
    """Plan, fly every agent on ``cfg.seeds`` and write the JSON rows and plots asked for.

    ``progress(total)`` is called once the workers run (a bar made earlier would start a
    thread, and workers then could not be forked) and returns the per-episode callback."""
    flight, agents, notes = plan(cfg)
    seeds = cfg.seeds
    with Workers(min(cfg.workers, len(seeds)), ray=cfg.ray) as pool:
        tick = progress(len(agents) * len(seeds)) if progress else None
        rows, traces = evaluate(flight, agents, seeds, pool, tick)
    run = EvalRun(flight, rows, traces, notes)
    if cfg.json:
        try:
            cfg.json.parent.mkdir(parents=True, exist_ok=True)
            cfg.json.write_text(json.dumps({"rows": rows}, indent=2))
        except OSError as err:  # the folder changed while the episodes flew
            raise ConfigError(f"--json {cfg.json}: cannot write there ({err.strerror})") from None
        run.written.append(cfg.json)
    if cfg.plots:
        from gymfg_il.evaluation.plots import figure1, primary_control
        from gymfg_il.evaluation.tracks import ground_tracks, has_track

        label, model = flight.task_label.rsplit(":", 1)[-1], flight.aircraft
        for name, episodes in traces.items():
            path = cfg.plots / f"{label}_{model}_{name.replace(':', '-')}.png"
            title = f"{name}: {label} on {model}"
            control = primary_control(episodes[0].variable)
            figure1(episodes[: cfg.plot_episodes], control, title, path)
            run.written.append(path)
        first = next(iter(traces.values()))
        if first and has_track(first[0]):  # gates, a runway, a lead: where, not when
            path = cfg.plots / f"{label}_{model}_tracks.png"
            title = f"{label} on {model}: ground track and vertical profile"
            run.written.append(ground_tracks(traces, title, path, cfg.plot_episodes))
    return run
