"""Re-flying a recorded episode through JSBSim from its seed and actions.

The world is rebuilt from the log's flight spec (every team and aircraft), reset with the
episode's seed, and every aircraft is driven with its logged (executed) actions; every state
must match the log bit for bit. A team run whose tasks or scenario the record cannot rebuild
(a reward lambda, a scenario of your own) is replayed by passing the teams or the scenario
that flew it.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from gymfg_il.envs.actions import Controls
from gymfg_il.envs.roster import live
from gymfg_il.envs.scenarios import Scenario
from gymfg_il.envs.team import Team
from gymfg_il.envs.world import World
from gymfg_il.errors import ConfigError
from gymfg_il.recording.reader import Log, LoggedEpisode
from gymfg_il.rollout.records import OpponentView


@dataclass
class ReplayResult:
    """How the re-flown episode compares with the log (all aircraft, or the one asked for).

    ``per_aircraft`` holds each callsign's (identical, first mismatching step)."""

    episode: int
    steps: int
    identical: bool
    max_abs_diff: float
    first_mismatch: int | None
    per_aircraft: dict[str, tuple[bool, int | None]] = field(default_factory=dict)


def world_for(
    log: Log,
    views: Sequence[int] | None = None,
    teams: list[Team] | None = None,
    scenario: Scenario | None = None,
) -> World:
    """The world a log was flown in (``views``: FlightGear ports showing the first aircraft;
    ``teams``/``scenario``: the objects that flew it, where the record cannot rebuild them)."""
    spec = log.spec
    problems = [] if teams is not None else spec.rebuild_problems()
    if scenario is None and str((spec.scenario or {}).get("name", "")).startswith("python:"):
        problems.append(f"scenario {spec.scenario}")
    if problems:
        raise ConfigError(
            f"{log.path.name} cannot be rebuilt from its record ({'; '.join(problems)}); "
            "pass the teams= and scenario= that flew it"
        )
    config = spec.env_config(scenario=scenario)
    if views:
        first = spec.aircraft_specs[0].callsign
        config = dataclasses.replace(config, views={first: list(views)})
    online = bool(log.session.get("online"))
    return World(teams or spec.build_teams(), config, external_targets=online)


def _reset(world: World, episode: LoggedEpisode) -> None:
    """Reset ``world`` as the episode was: its seed and the reset options it logged."""
    options = episode.start.get("options") or {}
    overrides = {c: live(ic) for c, ic in options.get("initial_conditions", {}).items()}
    rng = np.random.default_rng(int(episode.start["seed"]))
    target = options.get("target")
    if target is None:
        world.reset(rng, overrides)
        return
    task = world.slots[0].task  # a gymnasium env's fixed target for one episode
    saved, task.fixed_target = task.fixed_target, float(target)  # type: ignore[attr-defined]
    try:
        world.reset(rng, overrides)
    finally:
        task.fixed_target = saved  # type: ignore[attr-defined]


def _show(world: World, view: OpponentView) -> None:
    """Give the world's external reward targets the values a logged view holds (NaN, that
    is absent, for those it does not show)."""
    shown = dict(zip(view.callsigns, view.values, strict=True))
    for callsign, target in world.external.items():
        if target.names() != view.names:
            target.rename(view.names)
        values = shown.get(callsign)
        target.values = values if values is not None else np.full(len(view.names), np.nan)


def replay_episode(
    log: Log,
    episode: LoggedEpisode,
    callsign: str | None = None,
    world: World | None = None,
    on_step: Callable[[World, int], None] | None = None,
) -> ReplayResult:
    """Re-fly ``episode`` and compare every aircraft's states and rewards with the log
    (``callsign``: judge that one only); ``on_step`` (a viewer such as FlightGear) is called
    after each step."""
    if callsign is not None and callsign not in episode.steps:
        raise ConfigError(f"episode {episode.index} has no steps of {callsign!r}")
    own = world is None
    world = world or world_for(log)
    try:
        missing = sorted(set(episode.steps) - set(world.by_callsign))
        if missing:
            raise ConfigError(f"the world has no aircraft {missing} that the log flew")
        _reset(world, episode)
        judged = [callsign] if callsign is not None else sorted(episode.steps)
        comparison = _Comparison(episode, judged)
        length = _fly(world, episode, comparison, on_step)
    finally:
        if own:
            world.close()
            world.pool.close()
    return comparison.result(len(episode.steps[judged[0]]) if callsign is not None else length)


def _fly(
    world: World,
    episode: LoggedEpisode,
    comparison: _Comparison,
    on_step: Callable[[World, int], None] | None,
) -> int:
    """Fly every aircraft of ``world`` with its logged actions (none once its steps run
    out), showing online teams what they saw, and compare each step; the steps flown."""
    logged = {c: (s.action, s.state) for c, s in episode.steps.items()}
    seen = {team: episode.views(team) for team in world.team_slots} if world.external else {}
    length = max(len(s) for s in episode.steps.values())
    for i in range(length):
        actions: list[Controls | None] = []
        for slot in world.slots:
            flown = logged.get(slot.callsign)
            if flown is None or i >= len(flown[0]):
                actions.append(None)
            else:
                a0, a1, a2, a3 = flown[0][i].tolist()
                actions.append((a0, a1, a2, a3))
        world.step_physics(actions)
        for views in seen.values():  # what an online team saw of the others: its rewards
            if i < len(views):
                _show(world, views[i])
        world.score()
        comparison.compare(world, i)
        if on_step is not None:
            on_step(world, i)
    return length


class _Comparison:
    """The judged aircraft's re-flown states and rewards against the log's: each one's
    first mismatching step and the largest state difference seen."""

    def __init__(self, episode: LoggedEpisode, judged: list[str]) -> None:
        self.episode = episode
        self.first: dict[str, int | None] = dict.fromkeys(judged)
        self.worst = 0.0

    def compare(self, world: World, i: int) -> None:
        """Compare step ``i`` of every judged aircraft that the log still holds."""
        for c in self.first:
            steps = self.episode.steps[c]
            states = steps.state
            if i >= len(states):
                continue
            slot = world.by_callsign[c]
            state, reward = slot.state, steps.reward[i]
            same = np.array_equal(state, states[i]) and slot.reward == reward
            if self.first[c] is None and not same:
                self.first[c] = i
            self.worst = max(self.worst, float(np.nanmax(np.abs(state - states[i]))))

    def result(self, steps: int) -> ReplayResult:
        """The comparison of an episode of ``steps`` steps."""
        mismatches = [f for f in self.first.values() if f is not None]
        return ReplayResult(
            self.episode.index,
            steps,
            not mismatches,
            self.worst,
            min(mismatches) if mismatches else None,
            {c: (f is None, f) for c, f in self.first.items()},
        )
