"""The offline environment: every team simulated in this process (the paper's design).

The paper's control loop runs as written, with gymnasium's split of ``done``::

    team_state, opponent_states = env.reset(team)
    done = False
    while not done:
        team_actions = [agent.act(s, opponent_states) for s, agent in zip(team_state, AGENTS)]
        team_state, opponent_states, rewards, terminated, truncated, info = env.step(
            np.hstack(team_actions))
        done = terminated or truncated
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from gymfg_il.agent import Agent
from gymfg_il.envs.actions import Controls, controls, team_controls
from gymfg_il.envs.config import EnvConfig
from gymfg_il.envs.scenarios import Scenario
from gymfg_il.envs.team import Team
from gymfg_il.envs.world import SimPool, World
from gymfg_il.errors import ConfigError, EnvStateError
from gymfg_il.flightgear.peers import MultiplayerConfig
from gymfg_il.sim.initial import InitialConditions
from gymfg_il.sim.properties import DEFAULT_OPPONENT_VIEW
from gymfg_il.sim.timing import DEFAULT_AGENT_HZ, DEFAULT_SIM_HZ
from gymfg_il.sim.weather import Weather

TeamState = list[np.ndarray]


class OfflineEnv:
    """All teams in one process: the caller's team acts through ``step``, the other teams
    are flown by the agents given here.

    Args:
        opponents: ``[(team, [agent per aircraft in roster order]), ...]``: teams flown by the
            environment itself.
        sim_hz, agent_hz, opponent_view, scenario, views, traffic, weather: see ``EnvConfig``
            (views: callsign -> FlightGear UDP ports; traffic: callsign -> the multiplayer
            ports of its views, where the other aircraft are shown).
        multiplayer: FlightGear multiplayer (``MultiplayerConfig``): people flying FlightGear
            join as opponents, heard on ``listen_port``; every aircraft here is sent to its
            ``send_to`` addresses. While it is set, ``step`` keeps to the wall clock (one
            step per ``1 / agent_hz`` seconds), because a person's aircraft flies in real
            time.
        trimmed_starts: trimmed straight, level starts (the default), or untrimmed ones:
            see ``EnvConfig``.

    ``reset(team)`` returns ``(team_state, opponent_states)``: one observation (float32) per
    aircraft of ``team`` in roster order, and an ``(n, len(opponent_view))`` array of what the
    team sees of every other team's aircraft (position and orientation by default).
    ``step(np.hstack(actions))`` returns ``(team_state, opponent_states, rewards, terminated,
    truncated, info)``: ``rewards`` has one entry per aircraft; ``terminated`` is True once
    every aircraft of the team has crashed, stalled or left the envelope (``info["reasons"]``
    says which and why); ``truncated`` is True at the time limit (the smallest
    ``episode_time_s`` among the teams). An aircraft that terminates stops being simulated,
    its reward is 0 and its action is ignored from then on; from the next step it is absent
    from the others' ``opponent_states`` (``info["opponent_callsigns"]`` names the rows) and
    from their rewards' ``ctx.targets``, as an online server drops a team that left.

    FlightGear aircraft (``multiplayer``) come after this simulation's aircraft in
    ``opponent_states`` (by callsign, position and orientation only); one silent for
    ``timeout_s`` leaves the rows and ``ctx.targets`` the same way. A reward target naming a
    callsign that is not simulated here (``c172p("person")``) is looked for among them.
    """

    def __init__(
        self,
        opponents: Sequence[tuple[Team, Sequence[Agent]]] = (),
        *,
        sim_hz: int = DEFAULT_SIM_HZ,
        agent_hz: int = DEFAULT_AGENT_HZ,
        opponent_view: tuple[str, ...] = DEFAULT_OPPONENT_VIEW,
        scenario: Scenario | None = None,
        views: Mapping[str, Sequence[int]] | None = None,
        traffic: Mapping[str, Sequence[int]] | None = None,
        weather: Weather | None = None,
        multiplayer: MultiplayerConfig | None = None,
        trimmed_starts: bool = True,
    ) -> None:
        self.config = EnvConfig(
            sim_hz,
            agent_hz,
            tuple(opponent_view),
            scenario,
            views,
            traffic,
            weather or Weather(),
            multiplayer,
            trimmed_starts,
        )
        self.opponents: list[tuple[Team, list[Agent]]] = []
        for entry in opponents:
            if not (isinstance(entry, tuple) and len(entry) == 2 and isinstance(entry[0], Team)):
                raise ConfigError(
                    f"opponents entries must be (Team, [agents]) pairs, got {entry!r}"
                )
            team, agents = entry
            agents = list(agents)
            if len(agents) != len(team.roster):
                raise ConfigError(
                    f"team {team.name!r} has {len(team.roster)} aircraft but {len(agents)} agents; "
                    "give one agent per aircraft, in roster order"
                )
            for agent in agents:
                if not isinstance(agent, Agent):
                    raise ConfigError(
                        f"{agent!r} is not an Agent (needs reset(seed) and act(obs, opp))"
                    )
            self.opponents.append((team, agents))
        self._pool = SimPool(sim_hz, agent_hz)
        self.world: World | None = None
        self.team: Team | None = None
        self._rng = np.random.default_rng()
        self._done = True

    @property
    def dt(self) -> float:
        return self.config.dt

    def configure(self, team: Team) -> None:
        """Build the simulation around ``team`` (reset does this on first use)."""
        if not isinstance(team, Team):
            raise ConfigError(f"reset(team) needs a Team, got {team!r}")
        if self.world is not None:
            self.world.close()
        teams = [team] + [t for t, _ in self.opponents]
        self.world = World(teams, self.config, self._pool)
        self.team = team

    def reset(
        self,
        team: Team | None = None,
        *,
        seed: int | None = None,
        options: Mapping[str, Any] | None = None,
    ) -> tuple[TeamState, np.ndarray]:
        """Start an episode; ``team`` is needed the first time (later ones may repeat it).

        ``options["initial_conditions"]``, a ``{callsign: InitialConditions}`` dict, overrides
        the start of those aircraft for this episode.
        """
        if team is not None and team is not self.team:
            self.configure(team)
        if self.world is None or self.team is None:
            raise EnvStateError("the first reset needs your team: env.reset(team)")
        if seed is not None:
            self._rng = np.random.default_rng(seed)
        options = dict(options or {})
        overrides: dict[str, InitialConditions] = options.pop("initial_conditions", {})
        if options:
            raise ConfigError(f"unknown reset options {sorted(options)}; known: initial_conditions")
        self.world.reset(self._rng, overrides)
        for opponent, agents in self.opponents:
            slots = self.world.team_slots[opponent.name]
            for agent, slot in zip(agents, slots, strict=True):
                agent.reset(int(self._rng.integers(2**31)))
                start = getattr(agent, "start_from", None)
                if start is not None:  # a controller starts from the trim the aircraft has
                    start(slot.action)
        self._done = False
        return self._team_state(), self.world.opponent_states(self.team.name, present_only=True)

    def step(
        self, team_actions: object
    ) -> tuple[TeamState, np.ndarray, np.ndarray, bool, bool, dict[str, Any]]:
        world, team = self.world, self.team
        if world is None or team is None or self._done:
            raise EnvStateError(
                "call env.reset(team) before step (and again after an episode ends)"
            )
        own = team_controls(team_actions, team.callsigns)
        actions: list[Controls | None] = list(own)
        for other, agents in self.opponents:
            opp_view = world.opponent_states(other.name, present_only=True)
            for slot, agent in zip(world.team_slots[other.name], agents, strict=True):
                if slot.terminated:
                    actions.append(None)
                    continue
                obs = world.observation(slot)
                actions.append(controls(agent.act(obs, opp_view), f"action of {slot.callsign!r}"))
        world.advance(actions)
        slots = world.team_slots[team.name]
        rewards = np.array([s.reward for s in slots])
        terminated = all(s.terminated for s in slots)
        truncated = world.truncated and not terminated
        self._done = terminated or truncated
        info = {
            "step": world.steps,
            "time_s": world.steps * world.dt,
            "terminated": [s.terminated for s in slots],
            "reasons": {s.callsign: s.reason for s in world.slots if s.reason},
            "opponent_callsigns": world.opponent_callsigns(team.name, True),
        }
        return (
            self._team_state(),
            world.opponent_states(team.name, present_only=True),
            rewards,
            terminated,
            truncated,
            info,
        )

    def _team_state(self) -> TeamState:
        assert self.world is not None and self.team is not None
        world = self.world
        return [world.observation(s) for s in world.team_slots[self.team.name]]

    def close(self) -> None:
        if self.world is not None:
            self.world.close()
            self.world = None
        self._pool.close()
