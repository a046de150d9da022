"""The one rollout loop: agents fly an env step by step, and every step of every aircraft comes
out as a ``Step`` record.

    rollout = Rollout(env, [pilot], experts=[expert], noise=0.02)
    episode = rollout.episode(seed)            # reset and fly to the end
    rollout.reset(seed); tick = rollout.step()  # or one step at a time (the manual session)

``env`` is a gymnasium ``AircraftEnv`` (one pilot) or an ``OfflineEnv`` / ``OnlineEnv`` with
``team=`` (one pilot per aircraft of the team, in roster order; the other teams of an offline
env are flown by the env and recorded too). Each step:

1. every pilot chooses from its aircraft's observation (and the opponent states); the choice
   is clipped to the action contract (``envs.actions.clip``);
2. an expert, where given, labels the same observation (else the pilot's choice is the label);
3. DART noise, where asked, perturbs every control of what is flown (drawn from the seed);
4. the env steps; what every aircraft really flew, its reward, state and flags are read back
   from the world, so the records hold what JSBSim was given.

An expert with a ``track(action, from_observation=True)`` method (the autopilot) is told what
was flown, so its integrators follow the real flight (DAgger). A pilot with an ``intervening``
attribute (a person taking over from an assistant) marks its steps as interventions.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from gymfg_il.agent import Agent
from gymfg_il.envs.actions import clip
from gymfg_il.envs.single import AircraftEnv
from gymfg_il.envs.team import Team
from gymfg_il.envs.world import World
from gymfg_il.errors import ConfigError, EnvStateError
from gymfg_il.rollout.records import (
    Episode,
    EpisodeBuilder,
    OpponentView,
    Start,
    Step,
    Tick,
    reset_record,
)

NOISE_STREAM = 7919  # the noise of episode ``seed`` is drawn from default_rng([seed, 7919])


def starts(world: World) -> list[Start]:
    """Every aircraft of ``world`` as it starts the episode just reset."""
    return [
        Start(
            s.callsign,
            s.team,
            s.aircraft.model,
            s.task.describe(),
            s.task.target_value(0),
            s.state.copy(),
            world.observation(s),
        )
        for s in world.slots
    ]


def observe_live(world: World) -> dict[str, np.ndarray]:
    """The observation of every aircraft still flying (what its pilot chooses from)."""
    return {s.callsign: world.observation(s) for s in world.slots if not s.terminated}


def step_records(
    world: World,
    before: dict[str, np.ndarray],
    labels: dict[str, np.ndarray],
    interventions: dict[str, bool],
    ended: bool,
) -> list[Step]:
    """What the step just taken did to every aircraft that was flying (``before``): its
    executed action, reward, state and flags as the world has them. ``ended``: the episode
    ends with this step (an aircraft still flying is then truncated: the time limit, the
    server, or its opponents all having stopped cut its flight short)."""
    out = []
    for slot in world.slots:
        obs = before.get(slot.callsign)
        if obs is None:
            continue
        action = slot.action
        out.append(
            Step(
                slot.callsign,
                slot.team,
                world.steps,
                obs,
                action,
                labels.get(slot.callsign, action),
                float(slot.reward),
                slot.state,
                slot.terminated,
                ended and not slot.terminated,
                interventions.get(slot.callsign, False),
                slot.reason,
            )
        )
    return out


def team_views(
    world: World, names: tuple[str, ...], own: tuple[str, list[str], np.ndarray] | None = None
) -> dict[str, OpponentView]:
    """What each team of ``world`` sees of the others now; ``own`` = (team, callsigns, rows)
    replaces the world's view for a team whose opponents are elsewhere (online)."""
    views = {}
    for team in world.team_slots:
        if own is not None and team == own[0]:
            views[team] = OpponentView(list(own[1]), names, np.asarray(own[2], np.float64))
            continue
        # the rows name this simulation's opponents, then the FlightGear aircraft heard
        callsigns = world.opponent_callsigns(team, present_only=True)
        rows = world.opponent_states(team, present_only=True)
        views[team] = OpponentView(callsigns, names, rows)
    return views


