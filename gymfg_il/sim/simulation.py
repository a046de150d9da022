"""One aircraft's JSBSim instance: built once, reset many times, stepped with cached nodes.

The hot path (``apply`` + ``read``) touches JSBSim only through property nodes cached at build
time and plain Python floats, so an agent step costs little beyond the physics itself
(``benchmarks/run.py`` measures it against a bare ``FGFDMExec.run()`` loop).
"""

from __future__ import annotations

import dataclasses
import logging
import os
import tempfile
from collections.abc import Callable
from typing import Any

import numpy as np

from gymfg_il.aircraft import jsbsim_root, resolve_model
from gymfg_il.sim.gusts import GUST_AXES, Gust, gust_at
from gymfg_il.sim.initial import InitialConditions
from gymfg_il.sim.properties import CATALOGUE, StateVar
from gymfg_il.sim.timing import DEFAULT_AGENT_HZ, DEFAULT_SIM_HZ, substeps
from gymfg_il.sim.trim import Trim, trim_for
from gymfg_il.sim.weather import Air

CALM = Air()

log = logging.getLogger(__name__)


def _quiet_jsbsim() -> None:
    """Silence JSBSim's banner and load chatter for every instance made afterwards."""
    import jsbsim

    jsbsim.FGJSBBase().debug_lvl = 0


