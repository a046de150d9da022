"""The PettingZoo adapter: every aircraft of every team is an agent (``parallel_env(teams)``).

Each agent (named by callsign) observes a dict: ``observation`` (its task's observation,
float32) and ``opponents`` (what it may see of every other team's aircraft, one row each,
float64, the columns of ``opponent_view``). Actions are ``[aileron, elevator, rudder,
throttle]``. Rewards, terminations and the time limit are those of the offline env.
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
        for slot in self.world.slots:
            n_opp = len(self.world.opponents_of(slot.team))
            low, high = slot.task.observation_bounds()
            self._obs_spaces[slot.callsign] = gym.spaces.Dict(
                {
                    "observation": gym.spaces.Box(low, high, dtype=np.float32),
                    "opponents": gym.spaces.Box(
                        np.tile(v_low, (n_opp, 1)), np.tile(v_high, (n_opp, 1)), dtype=np.float64
                    ),
                }
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
        return self._observe(), {a: {} for a in self.agents}

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
        infos = {s.callsign: ({"reason": s.reason} if s.reason else {}) for s in live}
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
) -> GymFGParallelEnv:
    """A PettingZoo ParallelEnv over ``teams`` (every aircraft an agent, named by callsign)."""
    config = (
        EnvConfig(sim_hz, agent_hz, scenario=scenario)
        if opponent_view is None
        else EnvConfig(sim_hz, agent_hz, tuple(opponent_view), scenario)
    )
    return GymFGParallelEnv(teams, config)