class Rollout:
    """Fly ``pilots`` in ``env`` (see the module docstring).

    Args:
        env: an ``AircraftEnv``, or an ``OfflineEnv``/``OnlineEnv`` (then give ``team``).
        pilots: one Agent per aircraft flown through the env's ``step``.
        experts: a labelling Agent (or None) per pilot.
        noise: std of Gaussian noise on each executed control, throttle too (DART); 0 = none.
        team: the team the pilots fly, for team envs.
    """

    def __init__(
        self,
        env: Any,
        pilots: Sequence[Agent],
        *,
        experts: Sequence[Agent | None] | None = None,
        noise: float = 0.0,
        team: Team | None = None,
    ) -> None:
        self.env, self.pilots, self.team = env, list(pilots), team
        self.solo = isinstance(getattr(env, "env", env), AircraftEnv)  # (a Recorder wraps)
        if not self.solo and team is None:
            raise ConfigError("a team env needs the team its pilots fly: Rollout(..., team=team)")
        n = 1 if self.solo else len(team.roster)  # type: ignore[union-attr]
        if len(self.pilots) != n:
            raise ConfigError(f"{n} aircraft but {len(self.pilots)} pilots; give one each")
        self.experts: list[Agent | None] = list(experts) if experts is not None else [None] * n
        if len(self.experts) != n:
            raise ConfigError(f"{n} aircraft but {len(self.experts)} experts; give one each")
        if not (isinstance(noise, (int, float)) and noise >= 0):
            raise ConfigError(f"noise={noise!r} must be a number >= 0")
        self.noise = float(noise)
        self.done = True
        self._obs: list[np.ndarray] = []
        self._opponents: np.ndarray | None = None
        self._after: dict[str, np.ndarray] = {}
        self._rng = np.random.default_rng()

    @property
    def world(self) -> World:
        world: World | None = self.env.world
        if world is None:
            raise EnvStateError("the env has no world yet: reset the rollout first")
        return world

    def _own(self) -> list[Any]:
        world = self.world
        return [world.slots[0]] if self.solo else world.team_slots[self.team.name]  # type: ignore[union-attr]

    def reset(self, seed: int, options: dict[str, Any] | None = None) -> list[Start]:
        """Reset the env, the pilots and the experts with ``seed``; the aircraft's starts."""
        if self.solo:
            obs, _ = self.env.reset(seed=seed, options=options)
            self._obs, self._opponents = [obs], None
        else:
            team_state, opponents = self.env.reset(self.team, seed=seed, options=options)
            self._obs, self._opponents = list(team_state), opponents
        for agent in (*self.pilots, *self.experts):
            if agent is not None:
                agent.reset(seed)
        for slot, pilot, expert in zip(self._own(), self.pilots, self.experts, strict=True):
            for agent in (pilot, expert):
                start = getattr(agent, "start_from", None)
                if start is not None:
                    start(slot.action)
        self._rng = np.random.default_rng([seed, NOISE_STREAM])
        self.done = False
        return starts(self.world)

    def step(self) -> Tick:
        """Fly one agent step; a record of every aircraft that flew it."""
        if self.done:
            raise EnvStateError("reset the rollout before stepping it (and after each episode)")
        world = self.world
        own = self._own()
        before = observe_live(world)
        labels: dict[str, np.ndarray] = {}
        interventions: dict[str, bool] = {}
        flown = []
        for slot, obs, pilot, expert in zip(own, self._obs, self.pilots, self.experts, strict=True):
            clean = clip(pilot.act(obs, self._opponents))
            action = clean
            if self.noise:
                action = clean.copy()
                # every control, the throttle too: noise on the surfaces alone never showed
                # the speed loop at work, and a clone of it left the throttle still in gusts
                action += self._rng.normal(0.0, self.noise, len(action))
                action = clip(action)
            if expert is not None:
                labels[slot.callsign] = clip(expert.act(obs, self._opponents))
                track = getattr(expert, "track", None)
                if track is not None:  # its integrators follow what is really flown
                    track(action, from_observation=True)
            else:
                labels[slot.callsign] = clean
            interventions[slot.callsign] = bool(getattr(pilot, "intervening", False))
            flown.append(action)
        if self.solo:
            obs, _, terminated, truncated, _ = self.env.step(flown[0])
            self._obs = [obs]
            after = {own[0].callsign: obs}
            views: dict[str, OpponentView] = {}
        else:
            team_state, opponents, _, terminated, truncated, info = self.env.step(np.hstack(flown))
            self._obs, self._opponents = list(team_state), opponents
            # every aircraft that flew, terminated now or not: the observation its step led to
            after = {c: world.observation(world.by_callsign[c]) for c in before}
            after.update({s.callsign: o for s, o in zip(own, team_state, strict=True)})
            names = tuple(getattr(self.env, "view", ()) or world.config.opponent_view)
            mine = (self.team.name, info.get("opponent_callsigns", []), opponents)  # type: ignore[union-attr]
            views = team_views(world, names, mine)
        self.done = bool(terminated or truncated)
        tick = Tick(
            world.steps,
            step_records(world, before, labels, interventions, self.done),
            views,
            self.done,
            bool(truncated),
        )
        self._after = after
        return tick

    @property
    def current(self) -> list[np.ndarray]:
        """The observations the pilots choose the next actions from (roster order)."""
        return self._obs

    @property
    def observations(self) -> dict[str, np.ndarray]:
        """Every aircraft's observation after the last step."""
        return self._after

    def episode(
        self,
        seed: int,
        options: dict[str, Any] | None = None,
        on_tick: Callable[[Tick], None] | None = None,
    ) -> Episode:
        """Reset with ``seed`` and fly to the end of the episode."""
        starts = self.reset(seed, options)
        record = reset_record(options, starts[0].callsign if self.solo else None)
        builder = EpisodeBuilder(seed, self.world_dt(), starts, record)
        while not self.done:
            tick = self.step()
            builder.add(tick, self._after)
            if on_tick is not None:
                on_tick(tick)
        return builder.episode()

    def world_dt(self) -> float:
        return float(self.env.dt)