class Simulation:
    """A JSBSim ``FGFDMExec`` for one aircraft model at ``sim_hz``, stepped at ``agent_hz``.

    Args:
        model: JSBSim aircraft model (case-insensitive).
        sim_hz: JSBSim integration rate; 120 Hz by default.
        agent_hz: agent rate; must divide ``sim_hz`` exactly.
        catalogue: the state variables ``read()`` returns, in order.
    """

    def __init__(
        self,
        model: str,
        sim_hz: int = DEFAULT_SIM_HZ,
        agent_hz: int = DEFAULT_AGENT_HZ,
        catalogue: tuple[StateVar, ...] = CATALOGUE,
    ) -> None:
        import jsbsim

        self.model = resolve_model(model)
        self.sim_hz = sim_hz
        self.agent_hz = agent_hz
        self.substeps = substeps(sim_hz, agent_hz)
        _quiet_jsbsim()
        fdm = jsbsim.FGFDMExec(jsbsim_root())
        fdm.set_debug_level(0)
        if not fdm.load_model(self.model):
            raise RuntimeError(f"JSBSim could not load aircraft {self.model!r}")
        fdm.set_dt(1.0 / sim_hz)
        self.fdm = fdm
        pm = fdm.get_property_manager()
        self.engines = max(1, fdm.get_propulsion().get_num_engines())

        def node(prop: str) -> Any:  # a JSBSim FGPropertyNode
            n = pm.get_node(prop, True) if not pm.hasNode(prop) else pm.get_node(prop)
            if n is None:
                raise RuntimeError(f"JSBSim model {self.model!r} has no property {prop!r}")
            return n

        self._getters: list[Callable[[], float]] = [
            node(v.prop).get_double_value for v in catalogue
        ]
        setters = [
            node(p).set_double_value
            for p in ("fcs/aileron-cmd-norm", "fcs/elevator-cmd-norm", "fcs/rudder-cmd-norm")
        ]
        self._set_aileron, self._set_elevator, self._set_rudder = setters
        self._set_gust = [node(f"atmosphere/gust-{a}-fps").set_double_value for a in GUST_AXES]
        self.gusts: tuple[Gust, ...] = ()  # the last reset's air's gusts (``sim.gusts``)
        self._frame = 0  # JSBSim steps since the last reset (the gusts' clock)
        self._set_throttles: list[Callable[[float], None]] = [
            node(f"fcs/throttle-cmd-norm[{i}]").set_double_value for i in range(self.engines)
        ]
        self._mixtures = [f"fcs/mixture-cmd-norm[{i}]" for i in range(self.engines)]
        self._has_gear = pm.hasNode("gear/gear-cmd-norm")
        # JSBSim gives a gear unit a pos-norm only when it retracts (the c172p's does not)
        units = fdm.get_ground_reactions().get_num_gear_units()
        self._retracts = any(pm.hasNode(f"gear/unit[{i}]/pos-norm") for i in range(units))
        self._run = fdm.run
        self._substep_range = range(self.substeps)
        self._set_trims = [
            node(f"fcs/{axis}-trim-cmd-norm").set_double_value for axis in ("pitch", "roll", "yaw")
        ]
        self.trim: Trim | None = None  # the last reset's trim (None: an untrimmed start)
        # the controls the last reset started with: the trim's, or centred with its throttle
        self.start_action: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)
        self.resets = 0
        if self._retracts:
            self._retract_gear()

    @property
    def dt(self) -> float:
        """Seconds of simulated time per agent step."""
        return self.substeps / self.sim_hz

    def reset(
        self, ic: InitialConditions, throttle: float = 0.0, air: Air | None = None
    ) -> np.ndarray:
        """Put the aircraft in ``ic`` with engines running, in ``air`` (calm by default);
        return the first state vector. A trimmed ``ic`` (``trimmed=True``) starts at the trim's
        pitch with the controls at the trim's values (``self.start_action``; ``self.trim``
        holds the trim); an untrimmed one with the surfaces centred and ``throttle``."""
        air = air or CALM
        trim = None
        controls = (0.0, 0.0, 0.0, throttle)
        if ic.trimmed:
            trim = trim_for(self.model, ic.altitude_ft, ic.airspeed_kts, self.sim_hz, Simulation)
            ic = dataclasses.replace(ic, pitch_deg=trim.pitch_deg, trimmed=False)
            controls = (trim.aileron, trim.elevator, trim.rudder, trim.throttle)
        self.trim = trim
        self.start_action = controls
        xml = ic.to_xml(air.wind).replace("</initialize>", " <running>-1</running>\n</initialize>")
        fdm = self.fdm
        # JSBSim reads initial conditions only from a file. It lives just for the load, so
        # worker processes that exit without atexit, or a kill -9, leave nothing behind.
        fd, path = tempfile.mkstemp(prefix="gymfg-ic-", suffix=".xml")
        try:
            with os.fdopen(fd, "w", encoding="ascii") as f:
                f.write(xml)
            fdm.get_ic().load(path, False)
        finally:
            os.remove(path)
        air.before_reset(fdm)
        self.gusts, self._frame = air.gusts, 0
        for prop in self._mixtures:
            fdm[prop] = 1.0
        self.apply(*controls, run=False)
        if self._has_gear:
            fdm["gear/gear-cmd-norm"] = 0.0
        fdm.reset_to_initial_conditions(0)
        # the trim lives in the controls, never in JSBSim's trim commands: an action is then
        # the whole command, a function of the state the aircraft is in (with the trim in
        # fcs/*-trim-cmd-norm a label would depend on where the episode started)
        for set_trim in self._set_trims:
            set_trim(0.0)
        if trim is not None:
            self._settle_engines(trim.throttle)
        self.resets += 1
        return self.read()

    def _settle_engines(self, throttle: float) -> None:
        """Bring the engines to their steady state at the start's throttle.

        JSBSim starts a running engine at its full-throttle steady state (``InitRunning`` also
        sets the throttle commands to 1, which the first step overwrites), so from a trimmed
        start the c172p's propeller spun down from ~2,780 to ~2,340 RPM over
        the first second and pitched the aircraft at up to 0.021 rad/s. A run with the
        integration suspended (as JSBSim's own ``RunIC`` does) loads the trim's throttle into
        the engines without moving the clock or the aircraft; the steady state is then
        computed from it. Hands-off pitch rates fall to ~0.011 rad/s on the c172p (0.021 without).
        """
        fdm = self.fdm
        for set_throttle in self._set_throttles:
            set_throttle(throttle)
        fdm.suspend_integration()
        try:
            self._run()
            fdm.get_propulsion().get_steady_state()
        finally:
            fdm.resume_integration()

    def _retract_gear(self) -> None:
        """Fly once with the gear commanded up until it is stowed.

        JSBSim keeps the gear actuator's position across resets, so a fresh instance would
        start its first episode with the gear down and later ones with it up. Stowing it once
        at build time makes every episode start alike.
        """
        self.reset(InitialConditions(altitude_ft=30000.0, airspeed_kts=250.0, trimmed=False))
        for _ in range(60 * self.sim_hz):
            if self.fdm["gear/gear-pos-norm"] <= 0.0:
                break
            self._run()
        self.resets = 0

    def apply(
        self, aileron: float, elevator: float, rudder: float, throttle: float, run: bool = True
    ) -> None:
        """Set the four controls, then advance JSBSim one agent step (``substeps`` frames)."""
        self._set_aileron(aileron)
        self._set_elevator(elevator)
        self._set_rudder(rudder)
        for set_throttle in self._set_throttles:
            set_throttle(throttle)
        if run and self.gusts:
            self._run_gusts()
        elif run:
            step = self._run
            for _ in self._substep_range:
                step()

    def _run_gusts(self) -> None:
        """One agent step with the gusts blowing, set anew at every JSBSim step."""
        for _ in self._substep_range:
            wind = gust_at(self.gusts, self._frame / self.sim_hz)
            for set_axis, value in zip(self._set_gust, wind, strict=True):
                set_axis(value)
            self._run()
            self._frame += 1

    def read(self) -> np.ndarray:
        """The catalogue's values now, as a new float64 vector."""
        return np.array([get() for get in self._getters])

    def close(self) -> None:
        """Nothing to release: the instance holds no files or sockets."""
