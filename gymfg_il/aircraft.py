"""Aircraft: a JSBSim model flown under a callsign (the paper's ``gymfg.aircraft``).

``Aircraft(model, callsign)`` accepts any aircraft JSBSim ships (``available_models()``); the
paper's three have factories: ``f15``, ``c172p`` and ``a320``. Aircraft compare and hash by
``(model, callsign)``, so ``f15("red-one")`` written twice names the same aircraft, as the
paper's ``reward_function_targets`` listing needs.
"""

from __future__ import annotations

import difflib
import functools
import math
import os
from dataclasses import dataclass, field

from gymfg_il.errors import ConfigError, UnknownAircraftError
from gymfg_il.names import check_name
from gymfg_il.units import KT_TO_FPS

G_FPS2 = 32.174  # standard gravity (ft/s^2)


def turn_rate_dps(airspeed_kts: float, bank_deg: float) -> float:
    """Rate (deg/s) of a coordinated level turn at ``bank_deg`` and ``airspeed_kts`` (true)."""
    return math.degrees(G_FPS2 * math.tan(math.radians(bank_deg)) / (airspeed_kts * KT_TO_FPS))


@dataclass(frozen=True, slots=True)
class FlightProfile:
    """Where an aircraft flies comfortably: the start state tasks draw around, and its limits.

    Attributes:
        cruise_kts: true airspeed at the start of an episode.
        cruise_altitude_ft: altitude above sea level at the start of an episode.
        cruise_throttle: throttle that roughly holds cruise_kts in level flight.
        min_airspeed_kts: below this calibrated airspeed the aircraft counts as stalled.
        ceiling_ft: above this altitude the aircraft has left its envelope.
        min_agl_ft: below this height above ground the aircraft counts as crashed.
        bank_deg: the bank its pilot turns at in a maneuver (the maneuver experts' limit): an
            airliner's 30, a fighter's 45, a light aircraft's 25.
        approach_kts: the calibrated airspeed of its final approach; None: 1.4 x
            min_airspeed_kts. Set where the aircraft cannot hold that speed clean (the action
            has no flaps, no stabilizer trim).
    """

    cruise_kts: float
    cruise_altitude_ft: float
    cruise_throttle: float
    min_airspeed_kts: float
    ceiling_ft: float
    min_agl_ft: float = 50.0
    bank_deg: float = 25.0
    approach_kts: float | None = None

    @property
    def turn_rate_dps(self) -> float:
        """Rate (deg/s) of a level turn at cruise speed and ``bank_deg``."""
        return turn_rate_dps(self.cruise_kts, self.bank_deg)

    @property
    def maneuver_scale(self) -> float:
        """How many times longer its turns take than ``REFERENCE_PROFILE``'s (110 kt at 25
        deg of bank), at least 1: the maneuvers stretch their times by it (1 for the c172p,
        about 1.7 for the f15, 2.1 for the A320)."""
        return max(1.0, REFERENCE_PROFILE.turn_rate_dps / self.turn_rate_dps)

    @property
    def final_approach_kts(self) -> float:
        """The calibrated airspeed of its final approach: ``approach_kts``, else 1.4 x its
        minimum airspeed (70 kt for the c172p)."""
        if self.approach_kts is not None:
            return self.approach_kts
        return round(1.4 * self.min_airspeed_kts, 1)

    def __post_init__(self) -> None:
        problems = []
        if not self.cruise_kts > self.min_airspeed_kts > 0:
            problems.append(
                f"need cruise_kts > min_airspeed_kts > 0, got {self.cruise_kts} and "
                f"{self.min_airspeed_kts}"
            )
        if self.approach_kts is not None and not (
            self.min_airspeed_kts < self.approach_kts < self.cruise_kts
        ):
            problems.append(
                f"approach_kts={self.approach_kts} must lie between min_airspeed_kts="
                f"{self.min_airspeed_kts} and cruise_kts={self.cruise_kts}"
            )
        if not 5.0 <= self.bank_deg <= 75.0:
            problems.append(f"bank_deg={self.bank_deg} must lie in [5, 75] degrees")
        if not 0.0 <= self.cruise_throttle <= 1.0:
            problems.append(f"cruise_throttle={self.cruise_throttle} must lie in [0, 1]")
        if not self.ceiling_ft > self.cruise_altitude_ft > self.min_agl_ft:
            problems.append(
                f"need ceiling_ft > cruise_altitude_ft > min_agl_ft, got {self.ceiling_ft}, "
                f"{self.cruise_altitude_ft}, {self.min_agl_ft}"
            )
        if problems:
            raise ConfigError("FlightProfile: " + "; ".join(problems))


