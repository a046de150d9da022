"""Formation: hold a slot behind and beside a lead aircraft that an autopilot flies through
heading and altitude changes.

The lead is a second JSBSim aircraft of the same model. Its flight does not depend on the
follower's, so the task flies it whole at reset (its own simulation, its own autopilot, the
seed's schedule of headings and altitudes) and the follower sees it step by step as an
opponent is seen: position and orientation only. The plan records the lead's track, so a
log, a dataset's episode or a judge has both aircraft.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any, ClassVar

import numpy as np

from gymfg_il.aircraft import REFERENCE_PROFILE
from gymfg_il.errors import ConfigError
from gymfg_il.sim.initial import InitialConditions
from gymfg_il.sim.properties import INDEX, indices
from gymfg_il.tasks.experts import Targets
from gymfg_il.tasks.geometry import offset_position
from gymfg_il.tasks.grades import Measure
from gymfg_il.tasks.guidance import Line
from gymfg_il.tasks.maneuvers import ManeuverTask, Verdict
from gymfg_il.tasks.rewards import closeness
from gymfg_il.tasks.scenery import Landmark
from gymfg_il.units import FT_PER_DEG, wrap_180, wrap_360

LEAD_VIEW = ("lat_deg", "lon_deg", "altitude_ft", "roll_deg", "pitch_deg", "heading_deg")
_LEAD_IDX = indices(LEAD_VIEW)
_ALT, _HDG = INDEX["altitude_ft"], INDEX["heading_deg"]
_LAT, _LON = INDEX["lat_deg"], INDEX["lon_deg"]


def _tas_over_cas(altitude_ft: float) -> float:
    """True over calibrated airspeed at ``altitude_ft`` in the standard atmosphere, at low
    Mach (the square root of sea level's air density over the density there)."""
    return float((1.0 - 6.8756e-6 * altitude_ft) ** -2.12795)


def _lead_schedule(
    rng: np.random.Generator,
    steps: int,
    dt: float,
    altitude: float,
    heading: float,
    scale: float = 1.0,
) -> tuple[np.ndarray, np.ndarray]:
    """The lead's altitude and heading targets per step: straight for 10 s, then every 20-25
    s a new heading (20-60 deg either way, turned at 3 deg/s) and altitude (100-300 ft either
    way, at 5 ft/s); the times stretched and the turn rate slowed by ``scale`` (the
    aircraft's ``maneuver_scale``)."""
    alt_t, hdg_t = np.empty(steps + 1), np.empty(steps + 1)
    alt_goal, hdg_goal = altitude, heading
    next_change = 10.0 * scale
    turn = 3.0 / scale * dt
    for i in range(steps + 1):
        t = i * dt
        if t >= next_change:
            hdg_goal += float(rng.uniform(20.0, 60.0)) * (1.0 if rng.random() < 0.5 else -1.0)
            alt_goal += float(rng.uniform(100.0, 300.0)) * (1.0 if rng.random() < 0.5 else -1.0)
            next_change = t + float(rng.uniform(20.0, 25.0)) * scale
        heading += max(-turn, min(turn, hdg_goal - heading))
        altitude += max(-5.0 * dt, min(5.0 * dt, alt_goal - altitude))
        alt_t[i], hdg_t[i] = altitude, wrap_360(heading)
    return alt_t, hdg_t


class FormationTask(ManeuverTask):
    """Hold a slot 150 ft behind and 100 ft right of a lead aircraft, at its altitude.

    Observation: ``FLIGHT_VARS`` and ``heading_deg``, then (from the lead's position and
    orientation alone, as an opponent is seen):

    | entry | unit | meaning |
    | --- | --- | --- |
    | behind_slot_ft | ft | how far behind the slot, along the lead's heading |
    | behind_slot_rate_fps | ft/s | how fast that grows (from the last two steps) |
    | right_of_slot_ft | ft | how far right of the slot |
    | below_slot_ft | ft | the slot's altitude - altitude |
    | lead_heading_error_deg | deg | the lead's heading - heading, wrapped |
    | lead_roll_deg, lead_pitch_deg | deg | the lead's attitude |

    Plan: the lead (same model) starts 250-450 ft ahead at 95 % of cruise speed, the
    follower up to 100 ft either side of and above or below the slot's line; the lead flies
    straight for 10 s, then every 20-25 s turns 20-60 deg (at 3 deg/s) and climbs or descends
    100-300 ft (at 5 ft/s), its times stretched and its turn rate divided by the aircraft's
    ``maneuver_scale`` (a lead banks about as far short of its limit on every aircraft). The
    lead's autopilot holds 95 % of cruise as calibrated airspeed, scaled from the c172p's
    altitude to the aircraft's own (calibrated falls further below true airspeed higher up;
    unscaled, a jet's lead at its cruise altitude would speed up at full throttle, where no
    follower of the same model can catch it). The slot and tolerances are the same on every
    aircraft.
    Reward: ``exp(-distance to the slot / 100)`` minus the smoothness term. Success: from 30
    s on, within ``tolerance_ft`` (100) of the slot at every step, and never within 50 ft of
    the lead. Grade: the distance to the slot from 30 s on.
    Start and end: as every maneuver (module docstring); 90 s episodes on the c172p, times
    the aircraft's ``maneuver_scale`` (153 s on the f15, 186 on the A320).
    """

    name = "formation"
    slot = (150.0, 100.0)  # behind, right of the lead (ft)
    extra_names = (
        "behind_slot_ft",
        "behind_slot_rate_fps",
        "right_of_slot_ft",
        "below_slot_ft",
        "lead_heading_error_deg",
        "lead_roll_deg",
        "lead_pitch_deg",
    )
    tracked_entry = ("altitude_ft", "below_slot_ft", 100.0)
    needs_lead_pilot = True  # the environment sets ``lead_pilot`` (controllers.lead)
    lead_pilot: Any = None
    join_s = 30.0
    tolerance_ft = 100.0
    min_separation_ft = 50.0

    def memory(self, by_expert: bool = False) -> str:
        """None: the slot moves with the lead, and from five demonstrations a clone with
        the vertical loops' integrals held it 69 % of the time, one without 100 %
        (docs/results/memory.md)."""
        return "none"

    # the lead's heading and bank as bugs; the slot's offset (behind/ahead, right/left,
    # below/above) and the closure rate, in words and on a diagram
    guidance = (
        Line("lead_heading_deg", "deg", "heading", "bug", "the lead's heading"),
        Line("lead_roll_deg", "deg", "bank", "bug", "the lead's bank"),
        Line("behind_slot_ft", "ft", "slot", "guidance", "off the slot, along"),
        Line("right_of_slot_ft", "ft", "slot", "guidance", "off the slot, across"),
        Line("below_slot_ft", "ft", "slot", "guidance", "off the slot, height"),
        Line("behind_slot_rate_fps", "ft/s", "slot", "guidance", "closure"),
    )

    expert_targets = Targets(
        vertical_source="below_slot_ft",
        lateral="track",
        lateral_source="lead_heading_error_deg",
        track_source="right_of_slot_ft",
        track_gain=0.2,
        station_source="behind_slot_ft",
        station_rate_source="behind_slot_rate_fps",
        relative=frozenset({"vertical", "lateral"}),
    )
    expert_on_display: ClassVar[Mapping[str, Any]] = {
        "lateral_source": "lead_heading_deg",
        "relative": frozenset({"vertical"}),
    }

    def guidance_values(self, observed: Mapping[str, float]) -> list[float]:
        o = observed
        return [
            wrap_360(o["heading_deg"] + o["lead_heading_error_deg"]),
            o["lead_roll_deg"],
            o["behind_slot_ft"],
            o["right_of_slot_ft"],
            o["below_slot_ft"],
            o["behind_slot_rate_fps"],
        ]

    def draw_plan(self, state: np.ndarray, rng: np.random.Generator) -> dict[str, Any]:
        profile = self._profile()
        heading = float(state[_HDG])
        gap = float(rng.uniform(100.0, 300.0))
        side, up = float(rng.uniform(-100.0, 100.0)), float(rng.uniform(-100.0, 100.0))
        ahead, left = self.slot[0] + gap, self.slot[1] + side
        h = math.radians(heading)
        north = ahead * math.cos(h) + left * math.sin(h)
        east = ahead * math.sin(h) - left * math.cos(h)
        lat, lon = offset_position(float(state[_LAT]), float(state[_LON]), north, east)
        speed = 0.95 * profile.cruise_kts
        ic = InitialConditions(lat, lon, float(state[_ALT]) - up, heading, speed)
        alt_t, hdg_t = _lead_schedule(
            rng, self.max_steps, self.dt, ic.altitude_ft, heading, profile.maneuver_scale
        )
        # the lead's target is a calibrated airspeed: 95 % of cruise at the reference's
        # altitude, as much less higher up as calibrated airspeed falls short of true there
        reference = _tas_over_cas(REFERENCE_PROFILE.cruise_altitude_ft)
        target = speed * (reference / _tas_over_cas(profile.cruise_altitude_ft))
        track = np.round(self._fly_lead(ic, alt_t, hdg_t, target), 8)
        self._lead = track  # as an array, for every step's observation
        return {"slot_ft": list(self.slot), "lead": track.tolist()}

    def _fly_lead(
        self, ic: InitialConditions, alt_t: np.ndarray, hdg_t: np.ndarray, speed: float
    ) -> np.ndarray:
        """The lead's (lat, lon, altitude, roll, pitch, heading) at every step."""
        if self.lead_pilot is None:
            raise ConfigError(
                "the formation task's lead is flown by an autopilot the environment provides: "
                "fly it in an env (AircraftEnv, OfflineEnv), or set task.lead_pilot = "
                "gymfg_il.controllers.lead.LeadPilot(model, dt)"
            )
        throttle = self._profile().cruise_throttle
        return np.asarray(self.lead_pilot(ic, alt_t, hdg_t, speed, throttle, _LEAD_IDX))

    @classmethod
    def geometry(
        cls,
        plan: dict[str, Any],
        states: np.ndarray,
        steps: np.ndarray,
        track: np.ndarray | None = None,
    ) -> dict[str, np.ndarray]:
        """Where ``states`` (rows, at agent ``steps``) are from the slot and the lead
        (``track``: the plan's lead as an array, when the caller has it)."""
        track = np.asarray(plan["lead"]) if track is None else track
        lead = track[np.minimum(steps, len(track) - 1)]
        cos_lat = math.cos(math.radians(float(lead[0, 0])))
        north = (states[:, _LAT] - lead[:, 0]) * FT_PER_DEG
        east = wrap_180(states[:, _LON] - lead[:, 1]) * FT_PER_DEG * cos_lat
        h = np.radians(lead[:, 5])
        fwd = north * np.cos(h) + east * np.sin(h)  # ahead of the lead (ft)
        right = -north * np.sin(h) + east * np.cos(h)
        behind, right_of = plan["slot_ft"]
        return {
            "behind": -(fwd + behind),
            "right": right - right_of,
            "below": lead[:, 2] - states[:, _ALT],
            "separation": np.sqrt(north**2 + east**2 + (lead[:, 2] - states[:, _ALT]) ** 2),
            "lead": lead,
        }

    def extras(self, state: np.ndarray, step: int) -> list[float]:
        g = self.geometry(self.plan, state[None], np.array([step]), self._lead)
        behind = float(g["behind"][0])
        if step == 0:
            self._last_behind = behind
        rate, self._last_behind = (behind - self._last_behind) / self.dt, behind
        lead = g["lead"][0]
        return [
            behind,
            rate,
            float(g["right"][0]),
            float(g["below"][0]),
            wrap_180(float(lead[5]) - float(state[_HDG])),
            float(lead[3]),
            float(lead[4]),
        ]

    def shaped(self, extras: np.ndarray, state: np.ndarray) -> float:
        return closeness(math.sqrt(extras[0] ** 2 + extras[2] ** 2 + extras[3] ** 2), 100.0)

    @classmethod
    def landmarks(cls, plan: dict[str, Any], step: int) -> list[Landmark]:
        """The lead, where its track has it at agent ``step``."""
        track = plan["lead"]
        lat, lon, alt, roll, pitch, heading = track[min(step, len(track) - 1)]
        return [Landmark("aircraft", lat, lon, alt, heading, roll, pitch)]

    @classmethod
    def judge(
        cls, plan: dict[str, Any], states: np.ndarray, dt: float, gusty: bool = False
    ) -> Verdict:
        g = cls.geometry(plan, states, np.arange(len(states)))
        closest = float(g["separation"].min())
        if closest < cls.min_separation_ft:
            return Verdict(False, f"came within {closest:.0f} ft of the lead")
        off = np.sqrt(g["behind"] ** 2 + g["right"] ** 2 + g["below"] ** 2)
        held = off[round(cls.join_s / dt) :]
        if not len(held):
            return Verdict(False, f"ended before {cls.join_s:g} s")
        worst = int(held.argmax())
        if gusty and held.mean() > cls.tolerance_ft:
            return Verdict(False, f"{held.mean():.0f} ft from the slot on average")
        if not gusty and held[worst] > cls.tolerance_ft:
            when = (worst + round(cls.join_s / dt)) * dt
            return Verdict(False, f"{held[worst]:.0f} ft from the slot at {when:.1f} s")
        measures = (Measure.of("off the slot", "ft", held, cls.tolerance_ft, mean=gusty),)
        mean, most = held.mean(), held.max()
        how = f"{mean:.0f} ft off on average" if gusty else f"at most {most:.0f} ft off"
        return Verdict(True, f"in the slot from {cls.join_s:g} s, {how}", measures)
