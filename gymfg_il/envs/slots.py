"""What the world is made of: one ``Slot`` per aircraft (its sim, task, states, actions and
reward) and the ``SimPool`` that keeps JSBSim instances across reconfigurations."""

from __future__ import annotations

from collections import deque
from collections.abc import Sequence

import numpy as np

from gymfg_il.aircraft import Aircraft
from gymfg_il.sim.properties import NAMES, StateView
from gymfg_il.sim.simulation import Simulation
from gymfg_il.tasks.base import Task
from gymfg_il.tasks.rewards import RewardContext

__all__ = ["SimPool", "Slot"]


class SimPool:
    """JSBSim instances kept across reconfigurations, so each is built once per model."""

    def __init__(self, sim_hz: int, agent_hz: int) -> None:
        self.sim_hz, self.agent_hz = sim_hz, agent_hz
        self._free: dict[str, list[Simulation]] = {}

    def take(self, model: str) -> Simulation:
        free = self._free.get(model)
        return free.pop() if free else Simulation(model, self.sim_hz, self.agent_hz)

    def give_back(self, sims: Sequence[Simulation]) -> None:
        for sim in sims:
            self._free.setdefault(sim.model, []).append(sim)

    def close(self) -> None:
        for sims in self._free.values():
            for sim in sims:
                sim.close()
        self._free.clear()


class Slot:
    """One aircraft's place in the world: its sim, task, last states, actions and reward."""

    __slots__ = (
        "action",
        "aircraft",
        "blown",
        "ctx",
        "ended_at",
        "history",
        "index",
        "prev_action",
        "prev_state",
        "reason",
        "reward",
        "sim",
        "state",
        "target_links",
        "task",
        "team",
        "terminated",
    )

    def __init__(self, index: int, team: str, aircraft: Aircraft, task: Task, sim: Simulation):
        self.index = index
        self.team = team
        self.aircraft = aircraft
        self.task = task
        self.sim = sim
        self.state: np.ndarray = np.zeros(len(NAMES), dtype=np.float64)
        self.prev_state: np.ndarray = self.state
        self.action: np.ndarray = np.zeros(4)
        self.prev_action: np.ndarray = self.action
        self.reward = 0.0
        self.terminated = False
        self.reason: str | None = None
        self.ended_at: int | None = None  # the step it terminated at
        self.blown = False  # its simulation diverged (``World.step_physics``)
        self.history: deque[tuple[np.ndarray, np.ndarray]] = deque(
            maxlen=max(task.history_window, 1)
        )
        self.ctx = RewardContext(
            StateView(self.state),
            StateView(self.state),
            self.action,
            self.action,
            history=self.history,
        )
        # (callsign, view to refresh, source slot or None (seen from a server), restricted to
        # the opponent view?)
        self.target_links: list[tuple[str, StateView, Slot | None, bool]] = []

    def present(self, step: int) -> bool:
        """Whether it is still there to be seen at ``step`` (it crashed at this step or
        flies on; from the next step on, a terminated aircraft is absent)."""
        return self.ended_at is None or self.ended_at >= step

    @property
    def callsign(self) -> str:
        return self.aircraft.callsign
