"""The dataset card's table of facts, read from the episodes' ``gymfg/*`` columns.

Those columns come from logs and files a user may have been sent: every value is shown
through ``cell`` (printable, escaped for Markdown and HTML, at most ``CELL_MAX`` characters),
and numbers through ``as_int`` / ``as_float``, so no record can break the table, inject
markup or blow the card up, and none can stop the card from being written.
"""

from __future__ import annotations

import json
import math
import re
from collections import Counter
from importlib.metadata import PackageNotFoundError, version
from typing import Any

from gymfg_il.tasks.grades import GRADES, rank

PACKAGE = "gymfg-il"
CELL_MAX = 64  # names are at most 64 characters (``gymfg_il.names``)
# Markdown's and HTML's special characters, shown as themselves
_ESCAPES = str.maketrans(
    {c: f"\\{c}" for c in "\\`*_[]|#~"} | {"<": "&lt;", ">": "&gt;", "&": "&amp;"}
)
_PLAIN = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.+-]*")


def cell(value: Any, limit: int = CELL_MAX) -> str:
    """``value`` as a card shows it: control, format and separator characters (a newline, a
    NUL, a right-to-left override) as U+FFFD, at most ``limit`` characters (an ellipsis
    ends a longer one), Markdown and HTML escaped (a plain name, ``c172p`` or
    ``altitude_ft``, needs no escape)."""
    text = str(value)
    if _PLAIN.fullmatch(text) and len(text) <= limit:
        return text
    text = "".join(c if c.isprintable() else "\ufffd" for c in text[: limit + 1])
    if len(text) > limit:
        text = text[: limit - 1] + "\u2026"
    return text.translate(_ESCAPES)


def code(value: Any) -> str:
    """A name as code (``c172p`` in backticks) where it is a plain name, else as ``cell``."""
    text = str(value)
    return f"`{text}`" if _PLAIN.fullmatch(text) and len(text) <= CELL_MAX else cell(text)


def as_int(value: Any, default: int = -1) -> int:
    """An integer column's value; ``default`` for anything else (null, a string, a bool)."""
    return value if type(value) is int else default


def as_float(value: Any, default: float = math.nan) -> float:
    """A float column's value; ``default`` for anything else or a non-finite number."""
    if type(value) in (int, float) and math.isfinite(value):
        return float(value)
    return default


def installed(package: str) -> str:
    try:
        return version(package)
    except PackageNotFoundError:
        return "unknown"


def counted(values: list[Any]) -> str:
    counts = Counter(cell(v) for v in values if str(v))
    return (
        ", ".join(f"{k} ({n} episode{'s' * (n != 1)})" for k, n in sorted(counts.items()))
        or "unknown"
    )


def _verdicts(success: list[Any]) -> str:
    """How many episodes the task's own judge passed (``gymfg/success``: 1, 0, -1; any
    other value counts as not judged)."""
    judged = [v for v in map(as_int, success) if v in (0, 1)]
    if not judged:
        return "not recorded"
    unjudged = len(success) - len(judged)
    return f"{sum(judged)} of {len(judged)} succeeded by the task's own judge" + (
        f"; {unjudged} not judged" if unjudged else ""
    )


def _grades(grades: list[Any]) -> str:
    """How many episodes earned each grade (``gymfg/grade``), best first."""
    counts = Counter(str(g) for g in grades if rank(g) >= 0)
    said = ", ".join(f"{counts[g]} {g}" for g in GRADES if counts[g])
    return said or "not recorded"


def _timing(episodes: dict[str, list[Any]], shown: int = 20) -> str:
    """The rate and jitter of each episode flown in real time (``cockpit.timing``)."""
    late = [as_int(n) for n in episodes.get("gymfg/late_frames", [])]
    rate = [as_float(r) for r in episodes.get("gymfg/rate_hz", [-1.0] * len(late))]
    jitter = [as_float(j) for j in episodes.get("gymfg/jitter_ms", [-1.0] * len(late))]
    timed = [(i, n, r, j) for i, (n, r, j) in enumerate(zip(late, rate, jitter, strict=True))]
    timed = [t for t in timed if t[1] >= 0]
    if not timed:
        return "not recorded (no episode was flown in real time)"
    delay = [as_float(d) for d in episodes.get("gymfg/input_delay_ms", [-1.0] * len(late))]
    age = [as_int(a) for a in episodes.get("gymfg/input_age_frames", [-1] * len(late))]

    def afar(i: int) -> str:  # a pilot from afar (collect web): the input's delay seen
        if i >= len(delay) or delay[i] < 0:
            return ""
        return f", input delay p99 {delay[i]:.0f} ms ({age[i]} frames)"

    said = [
        f"episode {i}: {r:.1f} Hz, jitter {j:.1f} ms, {n} late{afar(i)}" for i, n, r, j in timed
    ]
    more = f"; {len(said) - shown} more" if len(said) > shown else ""
    total = sum(t[1] for t in timed)
    flagged = sum(t[1] > 0 for t in timed)
    return (
        f"{total} late frame(s) in {flagged} of {len(timed)} real-time episodes; "
        + "; ".join(said[:shown])
        + more
    )


