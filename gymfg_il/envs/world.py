"""The central state of one simulation: every aircraft of every team, stepped in lockstep.

``World`` is what the offline env, the gymnasium and PettingZoo adapters and (later) the online
server share. It owns one ``Simulation`` per aircraft, the tasks, the reward contexts and the
clock; it knows nothing about who chooses the actions.
"""

from __future__ import annotations

import dataclasses
import logging
import math
import time
import zlib
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from gymfg_il.controllers.lead import LeadPilot
from gymfg_il.envs.actions import Controls
from gymfg_il.envs.config import EnvConfig
from gymfg_il.envs.slots import SimPool, Slot
from gymfg_il.envs.team import Team, build_task, check_unique
from gymfg_il.errors import ConfigError
from gymfg_il.flightgear.display import Displays
from gymfg_il.flightgear.multiplayer import CALLSIGN_BYTES
from gymfg_il.flightgear.peers import MultiplayerLink, Peer
from gymfg_il.sim.initial import InitialConditions
from gymfg_il.sim.properties import ORIENTATION, POSITION, StateView, indices
from gymfg_il.sim.timing import episode_steps
from gymfg_il.tasks.base import diverged

log = logging.getLogger(__name__)

__all__ = ["EnvConfig", "SimPool", "Slot", "World"]


