"""Joint initial conditions: scenarios that place all aircraft at once (formation, merge).

A scenario is ``(rng, [(team, aircraft), ...]) -> {callsign: InitialConditions}``; give it to an
environment as ``scenario=``. Aircraft it leaves out start from their tasks' own conditions. Any
randomness comes from ``rng``, the environment's seeded generator.

The built-in scenarios are frozen dataclasses, so a flight spec can record them by name and
parameters (``SCENARIOS``) and a replay can build them again; any other callable works too, but a
log of it can only be replayed by passing the same callable back.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict, dataclass, fields
from typing import Any

import numpy as np

from gymfg_il.aircraft import Aircraft
from gymfg_il.errors import ConfigError
from gymfg_il.sim.initial import InitialConditions
from gymfg_il.tasks.geometry import offset_position
from gymfg_il.units import wrap_360

# (rng, [(team name, aircraft), ...]) -> {callsign: ic}
Scenario = Callable[
    [np.random.Generator, Sequence[tuple[str, Aircraft]]], Mapping[str, InitialConditions]
]


def _check(**values: float) -> None:
    bad = [f"{k}={v!r}" for k, v in values.items() if not (math.isfinite(v) and v >= 0)]
    if bad:
        raise ConfigError(f"scenario parameters must be finite and >= 0: {', '.join(bad)}")


@dataclass(frozen=True)
class Formation:
    """Echelon right: aircraft i sits i x spacing behind and to the right of the first, same
    altitude, heading and airspeed (the first aircraft's cruise profile unless ``lead``)."""

    lead: InitialConditions | None = None
    spacing_ft: float = 300.0
    jitter_ft: float = 0.0
    heading_jitter_deg: float = 0.0

    def __post_init__(self) -> None:
        _check(
            spacing_ft=self.spacing_ft,
            jitter_ft=self.jitter_ft,
            heading_jitter_deg=self.heading_jitter_deg,
        )

    def __call__(
        self, rng: np.random.Generator, aircraft: Sequence[tuple[str, Aircraft]]
    ) -> dict[str, InitialConditions]:
        first = aircraft[0][1].profile
        base = self.lead or InitialConditions(
            altitude_ft=first.cruise_altitude_ft, airspeed_kts=first.cruise_kts
        )
        heading = base.heading_deg + float(rng.uniform(-1, 1)) * self.heading_jitter_deg
        psi = math.radians(heading)
        out = {}
        for i, (_, plane) in enumerate(aircraft):
            back, right = -i * self.spacing_ft, i * self.spacing_ft
            back += float(rng.uniform(-1, 1)) * self.jitter_ft
            right += float(rng.uniform(-1, 1)) * self.jitter_ft
            north = back * math.cos(psi) - right * math.sin(psi)
            east = back * math.sin(psi) + right * math.cos(psi)
            lat, lon = offset_position(base.latitude_deg, base.longitude_deg, north, east)
            out[plane.callsign] = InitialConditions(
                lat,
                lon,
                base.altitude_ft,
                wrap_360(heading),
                base.airspeed_kts,
                trimmed=base.trimmed,
            )
        return out


@dataclass(frozen=True)
class HeadOnMerge:
    """The first team flies north, every other team south towards it, ``distance_ft`` apart;
    aircraft of one team line up abreast ``lateral_spacing_ft`` apart, each at its cruise
    airspeed, all at ``altitude_ft`` (the first aircraft's cruise altitude by default)."""

    distance_ft: float = 30000.0
    altitude_ft: float | None = None
    lateral_spacing_ft: float = 500.0
    jitter_ft: float = 0.0

    def __post_init__(self) -> None:
        _check(
            distance_ft=self.distance_ft,
            lateral_spacing_ft=self.lateral_spacing_ft,
            jitter_ft=self.jitter_ft,
        )

    def __call__(
        self, rng: np.random.Generator, aircraft: Sequence[tuple[str, Aircraft]]
    ) -> dict[str, InitialConditions]:
        origin = InitialConditions()
        first_team = aircraft[0][0]
        alt = self.altitude_ft
        if alt is None:
            alt = aircraft[0][1].profile.cruise_altitude_ft
        out = {}
        counts: dict[bool, int] = {True: 0, False: 0}
        for team, plane in aircraft:
            ours = team == first_team
            k = counts[ours]
            counts[ours] += 1
            north = -self.distance_ft / 2 if ours else self.distance_ft / 2
            north += float(rng.uniform(-1, 1)) * self.jitter_ft
            east = k * self.lateral_spacing_ft + float(rng.uniform(-1, 1)) * self.jitter_ft
            lat, lon = offset_position(origin.latitude_deg, origin.longitude_deg, north, east)
            out[plane.callsign] = InitialConditions(
                lat, lon, alt, 0.0 if ours else 180.0, plane.profile.cruise_kts
            )
        return out


def formation(
    lead: InitialConditions | None = None,
    spacing_ft: float = 300.0,
    jitter_ft: float = 0.0,
    heading_jitter_deg: float = 0.0,
) -> Formation:
    """An echelon-right formation (see ``Formation``)."""
    return Formation(lead, spacing_ft, jitter_ft, heading_jitter_deg)


def head_on_merge(
    distance_ft: float = 30000.0,
    altitude_ft: float | None = None,
    lateral_spacing_ft: float = 500.0,
    jitter_ft: float = 0.0,
) -> HeadOnMerge:
    """Two sides flying at each other (see ``HeadOnMerge``)."""
    return HeadOnMerge(distance_ft, altitude_ft, lateral_spacing_ft, jitter_ft)


SCENARIOS: dict[str, type] = {"formation": Formation, "head_on_merge": HeadOnMerge}


def scenario_record(scenario: Scenario | None) -> dict[str, Any] | None:
    """A scenario as plain data: ``{"name": ..., parameters...}``; a callable of your own is
    named ``"python:<module.qualname>"`` and cannot be rebuilt from the record."""
    if scenario is None:
        return None
    for name, cls in SCENARIOS.items():
        if type(scenario) is cls:
            params = asdict(scenario)  # type: ignore[call-overload]
            return {"name": name, **params}
    qualname = getattr(scenario, "__qualname__", type(scenario).__qualname__)
    module = getattr(scenario, "__module__", "?")
    return {"name": f"python:{module}.{qualname}"}


def scenario_from_record(record: Mapping[str, Any] | None) -> Scenario | None:
    """The scenario a record describes (the inverse of ``scenario_record``)."""
    if record is None:
        return None
    params = dict(record)
    name = params.pop("name", None)
    cls = SCENARIOS.get(str(name))
    if cls is None:
        raise ConfigError(
            f"scenario {name!r} cannot be built from a record: known ones are "
            f"{', '.join(SCENARIOS)}; for a scenario of your own, pass it again (scenario=)"
        )
    known = {f.name for f in fields(cls)}
    unknown = sorted(set(params) - known)
    if unknown:
        raise ConfigError(f"scenario {name!r} has no parameters {unknown}; known: {sorted(known)}")
    lead = params.get("lead")
    if isinstance(lead, Mapping):  # recorded by asdict, or by a flight spec's plain form
        params["lead"] = InitialConditions(**lead.get("initial_conditions", lead))
    scenario: Scenario = cls(**params)
    return scenario
