"""Feeding FlightGear from a world: native-fdm packets for the aircraft that have views, and
every other aircraft as multiplayer traffic, paced to real time while anything is attached."""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from typing import Protocol

import numpy as np

from gymfg_il.aircraft import Aircraft
from gymfg_il.errors import ConfigError
from gymfg_il.flightgear.multiplayer import TrafficSender
from gymfg_il.flightgear.netfdm import FlightGearSender
from gymfg_il.sim.properties import ORIENTATION, POSITION, indices
from gymfg_il.sim.simulation import Simulation


class Slot(Protocol):
    """What the views read of an aircraft of the world (``envs.slots.Slot``)."""

    @property
    def callsign(self) -> str: ...

    aircraft: Aircraft
    sim: Simulation
    state: np.ndarray


class Displays:
    """The FlightGear views of one world (``EnvConfig.views`` and ``traffic``)."""

    def __init__(
        self,
        slots: Mapping[str, Slot],
        views: Mapping[str, Sequence[int]] | None,
        traffic: Mapping[str, Sequence[int]] | None,
        dt: float,
    ) -> None:
        for what, table in (("views", views), ("traffic", traffic)):
            unknown = sorted(set(table or {}) - set(slots))
            if unknown:
                raise ConfigError(f"{what} name {unknown}, which are not in this simulation")
        self.slots = slots
        self.dt = dt
        self.senders = {c: FlightGearSender(list(p)) for c, p in (views or {}).items()}
        self.traffic = {c: TrafficSender(list(p)) for c, p in (traffic or {}).items()}
        self._pose_idx = indices(POSITION + ORIENTATION)
        # aircraft simulated elsewhere (an online client's opponents): callsign -> lat, lon,
        # altitude, roll, pitch, heading, for the views' traffic
        self.others: dict[str, np.ndarray] = {}
        self._next_frame = 0.0

    def __bool__(self) -> bool:
        return bool(self.senders or self.traffic)

    def show(self) -> None:
        """Send this step to every view, at real time (FlightGear drops faster packets)."""
        for callsign, sender in self.senders.items():
            sim = self.slots[callsign].sim
            sender.send(sim.fdm, sim.engines)
        if self.traffic:
            self._send_traffic()
        now = time.perf_counter()
        if self._next_frame > now:
            time.sleep(self._next_frame - now)
        self._next_frame = max(now, self._next_frame) + self.dt

    def _send_traffic(self) -> None:
        poses = [
            (s.callsign, s.aircraft.model, s.state[self._pose_idx]) for s in self.slots.values()
        ]
        # an online client's opponents; their model is unknown here: FlightGear's fallback
        poses += [(callsign, "", pose) for callsign, pose in self.others.items()]
        for viewer, sender in self.traffic.items():
            for callsign, model, pose in poses:
                if callsign != viewer and np.isfinite(pose).all():
                    sender.send(callsign, model, pose)

    def close(self) -> None:
        for view in self.senders.values():
            view.close()
        for traffic in self.traffic.values():
            traffic.close()
        self.senders, self.traffic = {}, {}
