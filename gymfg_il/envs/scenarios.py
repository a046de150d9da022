"""Joint initial conditions: scenarios that place all aircraft at once (formation, merge).

A scenario is ``(rng, [(team, aircraft), ...]) -> {callsign: InitialConditions}``; give it to an
environment as ``scenario=``. Aircraft it leaves out start from their tasks' own conditions. Any
randomness comes from ``rng``, the environment's seeded generator.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from gymfg_il.aircraft import Aircraft
from gymfg_il.envs.world import Scenario as JointStart
from gymfg_il.errors import ConfigError
from gymfg_il.sim.initial import InitialConditions
from gymfg_il.tasks.geometry import offset_position


def _check(**values: float) -> None:
    bad = [f"{k}={v!r}" for k, v in values.items() if not (math.isfinite(v) and v >= 0)]
    if bad:
        raise ConfigError(f"scenario parameters must be finite and >= 0: {', '.join(bad)}")


def formation(
    lead: InitialConditions | None = None,
    spacing_ft: float = 300.0,
    jitter_ft: float = 0.0,
    heading_jitter_deg: float = 0.0,
) -> JointStart:
    """Echelon right: aircraft i sits i x spacing behind and to the right of the first, same
    altitude, heading and airspeed (the first aircraft's cruise profile unless ``lead``)."""
    _check(spacing_ft=spacing_ft, jitter_ft=jitter_ft, heading_jitter_deg=heading_jitter_deg)

    def place(
        rng: np.random.Generator, aircraft: Sequence[tuple[str, Aircraft]]
    ) -> dict[str, InitialConditions]:
        first = aircraft[0][1].profile
        base = lead or InitialConditions(
            altitude_ft=first.cruise_altitude_ft, airspeed_kts=first.cruise_kts
        )
        heading = base.heading_deg + float(rng.uniform(-1, 1)) * heading_jitter_deg
        psi = math.radians(heading)
        out = {}
        for i, (_, plane) in enumerate(aircraft):
            back, right = -i * spacing_ft, i * spacing_ft
            back += float(rng.uniform(-1, 1)) * jitter_ft
            right += float(rng.uniform(-1, 1)) * jitter_ft
            north = back * math.cos(psi) - right * math.sin(psi)
            east = back * math.sin(psi) + right * math.cos(psi)
            lat, lon = offset_position(base.latitude_deg, base.longitude_deg, north, east)
            out[plane.callsign] = InitialConditions(
                lat, lon, base.altitude_ft, heading % 360.0, base.airspeed_kts
            )
        return out

    return place


def head_on_merge(
    distance_ft: float = 30000.0,
    altitude_ft: float | None = None,
    lateral_spacing_ft: float = 500.0,
    jitter_ft: float = 0.0,
) -> JointStart:
    """The first team flies north, every other team south towards it, ``distance_ft`` apart;
    aircraft of one team line up abreast ``lateral_spacing_ft`` apart, each at its cruise
    airspeed, all at ``altitude_ft`` (the first aircraft's cruise altitude by default)."""
    _check(distance_ft=distance_ft, lateral_spacing_ft=lateral_spacing_ft, jitter_ft=jitter_ft)
    origin = InitialConditions()

    def place(
        rng: np.random.Generator, aircraft: Sequence[tuple[str, Aircraft]]
    ) -> dict[str, InitialConditions]:
        first_team = aircraft[0][0]
        alt = altitude_ft if altitude_ft is not None else aircraft[0][1].profile.cruise_altitude_ft
        out = {}
        counts: dict[bool, int] = {True: 0, False: 0}
        for team, plane in aircraft:
            ours = team == first_team
            k = counts[ours]
            counts[ours] += 1
            north = -distance_ft / 2 if ours else distance_ft / 2
            north += float(rng.uniform(-1, 1)) * jitter_ft
            east = k * lateral_spacing_ft + float(rng.uniform(-1, 1)) * jitter_ft
            lat, lon = offset_position(origin.latitude_deg, origin.longitude_deg, north, east)
            out[plane.callsign] = InitialConditions(
                lat, lon, alt, 0.0 if ours else 180.0, plane.profile.cruise_kts
            )
        return out

    return place