# The light aircraft the maneuvers were first drawn for (the c172p's profile): the maneuvers
# of other aircraft scale from it (``maneuver_scale``, ``tasks.maneuvers``).
REFERENCE_PROFILE = FlightProfile(110.0, 5000.0, 0.75, 50.0, 14000.0)
# Measured on JSBSim 1.3.3: each of these holds its cruise airspeed near level flight.
PROFILES: dict[str, FlightProfile] = {
    "c172p": REFERENCE_PROFILE,
    "f15": FlightProfile(400.0, 15000.0, 0.75, 150.0, 60000.0, bank_deg=45.0),
    # clean and on its elevator alone the A320 cannot hold 1.4 x its minimum airspeed
    # (docs/results/maneuvers.md): it approaches faster
    "A320": FlightProfile(280.0, 12000.0, 0.65, 130.0, 39000.0, bank_deg=30.0, approach_kts=200.0),
}
GENERIC_PROFILE = FlightProfile(150.0, 6000.0, 0.7, 50.0, 40000.0)


def jsbsim_root() -> str:
    """The JSBSim data folder shipped with the ``jsbsim`` wheel."""
    import jsbsim

    return str(jsbsim.get_default_root_dir())


@functools.cache
def available_models() -> tuple[str, ...]:
    """Every aircraft model JSBSim ships here (folders holding ``<name>/<name>.xml``)."""
    folder = os.path.join(jsbsim_root(), "aircraft")
    return tuple(
        sorted(
            name
            for name in os.listdir(folder)
            if os.path.isfile(os.path.join(folder, name, f"{name}.xml"))
        )
    )


def resolve_model(model: str) -> str:
    """The canonical JSBSim name of ``model`` (case-insensitive), or a clear error."""
    models = available_models()
    if model in models:
        return model
    by_lower = {m.lower(): m for m in models}
    if isinstance(model, str) and model.lower() in by_lower:
        return by_lower[model.lower()]
    close = difflib.get_close_matches(str(model), models, n=5, cutoff=0.4)
    hint = f"closest: {', '.join(close)}" if close else f"known: {', '.join(models[:12])}, ..."
    raise UnknownAircraftError(
        f"unknown aircraft model {model!r}: JSBSim ships no such aircraft ({hint}); "
        "see gymfg_il.aircraft.available_models()"
    )


@dataclass(frozen=True, slots=True)
class Aircraft:
    """A JSBSim aircraft model under a callsign, unique within its simulation.

    Args:
        model: JSBSim model name (``"c172p"``, ``"f15"``, ``"A320"``, any of
            ``available_models()``; case-insensitive).
        callsign: the aircraft's name in its team, e.g. ``"red-one"``.
        profile: start state and limits; defaults to a measured profile for the paper's
            three aircraft and a generic light-aircraft profile for the rest.
    """

    model: str
    callsign: str
    profile: FlightProfile = field(default=GENERIC_PROFILE, compare=False, hash=False)

    def __post_init__(self) -> None:
        canonical = resolve_model(self.model)
        object.__setattr__(self, "model", canonical)
        if not isinstance(self.callsign, str) or not self.callsign.strip():
            raise ConfigError(
                f"callsign must be a non-empty string, got {self.callsign!r}: "
                'name the aircraft, e.g. c172p("red-one")'
            )
        check_name(self.callsign, "callsign")  # it reaches logs, windows and the wire
        if self.profile is GENERIC_PROFILE and canonical in PROFILES:
            object.__setattr__(self, "profile", PROFILES[canonical])


def f15(callsign: str) -> Aircraft:
    """An F-15 (JSBSim ``f15``)."""
    return Aircraft("f15", callsign)


def c172p(callsign: str) -> Aircraft:
    """A Cessna 172P (JSBSim ``c172p``)."""
    return Aircraft("c172p", callsign)


def a320(callsign: str) -> Aircraft:
    """An Airbus A320 (JSBSim ``A320``)."""
    return Aircraft("A320", callsign)
