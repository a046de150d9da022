"""A lead aircraft for the formation task: its own JSBSim instance flown by the autopilot
through a schedule of altitude and heading targets.

The task lives below the controllers (``tasks.formation``), so the environment hands it one
of these (``World`` does, for any task with ``needs_lead_pilot``).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from gymfg_il.aircraft import Aircraft
from gymfg_il.controllers.autopilot import Autopilot
from gymfg_il.controllers.gains import maneuver_gains
from gymfg_il.sim.initial import InitialConditions
from gymfg_il.sim.properties import ACTION_HIGH, ACTION_LOW, indices
from gymfg_il.sim.simulation import Simulation
from gymfg_il.sim.timing import DEFAULT_SIM_HZ
from gymfg_il.tasks.base import FLIGHT_VARS
from gymfg_il.tasks.experts import Targets

OWN = (*FLIGHT_VARS, "heading_deg")
_NAMES = (*OWN, "altitude_ft_target", "heading_deg_target")
_TARGETS = Targets(
    vertical_source="altitude_ft_target", lateral="heading", lateral_source="heading_deg_target"
)


class LeadPilot:
    """Fly a lead of ``model`` at ``dt`` seconds per step, JSBSim at ``sim_hz`` (its
    simulation is kept across episodes)."""

    def __init__(
        self, model: str, dt: float, sim_hz: int = DEFAULT_SIM_HZ, trimmed: bool = True
    ) -> None:
        self.model, self.dt = model, dt
        self.trimmed = trimmed  # the flight's trimmed_starts: the lead starts as the rest do
        self.sim = Simulation(model, sim_hz, round(1.0 / dt))
        self._own = indices(OWN)

    def __call__(
        self,
        ic: InitialConditions,
        altitude_targets: np.ndarray,
        heading_targets: np.ndarray,
        speed_kts: float,
        throttle: float,
        view: np.ndarray,
    ) -> np.ndarray:
        """The catalogue entries ``view`` of the lead at every step, from ``ic`` on, while
        the autopilot follows the targets (one per step) at ``speed_kts``."""
        targets = Targets(**{**_TARGETS.__dict__, "speed_source": float(speed_kts)})
        bank = Aircraft(self.model, "lead").profile.bank_deg  # flown as the maneuvers are
        gains = maneuver_gains(self.model, bank)
        pilot = Autopilot(_NAMES, self.model, self.dt, targets, gains)
        pilot.set_throttle_trim(throttle)
        sim = self.sim
        if ic.trimmed != self.trimmed:
            ic = dataclasses.replace(ic, trimmed=self.trimmed)
        state = sim.reset(ic, throttle)
        pilot.start_from(np.array(sim.start_action))
        track = np.empty((len(altitude_targets), len(view)))
        for i in range(len(altitude_targets)):
            track[i] = state[view]
            if i + 1 < len(altitude_targets):
                obs = np.append(state[self._own], (altitude_targets[i], heading_targets[i]))
                sim.apply(*np.clip(pilot.act(obs), ACTION_LOW, ACTION_HIGH))
                state = sim.read()
        return track
