"""What a logged episode becomes in a dataset: its frames (``episode_columns``) and its record,
the ``gymfg/*`` columns of the episode table (``episode_metadata``). Both follow from the log
alone, so ``collect recover`` checks a dataset's frames and records against them
(``datasets.verify``) and a dataset can always be rebuilt from its logs."""

from __future__ import annotations

import json
import math
from typing import Any

import numpy as np

from gymfg_il.datasets.features import WALL_TIME
from gymfg_il.recording.reader import Log, LoggedEpisode
from gymfg_il.tasks.grades import rank


def episode_columns(episode: LoggedEpisode, callsign: str) -> dict[str, np.ndarray]:
    """One aircraft's logged episode as dataset columns (one frame per agent step)."""
    steps = episode.steps[callsign]
    done = np.zeros(len(steps), dtype=bool)
    done[-1] = True
    return {
        "observation.state": steps.observation,
        "action": steps.label,
        "next.reward": steps.reward,
        "next.done": done,
        "intervention": steps.intervention,
        WALL_TIME: _since_first(steps.wall_time),
    }


def _since_first(clock: np.ndarray) -> np.ndarray:
    """Wall-clock seconds since the episode's first frame (where the log kept a time, else
    -1): LeRobot loads floats as float32, which would round Unix seconds to minutes."""
    if clock[0] < 0:
        return np.full_like(clock, -1.0)
    return np.where(clock >= 0, clock - clock[0], -1.0)


def target_record(task: dict[str, Any], target: float | None) -> dict[str, Any]:
    """How an episode's target is kept: ``target`` the fixed target (NaN where it moves or
    the task has none), ``target_kind`` static, dynamic or none, and for a moving target
    ``target_plan`` (JSON): the variable, where the target starts, how it moves (waypoints
    drawn from ``target_range`` every ``hold_s`` s, approached at ``rate`` units/s; offsets
    from the start value when ``relative``). The schedule itself follows from the seed."""
    if task.get("dynamic"):
        keys = ("variable", "relative", "target_range", "fixed_target", "rate", "hold_s")
        plan: dict[str, Any] = {"start": None if target is None else float(target)}
        plan |= {k: task[k] for k in keys if k in task}
        return {"target": math.nan, "target_kind": "dynamic", "target_plan": json.dumps(plan)}
    if target is None:
        return {"target": math.nan, "target_kind": "none", "target_plan": ""}
    return {"target": float(target), "target_kind": "static", "target_plan": ""}


def episode_metadata(log: Log, episode: LoggedEpisode, callsign: str) -> dict[str, Any]:
    """The ``gymfg/*`` columns of one aircraft's episode: where it comes from and what was
    flown (``spec``: the flight spec, JSON; ``target``: ``target_record``), who flew it and
    how it went (``pilot``, ``device``: the device they flew with, or ""; ``success``: the
    task's verdict, 1 or 0, -1 where it was not judged, with ``verdict`` in words;
    ``grade``: the task's (``tasks.grades``), or ""; ``mark``: the pilot's own, or "";
    ``gusts``: those blown, in a gusty flight)."""
    start, end = episode.start, episode.end or {}
    target = episode.start_of(callsign).get("target")
    info = log.aircraft(callsign)
    task = info.get("task", {}).get("task", "")
    return {
        "aircraft": str(info.get("model", "")),
        "callsign": callsign,
        "team": str(info.get("team", "")),
        "task": str(task),
        **target_record(info.get("task", {}), target),
        "seed": int(start.get("seed", -1)),
        "source": str(start.get("source", log.session.get("source", ""))),
        "noise": float(log.session.get("noise", 0.0)),
        "interventions": int(episode.steps[callsign].intervention.sum()),
        "iteration": int(start.get("iteration", 0)),
        "outcome": str(end.get("outcome", "")),
        "pilot": _text(start.get("pilot")),
        "device": _text(log.session.get("device")),
        "success": _verdict(end.get("success")),
        "verdict": _text(end.get("verdict")),
        "grade": str(end["grade"]) if rank(end.get("grade")) >= 0 else "",
        **_timing(end),
        "wall_start": float(episode.steps[callsign].wall_time[0]),  # Unix s, or -1
        "mark": episode.mark,
        "log": log.path.name,
        "log_episode": int(episode.index),
        "spec": log.spec.to_json(),
        "jsbsim": str(log.session.get("versions", {}).get("jsbsim", "")),
        **_gusts(log, start),
    }


def _gusts(log: Log, start: dict[str, Any]) -> dict[str, Any]:
    """A gusty flight's ``gusts`` column: the episode's gusts (``sim.gusts``) as JSON, a list
    of {start_s, duration_s, north_fps, east_fps, down_fps}; none for a flight without them
    (whose dataset is as it was before gusts existed)."""
    if log.spec.gusts == "none":
        return {}
    gusts = start.get("gusts")
    return {"gusts": json.dumps(gusts if isinstance(gusts, list) else [])}


def _timing(end: dict[str, Any]) -> dict[str, Any]:
    """A real-time episode's timing (``cockpit.timing``): late frames, rate and jitter, and
    from afar the input's delay and age; each -1 where the session ran as fast as it could or
    the log holds none."""
    late = end.get("late_frames")
    out: dict[str, Any] = {"late_frames": late if type(late) is int and late >= 0 else -1}
    age = end.get("input_age_frames")
    out["input_age_frames"] = age if type(age) is int and age >= 0 else -1
    for key in ("rate_hz", "jitter_ms", "input_delay_ms"):
        value = end.get(key)
        number = float(value) if isinstance(value, (int, float)) else math.nan  # a bool too
        out[key] = number if math.isfinite(number) and number >= 0 else -1.0
    return out


def _verdict(success: Any) -> int:
    """A logged verdict as its column holds it: 1, 0, or -1 where none was logged."""
    return 1 if success is True else 0 if success is False else -1


def _text(value: Any, limit: int = 200) -> str:
    """A logged string as a column holds it (a log is hostile: anything else is "")."""
    return value[:limit] if isinstance(value, str) else ""


def same_value(have: Any, want: Any) -> bool:
    """Whether a stored ``gymfg/*`` value is what the builder wrote for ``want``: the same
    type (an int is not a bool or a float, a float not a string) and value (NaN equals NaN)."""
    if isinstance(want, float):
        return type(have) is float and (have == want or (math.isnan(have) and math.isnan(want)))
    return type(have) is type(want) and have == want


def record_differences(stored: dict[str, Any], want: dict[str, Any]) -> list[str]:
    """The ``gymfg/*`` columns of a dataset episode (``stored``, by column name) that are
    not what its log gives (``want``: ``episode_metadata``), one line each. A
    column the dataset lacks is not a difference: a dataset built before the column existed
    keeps the columns it has (``DatasetBuilder``)."""
    out = []
    for key, value in want.items():
        name = f"gymfg/{key}"
        if name in stored and not same_value(stored[name], value):
            out.append(f"{name} is {_shown(stored[name])}, its log says {_shown(value)}")
    return out


def _shown(value: Any, limit: int = 40) -> str:
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."
