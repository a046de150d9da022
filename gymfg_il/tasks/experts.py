"""The structure of a task's expert, declared by the task as data (``Task.expert()``): which
target each loop of the PID autopilot follows, which gain set flies them, and where the loops
read their targets when a pilot sees only the window. ``controllers.autopilot.controller_for``
builds the autopilot from it, and ``manual.perception`` the synthetic pilot's loops.

The loops (``controllers.autopilot``): the elevator flies pitch, fed by a climb rate fed by
an altitude; the ailerons fly roll, fed by a heading; the throttle flies airspeed; the
rudder keeps the sideslip at zero or flies it to a target. An axis given no target holds
what it had at the first observation of the episode (altitude, wings level, airspeed), so
every expert flies a complete aircraft.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any


@dataclass(frozen=True)
class Targets:
    """Where each target comes from: an observation name, a constant, or None (hold start).

    ``relative``: names the axes (``vertical``, ``lateral``, ``speed``) whose source entry
    holds the error (target minus value, wrapped for headings) instead of the target itself.
    ``lateral="track"`` steers onto a line (a runway centre line, a slot beside a lead): the
    source holds the line's course minus the heading and ``track_source`` how far right of
    the line the aircraft is (ft); the heading target is the course turned towards the line
    by ``track_gain`` degrees per ft, at most ``track_limit_deg``.
    ``station_source`` keeps station on a moving point (a formation slot): it holds how far
    behind the point the aircraft is (ft) and ``station_rate_source`` how fast that grows
    (ft/s); the airspeed target is the airspeed plus ``station_gains`` (kt per ft, kt per
    ft/s) times them, at most 20 kt either way.
    """

    vertical: str = "altitude"  # "altitude", "pitch" or "climb"
    vertical_source: str | float | None = None
    lateral: str = "roll"  # "roll", "heading" or "track"
    lateral_source: str | float | None = 0.0
    speed_source: str | float | None = None
    sideslip_source: str | float | None = None  # None: coordinated flight (zero sideslip)
    relative: frozenset[str] = frozenset()
    track_source: str | None = None
    track_gain: float = 0.02
    track_limit_deg: float = 30.0
    station_source: str | None = None
    station_rate_source: str | None = None
    station_gains: tuple[float, float] = (0.4, 2.0)


@dataclass(frozen=True)
class Expert:
    """A task's expert, as data (module docstring).

    Attributes:
        targets: where each loop takes its target from (``Targets``).
        bank_deg: None: the aircraft's own gain set (``controllers.gains.gains_for``); a
            bank: the maneuver gains, banked at most this much
            (``controllers.gains.maneuver_gains``).
        on_display: where the loops take their targets from when a pilot reads only the
            window: fields of ``targets`` replaced by readings the window draws
            (``tasks.guidance``); empty where the expert's sources are drawn already (a
            target task's bug is its expert's source).
    """

    targets: Targets = Targets()
    bank_deg: float | None = None
    on_display: Mapping[str, Any] = field(default_factory=dict, hash=False)