class World:
    """All aircraft of all teams, stepped together at ``config.agent_hz``."""

    def __init__(
        self,
        teams: Sequence[Team],
        config: EnvConfig,
        pool: SimPool | None = None,
        external_targets: bool = False,
    ):
        """``external_targets``: reward targets outside these teams are allowed (an online
        env); they are seen through ``external[callsign]``, filled from the central state."""
        if not teams:
            raise ConfigError("a simulation needs at least one Team")
        check_unique(teams)
        self.teams = list(teams)
        self.config = config
        self.pool = pool or SimPool(config.sim_hz, config.agent_hz)
        self.view_idx = indices(config.opponent_view)
        self.max_steps = min(episode_steps(t.episode_time_s, config.agent_hz) for t in teams)
        self.dt = config.dt
        self.slots: list[Slot] = []
        for team in teams:
            for aircraft, spec in team.roster:
                task = build_task(spec, f"team {team.name!r}, aircraft {aircraft.callsign!r}")
                task.bind(aircraft, self.dt, self.max_steps)
                if getattr(task, "needs_lead_pilot", False) and task.lead_pilot is None:  # type: ignore[attr-defined]
                    task.lead_pilot = LeadPilot(  # type: ignore[attr-defined]
                        aircraft.model, self.dt, config.sim_hz, config.trimmed_starts
                    )
                sim = self.pool.take(aircraft.model)
                self.slots.append(Slot(len(self.slots), team.name, aircraft, task, sim))
        self.by_callsign = {s.callsign: s for s in self.slots}
        self.team_slots = {t.name: [s for s in self.slots if s.team == t.name] for t in teams}
        self.external: dict[str, StateView] = {}
        # FlightGear aircraft may be reward targets: seen like an online server's teams
        self.external_targets = external_targets or config.multiplayer is not None
        self._link_reward_targets()
        self.displays = Displays(self.by_callsign, config.views, config.traffic, self.dt)
        self.link: MultiplayerLink | None = None
        self.peers: dict[str, Peer] = {}  # FlightGear aircraft heard, by callsign
        self._pose_idx = indices(POSITION + ORIENTATION)
        # which pose columns an opponent sees of a FlightGear aircraft (multiplayer only: its
        # config refuses a view beyond position and orientation)
        self._peer_cols = (
            [(POSITION + ORIENTATION).index(v) for v in config.opponent_view]
            if config.multiplayer is not None
            else []
        )
        self._next_frame = 0.0
        if config.multiplayer is not None:
            self.link = MultiplayerLink(config.multiplayer)
            log.info(
                "FlightGear multiplayer: the simulation runs in real time (%g steps/s), "
                "FlightGear's clock",
                config.agent_hz,
            )
        # anything outside to tell of each step (views, traffic, a multiplayer link)?
        self._outward = bool(self.displays) or self.link is not None
        self.steps = 0
        self.started = False

    @property
    def traffic(self) -> dict[str, Any]:
        """The multiplayer senders of the views (empty when no view shows traffic)."""
        return self.displays.traffic

    @property
    def others(self) -> dict[str, np.ndarray]:
        """Poses of aircraft simulated elsewhere, shown in the views as traffic."""
        return self.displays.others

    def _link_reward_targets(self) -> None:
        view_names = self.config.opponent_view
        for team in self.teams:
            for owner, targets in team.reward_function_targets.items():
                slot = self.by_callsign[owner.callsign]
                for target in targets:
                    source = self.by_callsign.get(target.callsign)
                    if source is None and self.external_targets:
                        view = self.external.setdefault(
                            target.callsign, StateView(np.full(len(view_names), np.nan), view_names)
                        )
                        slot.target_links.append((target.callsign, view, None, True))
                        continue
                    if source is None or source.aircraft.model != target.model:
                        raise ConfigError(
                            f"team {team.name!r}: {owner.callsign!r} takes reward target "
                            f"{target!r}, which is not in this simulation"
                        )
                    restricted = source.team != slot.team
                    view = (
                        StateView(source.state[self.view_idx], view_names)
                        if restricted
                        else StateView(source.state)
                    )
                    slot.target_links.append((target.callsign, view, source, restricted))

    # -- episode ------------------------------------------------------------------------
    def reset(
        self,
        rng: np.random.Generator,
        overrides: Mapping[str, InitialConditions] | None = None,
    ) -> None:
        """Start an episode: joint (scenario), overridden or per-task initial conditions.

        Each aircraft draws from its own stream, derived from one number drawn from ``rng``
        and its callsign, so an aircraft's start and targets do not depend on which other
        aircraft share the simulation (an online team, which simulates only itself, meets
        the same episode as in the offline env).
        """
        base = int(rng.integers(2**63))
        scenario = self.config.scenario
        ics: dict[str, InitialConditions] = {}
        if scenario is not None:
            joint = np.random.default_rng([base, 0])
            ics.update(scenario(joint, [(s.team, s.aircraft) for s in self.slots]))
            ics = {c: self._start(ic) for c, ic in ics.items()}
        ics.update(overrides or {})
        unknown = set(ics) - set(self.by_callsign)
        if unknown:
            raise ConfigError(f"initial conditions given for unknown callsigns {sorted(unknown)}")
        self.others.clear()  # last episode's opponents are not shown at this one's start
        weather = self.config.weather
        for slot in self.slots:
            key = zlib.crc32(slot.callsign.encode())
            # the air gets a stream of its own: calm episodes draw exactly what they always did
            air = weather.draw(np.random.default_rng([base, 2, key]), self.max_steps * self.dt)
            own = np.random.default_rng([base, 1 + key])
            ic = ics.get(slot.callsign) or self._start(slot.task.initial_conditions(own))
            throttle = slot.aircraft.profile.cruise_throttle
            try:
                slot.state = slot.prev_state = slot.sim.reset(ic, throttle, air)
            except ConfigError as err:  # an untrimmable start: say whose
                raise ConfigError(f"{slot.callsign} ({slot.aircraft.model}): {err}") from None
            slot.task.reset(slot.state, own)
            # the controls it starts with: a trimmed start's trim values (hands-off flight)
            slot.action = slot.prev_action = np.array(slot.sim.start_action)
            slot.reward = 0.0
            slot.terminated = False
            slot.reason = None
            slot.ended_at = None
            slot.blown = False
            slot.history.clear()
        self.steps = 0
        self.started = True
        if self.displays:
            self.displays.show()
        if self.link is not None:
            self._exchange()

    def _start(self, ic: InitialConditions) -> InitialConditions:
        """A drawn start as the config asks: untrimmed when ``trimmed_starts`` is off."""
        if self.config.trimmed_starts or not ic.trimmed:
            return ic
        return dataclasses.replace(ic, trimmed=False)

    def advance(self, actions: Sequence[Controls | None]) -> None:
        """Apply one action per slot (None for terminated aircraft), step, score, check ends."""
        self.step_physics(actions)
        self.score()

    def step_physics(self, actions: Sequence[Controls | None]) -> None:
        """Apply one action per slot and advance JSBSim; ``score`` follows (an online env
        first learns the other teams' states in between)."""
        slots = self.slots
        for slot, act in zip(slots, actions, strict=True):
            if slot.terminated or act is None:
                continue
            slot.sim.apply(*act)
            if slot.task.history_window:
                slot.history.append((slot.prev_state, slot.prev_action))
            state = slot.sim.read()
            if diverged(state):
                # not a flight (NaN, 1e35 g): shown, to itself, to the other aircraft, the
                # server and the record, at its last flown state; ``score`` ends it
                slot.blown = True
                state = slot.state
            slot.prev_state = slot.state
            slot.state = state
            slot.prev_action = slot.action
            slot.action = np.array(act)
        self.steps += 1
        if self._outward:
            if self.displays:
                self.displays.show()
            if self.link is not None:
                self._exchange()

    def _exchange(self) -> None:
        """Send our aircraft to FlightGear, hear FlightGear's, and keep to its clock (real
        time; the views pace instead when there are any)."""
        link = self.link
        assert link is not None
        for slot in self.slots:
            pose = slot.state[self._pose_idx]
            if slot.present(self.steps) and np.isfinite(pose).all():
                link.send(slot.callsign, slot.aircraft.model, pose)
        # a server may echo our own aircraft back: they are not FlightGear's
        # (compared as sent: FlightGear keeps 7 characters of a callsign)
        ours = {c[: CALLSIGN_BYTES - 1] for c in self.by_callsign}
        self.peers = {c: p for c, p in link.poll().items() if c not in ours}
        for callsign, view in self.external.items():
            peer = self.peers.get(callsign)
            view.values[:] = np.nan if peer is None else np.take(peer.pose, self._peer_cols)
        if not self.displays:
            now = time.perf_counter()
            if self._next_frame > now:
                time.sleep(self._next_frame - now)
            self._next_frame = max(now, self._next_frame) + self.dt

    def score(self) -> None:
        """Rewards and terminations of the step just taken."""
        for slot in self.slots:
            if slot.terminated:
                slot.reward = 0.0
                continue
            self._score(slot)

    def _score(self, slot: Slot) -> None:
        ctx = slot.ctx
        ctx.state.values = slot.state
        ctx.prev_state.values = slot.prev_state
        ctx.action = slot.action
        ctx.prev_action = slot.prev_action
        ctx.step = self.steps
        ctx.dt = self.dt
        task = slot.task
        ctx.target = task.target_value(self.steps)
        if slot.target_links:
            self._show_targets(slot)
        reason = "diverged" if slot.blown else task.termination(slot.state)
        if reason == "diverged":  # no flight to score: the step earns nothing
            reward = 0.0
        else:
            reward = task.reward(ctx)
            if not math.isfinite(reward):
                raise ConfigError(
                    f"the reward of {slot.callsign!r} ({type(task).__name__}) returned "
                    f"{reward!r}; rewards must be finite"
                )
        slot.reward = reward
        if reason is not None:
            slot.terminated = True
            slot.reason = reason
            slot.ended_at = self.steps

    def _show_targets(self, slot: Slot) -> None:
        """Fill ``ctx.targets`` with the reward targets that are there to be seen: an
        aircraft that terminated before this step, or one the server does not show (it has
        not joined, or it left), is absent from it: ``ctx.targets.get(callsign)`` is None."""
        shown = slot.ctx.targets
        shown.clear()
        for callsign, view, source, restricted in slot.target_links:
            if source is None:  # seen from the server: there while the server shows it
                if np.isfinite(view.values).all():
                    shown[callsign] = view
            elif source.present(self.steps):
                view.values = source.state[self.view_idx] if restricted else source.state
                shown[callsign] = view

    # -- views --------------------------------------------------------------------------
    @property
    def truncated(self) -> bool:
        return self.steps >= self.max_steps

    def observation(self, slot: Slot) -> np.ndarray:
        return slot.task.observe(slot.state, self.steps)

    def opponents_of(self, team: str, present_only: bool = False) -> list[Slot]:
        """Every other team's aircraft (``present_only``: not those that terminated before
        this step, as a server drops them)."""
        return [
            s for s in self.slots if s.team != team and (not present_only or s.present(self.steps))
        ]

    def show_peers_as(self, view: Sequence[str]) -> None:
        """Show FlightGear aircraft with these columns from now on (an online server
        announces its own opponent view); each must be a position or orientation variable."""
        pose = POSITION + ORIENTATION
        self._peer_cols = [pose.index(v) for v in view]

    def peer_row(self, callsign: str) -> np.ndarray:
        """What an opponent sees of the FlightGear aircraft ``callsign`` (one heard now)."""
        return np.take(self.peers[callsign].pose, self._peer_cols)

    def opponent_callsigns(self, team: str, present_only: bool = False) -> list[str]:
        """Who the rows of ``opponent_states`` are: ``opponents_of``, then the FlightGear
        aircraft heard (by callsign)."""
        own = [s.callsign for s in self.opponents_of(team, present_only)]
        return own + sorted(self.peers)

    def opponent_states(self, team: str, present_only: bool = False) -> np.ndarray:
        """What ``team`` sees of other teams' aircraft: (n, len(opponent_view)) float64, in
        the order of ``opponent_callsigns``: this simulation's, then FlightGear's."""
        rows = [s.state[self.view_idx] for s in self.opponents_of(team, present_only)]
        rows += [self.peer_row(c) for c in sorted(self.peers)]
        if not rows:
            return np.zeros((0, len(self.view_idx)))
        return np.stack(rows)

    def close(self) -> None:
        self.displays.close()
        if self.link is not None:
            self.link.close()
            self.link = None
        self.pool.give_back([s.sim for s in self.slots])
        self.slots = []
