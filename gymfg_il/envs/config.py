"""What every environment is configured with: rates, the opponent view, a joint start, and
the FlightGear views fed from the simulation."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

from gymfg_il.envs.scenarios import Scenario
from gymfg_il.errors import ConfigError
from gymfg_il.flightgear.multiplayer import port_problem
from gymfg_il.flightgear.peers import MultiplayerConfig
from gymfg_il.sim.properties import DEFAULT_OPPONENT_VIEW, ORIENTATION, POSITION, indices
from gymfg_il.sim.timing import DEFAULT_AGENT_HZ, DEFAULT_SIM_HZ, substeps
from gymfg_il.sim.weather import Weather


@dataclass(frozen=True)
class EnvConfig:
    """Settings shared by every environment.

    Args:
        sim_hz: JSBSim rate (Hz).
        agent_hz: agent rate (Hz); must divide ``sim_hz`` exactly; it is a dataset's fps.
        opponent_view: the state variables an aircraft sees of other teams' aircraft
            (position and orientation by default, as in the paper).
        scenario: joint initial conditions overriding the tasks' own (see ``envs.scenarios``).
        views: callsign -> UDP ports of FlightGear views of that aircraft. Only aircraft
            listed here open a socket (the paper warns that a view per aircraft can load a
            network); while any view is attached the simulation paces itself to real time.
        traffic: callsign -> multiplayer UDP ports of the views of that aircraft
            (``FlightGear(multiplayer_port=...)``): every other aircraft of the simulation,
            opponents of an online client included, is sent there and appears in the view.
        weather: turbulence and wind (``sim.weather.Weather``), seeded per episode.
        multiplayer: FlightGear multiplayer (``flightgear.peers.MultiplayerConfig``): every
            FlightGear aircraft heard on its port is an opponent (position and orientation
            only), our aircraft are sent to its ``send_to`` addresses, and the simulation
            paces itself to real time, FlightGear's clock.
        trimmed_starts: the tasks' and the scenario's starts are trimmed straight, level
            flight (the default); False starts them untrimmed, as before trimmed starts
            existed (initial conditions given at reset keep their own ``trimmed``).
    """

    sim_hz: int = DEFAULT_SIM_HZ
    agent_hz: int = DEFAULT_AGENT_HZ
    opponent_view: tuple[str, ...] = DEFAULT_OPPONENT_VIEW
    scenario: Scenario | None = None
    views: Mapping[str, Sequence[int]] | None = None
    traffic: Mapping[str, Sequence[int]] | None = None
    weather: Weather = field(default_factory=Weather)
    multiplayer: MultiplayerConfig | None = None
    trimmed_starts: bool = True

    def __post_init__(self) -> None:
        substeps(self.sim_hz, self.agent_hz)
        problems = [
            f"traffic of {c!r}: {problem}"
            for c, ports in (self.traffic or {}).items()
            for problem in map(port_problem, ports)
            if problem
        ]
        if problems:
            raise ConfigError("; ".join(problems))
        view = tuple(self.opponent_view)
        object.__setattr__(self, "opponent_view", view)
        indices(view)
        if len(set(view)) != len(view):
            raise ConfigError(f"opponent_view lists a variable twice: {view}")
        if self.multiplayer is not None:
            if not isinstance(self.multiplayer, MultiplayerConfig):
                raise ConfigError(
                    f"multiplayer must be a MultiplayerConfig, got {self.multiplayer!r}"
                )
            unseen = [v for v in view if v not in POSITION + ORIENTATION]
            if unseen:
                raise ConfigError(
                    f"opponent_view {list(unseen)}: FlightGear aircraft show only "
                    f"{list(POSITION + ORIENTATION)}; drop the others or the multiplayer"
                )
        if not isinstance(self.trimmed_starts, bool):
            raise ConfigError(f"trimmed_starts={self.trimmed_starts!r} must be True or False")
        if self.scenario is not None and not callable(self.scenario):
            raise ConfigError(
                f"scenario must be callable (rng, aircraft) -> ics, got {self.scenario!r}"
            )

    @property
    def dt(self) -> float:
        return 1.0 / self.agent_hz