def _pilots(episodes: dict[str, list[Any]]) -> str:
    """Each named pilot's episodes, successes and grades (``gymfg/pilot``, ``gymfg/success``,
    ``gymfg/grade``)."""
    names = episodes.get("gymfg/pilot", [])
    success = episodes.get("gymfg/success", [-1] * len(names))
    grades = episodes.get("gymfg/grade", [""] * len(names))
    flown: dict[str, list[tuple[int, str]]] = {}
    for name, ok, graded in zip(names, success, grades, strict=True):
        if name:
            flown.setdefault(cell(name), []).append((as_int(ok), str(graded)))
    return (
        "; ".join(
            f"{name}: {len(eps)} episode{'s' * (len(eps) != 1)}, "
            f"{sum(ok == 1 for ok, _ in eps)} succeeded"
            + (f" ({_grades([g for _, g in eps])})" if any(rank(g) >= 0 for _, g in eps) else "")
            for name, eps in sorted(flown.items())
        )
        or "not named"
    )


def _gusts(records: list[Any] | None) -> list[tuple[str, str]]:
    """The gusts row of a dataset whose episodes flew in gusts (``sim.gusts``): how many,
    how strong and how long; none for one without them."""
    if records is None:
        return []
    peaks, lengths, episodes = [], [], 0
    for record in records:
        try:
            gusts = json.loads(record)
        except (TypeError, ValueError):
            continue
        episodes += 1
        for gust in gusts if isinstance(gusts, list) else []:
            if isinstance(gust, dict):
                axes = [as_float(gust.get(f"{a}_fps"), 0.0) for a in ("north", "east", "down")]
                peaks.append(math.hypot(*axes))
                lengths.append(as_float(gust.get("duration_s"), 0.0))
    if not peaks:
        return [("gusts", f"none blew in {episodes} episode(s)")]
    return [
        (
            "gusts",
            f"{len(peaks)} in {episodes} episode(s), peaks {min(peaks):.0f}-{max(peaks):.0f} "
            f"ft/s, {min(lengths):.1f}-{max(lengths):.1f} s long, drawn from each episode's "
            "seed; each episode's (start_s, duration_s, north/east/down_fps) are its "
            "`gymfg/gusts` and its log's start event",
        )
    ]


def jsbsim(episodes: dict[str, list[Any]]) -> str:
    recorded = sorted({cell(v) for v in episodes.get("gymfg/jsbsim", []) if v})
    return ", ".join(recorded) or (
        f"version not recorded; {installed('jsbsim')} where this card was written"
    )


def aircraft(meta: Any, episodes: dict[str, list[Any]]) -> list[str]:
    """The aircraft models the episodes flew (as recorded: show them through ``cell``)."""
    return sorted({str(a) for a in episodes.get("gymfg/aircraft", [])}) or [str(meta.robot_type)]


def facts(meta: Any, episodes: dict[str, list[Any]], specs: list[Any]) -> list[tuple[str, str]]:
    """The card's table: what the dataset holds, one row per fact."""
    features = meta.features
    known = bool(episodes)
    sim_hz = ", ".join(str(h) for h in sorted({s.sim_hz for s in specs})) or "unknown"
    weather = {
        f"turbulence {s.turbulence}, wind {s.wind_kt:g} kt"
        + (f" from {s.wind_from_deg:g} deg" if s.wind_from_deg is not None else "")
        + (f", {s.gusts} gusts" if s.gusts != "none" else "")
        for s in specs
    }
    starts = {"trimmed straight, level flight" if s.trimmed_starts else "untrimmed" for s in specs}
    kinds = episodes.get("gymfg/target_kind", [])
    cameras = [
        f"`{k}` ({f['shape'][1]}x{f['shape'][0]} video)"
        for k, f in features.items()
        if f.get("dtype") == "video"
    ]
    ends = [v for v in episodes.get("gymfg/outcome", []) if v]
    return [
        (
            "data",
            f"simulated: the JSBSim flight dynamics model (JSBSim {jsbsim(episodes)}); "
            "no real aircraft flew",
        ),
        ("aircraft", ", ".join(map(cell, aircraft(meta, episodes)))),
        ("tasks", counted(episodes.get("gymfg/task", [])) if known else "unknown"),
        ("targets", counted(kinds) if kinds else "not recorded"),
        ("sources", counted(episodes.get("gymfg/source", [])) if known else "unknown"),
        (
            "DART noise (action std)",
            counted(episodes.get("gymfg/noise", [])) if known else "unknown",
        ),
        ("weather", "; ".join(sorted(weather)) or "unknown"),
        *_gusts(episodes.get("gymfg/gusts")),
        ("starts", ", ".join(sorted(starts)) or "unknown"),
        ("episode ends", counted(ends) if ends else "not recorded"),
        ("verdicts", _verdicts(episodes.get("gymfg/success", []))),
        ("grades", _grades(episodes.get("gymfg/grade", []))),
        ("timing", _timing(episodes)),
        ("pilots", _pilots(episodes)),
        ("devices", counted(episodes.get("gymfg/device", [])).replace("unknown", "none")),
        ("pilots' marks", counted(episodes.get("gymfg/mark", [])).replace("unknown", "none")),
        ("rates", f"{meta.fps} fps (agent steps); JSBSim at {sim_hz} Hz"),
        ("episodes", f"{meta.total_episodes} ({meta.total_frames} frames)"),
        ("cameras", ", ".join(cameras) or "none"),
        ("card written by", f"GymFG-IL {installed(PACKAGE)}"),
    ]
