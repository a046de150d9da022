"""Evaluation: every agent flies the same seeded cases of one flight, and each gets a row.

A policy is flown with its own flight spec (its aircraft, task and options, rate and episode
time, from its ``config.json``) unless asked otherwise; ``flight_for`` settles what is flown
and refuses what cannot be meant (a 30 Hz policy flown at 10 Hz).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

from gymfg_il.envs.flight import FlightSpec
from gymfg_il.errors import ConfigError
from gymfg_il.evaluation.metrics import summarize
from gymfg_il.evaluation.trace import Trace, trace_of
from gymfg_il.rollout.agents import AgentSpec
from gymfg_il.rollout.seeded import fly_many
from gymfg_il.sim.timing import DEFAULT_AGENT_HZ
from gymfg_il.workers import Workers

# flag -> the solo spec field it sets
_FLAGS = {
    "task": "task",
    "dynamic": "dynamic",
    "aircraft": "aircraft",
    "episode_time_s": "episode_time_s",
    "turbulence": "turbulence",
    "wind_kt": "wind_kt",
}


def flight_for(
    policies: Mapping[Path, Mapping[str, Any]],
    *,
    task: str | None = None,
    dynamic: bool | None = None,
    aircraft: str | None = None,
    agent_hz: int | None = None,
    episode_time_s: float | None = None,
    turbulence: str | None = None,
    wind_kt: float | None = None,
) -> tuple[FlightSpec, list[str]]:
    """What to fly: the policies' own flight, changed where a flag asks (each change is
    returned as a note to print), or, without policies, the flags over the defaults.

    A rate other than the policy's is refused: its actions were learnt at its own rate."""
    specs = {path: meta.get("spec") for path, meta in policies.items()}
    known = {p: FlightSpec.from_dict(s) for p, s in specs.items() if s}
    distinct = {s.to_json(): p for p, s in known.items()}
    if len(distinct) > 1:
        a, b = list(distinct.values())[:2]
        raise ConfigError(
            f"{a} and {b} were trained on different flights; every agent of one evaluation "
            "flies the same cases: evaluate them separately"
        )
    asked: dict[str, Any] = {"task": task, "dynamic": dynamic, "aircraft": aircraft}
    asked.update(episode_time_s=episode_time_s, turbulence=turbulence, wind_kt=wind_kt)
    notes: list[str] = []
    if not known:
        missing = ", ".join(str(p) for p in policies)
        if policies and (task is None or aircraft is None):
            why = "; ".join(str(m.get("spec_note") or "") for m in policies.values()).strip("; ")
            raise ConfigError(
                f"{missing} records no flight of its own ({why or 'its dataset predates them'})"
                ": give --task and --aircraft"
            )
        rates = {int(m["fps"]) for m in policies.values() if m.get("fps")}
        if len(rates) > 1 or (rates and agent_hz is not None and {agent_hz} != rates):
            raise ConfigError(
                f"{missing} {'were' if len(policies) > 1 else 'was'} trained at {sorted(rates)} "
                f"Hz (the dataset's fps) and fly at that rate; drop --agent-hz or evaluate "
                "them separately"
            )
        rate = agent_hz or (rates.pop() if rates else DEFAULT_AGENT_HZ)
        given = {k: v for k, v in asked.items() if v is not None}
        return FlightSpec.solo(agent_hz=rate, **given), notes
    path, base = next(iter(known.items()))
    if agent_hz is not None and agent_hz != base.agent_hz:
        raise ConfigError(
            f"{path} was trained at {base.agent_hz} Hz (its dataset's fps) and flies at that "
            f"rate; --agent-hz {agent_hz} would change what each of its actions means. Drop "
            "--agent-hz, or train on data recorded at that rate"
        )
    changes: dict[str, Any] = {}
    for flag, value in asked.items():
        old = getattr(base, _FLAGS[flag])
        if value is None or value == old:
            continue
        changes[_FLAGS[flag]] = value
        notes.append(
            f"note: {path} was trained with {flag}={old!r}; flying it with {flag}={value!r} "
            "as asked"
        )
    if "task" in changes:
        changes["task_kwargs"] = {}  # another task's options would not fit
    return base.replace(**changes), notes


def add_ratios(rows: list[dict[str, Any]]) -> None:
    """Each agent's mean return and success rate as a share of the controller's (first row);
    None where the controller's is zero (no share to give)."""
    base = rows[0]
    for row in rows:
        for key, ratio in (("mean_return", "return_ratio"), ("success_rate", "success_ratio")):
            ref, value = float(base[key]), float(row[key])
            row[ratio] = value / ref if ref else None


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
        gusty = flight.turbulence != "none"
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
