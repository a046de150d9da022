"""The PettingZoo adapter: every aircraft of every team is an agent (``parallel_env(teams)``).

Each agent (named by callsign) observes a dict: ``observation`` (its task's observation,
float32) and ``opponents`` (what it may see of every other team's aircraft, one row each,
float64, the columns of ``opponent_view``). Actions are ``[aileron, elevator, rudder,
throttle]``. Rewards, terminations and the time limit are those of the offline env.

With ``multiplayer`` (a ``MultiplayerConfig``), people flying FlightGear join as opponents of
every team, exactly as in ``OfflineEnv``: the aircraft heard on ``listen_port`` follow the
simulation's rows in ``opponents`` (position and orientation only, sorted by callsign), each
agent's info names the rows (``opponent_callsigns``), a reward target naming a callsign not
simulated here is looked for among them, one silent for ``timeout_s`` leaves, every aircraft
here is sent to ``send_to``, and ``step`` keeps to the wall clock (real time). Their number
changes as people come and go, so ``opponents`` is then a ``gymnasium.spaces.Sequence`` of
rows (``stack=True``: an ``(n, len(opponent_view))`` array) rather than a fixed-shape Box.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import gymnasium as gym
import numpy as np
from pettingzoo import ParallelEnv

from gymfg_il.envs.actions import Controls, controls
from gymfg_il.envs.config import EnvConfig
from gymfg_il.envs.team import Team
from gymfg_il.envs.world import World
from gymfg_il.errors import ActionError, EnvStateError
from gymfg_il.flightgear.peers import MultiplayerConfig
from gymfg_il.sim.properties import ACTION_HIGH, ACTION_LOW, BY_NAME
from gymfg_il.sim.timing import DEFAULT_AGENT_HZ, DEFAULT_SIM_HZ


class GymFGParallelEnv(ParallelEnv):
    """Teams of aircraft as a PettingZoo ParallelEnv; build it with ``parallel_env``."""

    metadata = {"name": "gymfg_parallel_v0", "render_modes": []}  # noqa: RUF012

    def __init__(self, teams: Sequence[Team], config: EnvConfig) -> None:
        self.world = World(teams, config)
        self.possible_agents = [s.callsign for s in self.world.slots]
        self.agents: list[str] = []
        view = config.opponent_view
        v_low = np.array([BY_NAME[n].low for n in view])
        v_high = np.array([BY_NAME[n].high for n in view])
        self._obs_spaces: dict[str, gym.spaces.Space[Any]] = {}
        self.multiplayer = config.multiplayer is not None
        for slot in self.world.slots:
            n_opp = len(self.world.opponents_of(slot.team))
            low, high = slot.task.observation_bounds()
            opponents: gym.spaces.Space[Any] = (
                # FlightGear aircraft come and go: as many rows as there are opponents now
                gym.spaces.Sequence(gym.spaces.Box(v_low, v_high, dtype=np.float64), stack=True)
                if self.multiplayer
                else gym.spaces.Box(
                    np.tile(v_low, (n_opp, 1)), np.tile(v_high, (n_opp, 1)), dtype=np.float64
                )
            )
            self._obs_spaces[slot.callsign] = gym.spaces.Dict(
                {"observation": gym.spaces.Box(low, high, dtype=np.float32), "opponents": opponents}
            )
        self._act_space = gym.spaces.Box(ACTION_LOW, ACTION_HIGH, dtype=np.float32)
        self._rng = np.random.default_rng()
        self.render_mode = None

    def observation_space(self, agent: str) -> gym.spaces.Space[Any]:
        return self._obs_spaces[agent]

    def action_space(self, agent: str) -> gym.spaces.Space[Any]:
        return self._act_space

    def _observe(self) -> dict[str, dict[str, np.ndarray]]:
        world = self.world
        views = {t: world.opponent_states(t) for t in world.team_slots}
        return {
            s.callsign: {"observation": world.observation(s), "opponents": views[s.team]}
            for s in world.slots
            if s.callsign in self.agents
        }

    def reset(
        self, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, Any], dict[str, Any]]:
        if seed is not None:
            self._rng = np.random.default_rng(seed)
        self.world.reset(self._rng, (options or {}).get("initial_conditions"))
        self.agents = list(self.possible_agents)
        infos: dict[str, dict[str, Any]] = {a: {} for a in self.agents}
        if self.multiplayer:
            for s in self.world.slots:
                infos[s.callsign]["opponent_callsigns"] = self.world.opponent_callsigns(s.team)
        return self._observe(), infos

    def step(self, actions: dict[str, Any]) -> tuple[dict[str, Any], ...]:
        if not self.agents:
            raise EnvStateError("call reset() before step(), and again after an episode ends")
        unknown = set(actions) - set(self.agents)
        if unknown:
            raise ActionError(f"actions for agents that are not acting: {sorted(unknown)}")
        missing = [a for a in self.agents if a not in actions]
        if missing:
            raise ActionError(f"no action for agents {missing}; every live agent needs one")
        world = self.world
        ctrl: list[Controls | None] = [
            controls(actions[s.callsign], f"action of {s.callsign!r}")
            if s.callsign in self.agents
            else None
            for s in world.slots
        ]
        world.advance(ctrl)
        live = [s for s in world.slots if s.callsign in self.agents]
        obs = self._observe()
        rewards = {s.callsign: float(s.reward) for s in live}
        terms = {s.callsign: s.terminated for s in live}
        truncs = {s.callsign: world.truncated and not s.terminated for s in live}
        infos: dict[str, dict[str, Any]] = {
            s.callsign: ({"reason": s.reason} if s.reason else {}) for s in live
        }
        if self.multiplayer:  # who the rows of ``opponents`` are
            for s in live:
                infos[s.callsign]["opponent_callsigns"] = world.opponent_callsigns(s.team)
        self.agents = [a for a in self.agents if not (terms[a] or truncs[a])]
        return obs, rewards, terms, truncs, infos

    def close(self) -> None:
        if self.world.slots:
            pool = self.world.pool
            self.world.close()
            pool.close()


def parallel_env(
    teams: Sequence[Team],
    *,
    sim_hz: int = DEFAULT_SIM_HZ,
    agent_hz: int = DEFAULT_AGENT_HZ,
    opponent_view: tuple[str, ...] | None = None,
    scenario: Any = None,
    multiplayer: MultiplayerConfig | None = None,
) -> GymFGParallelEnv:
    """A PettingZoo ParallelEnv over ``teams`` (every aircraft an agent, named by callsign).

    ``multiplayer``: FlightGear aircraft heard become opponents of every team, in real time
    (see the module docstring); the env listens from here until ``close``.
    """
    config = (
        EnvConfig(sim_hz, agent_hz, scenario=scenario, multiplayer=multiplayer)
        if opponent_view is None
        else EnvConfig(sim_hz, agent_hz, tuple(opponent_view), scenario, multiplayer=multiplayer)
    )
    return GymFGParallelEnv(teams, config)
