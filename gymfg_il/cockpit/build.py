"""The cockpit session's factory: from a ``ManualConfig`` to the stages its loop runs
(``cockpit.session``), each given what it needs once, here. Who flies is decided here and
nowhere else: a person's devices, or the synthetic pilot's hands on the same controller.

A session of a person (no test or tool driving it) is refused at once when it could never
get input (``manual.devices``); every refusal comes before the session folder is touched.

A ``Plug`` flies a session from elsewhere (``collect web``: a browser): its input and window
replace pygame's devices and window, its dataset updater is shared by every pilot of the
server, and the session is otherwise the same loop.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from gymfg_il.agent import Agent
from gymfg_il.cockpit.flight_log import FlightLog
from gymfg_il.cockpit.inputs.devices import DeviceInput
from gymfg_il.cockpit.inputs.keys import help_lines
from gymfg_il.cockpit.inputs.source import Input
from gymfg_il.cockpit.inputs.synthetic_pilot import SyntheticInput
from gymfg_il.cockpit.pace import Pace
from gymfg_il.cockpit.phases import Phases, SessionStats
from gymfg_il.cockpit.updater import DatasetUpdater
from gymfg_il.cockpit.windows.gui import ControlsGUI
from gymfg_il.cockpit.windows.pygame_window import PygameWindow, window_size
from gymfg_il.cockpit.windows.view import NoWindow, Window
from gymfg_il.collectors.config import ManualConfig
from gymfg_il.collectors.session import check_appendable, check_out_folder
from gymfg_il.display.briefing import briefing
from gymfg_il.envs.flight import FlightSpec
from gymfg_il.envs.single import AircraftEnv
from gymfg_il.errors import ConfigError
from gymfg_il.manual.bindings import (
    FlightGearBindings,
    JoystickBindings,
    KeyboardBindings,
    MouseBindings,
    from_table,
)
from gymfg_il.manual.controller import ManualController
from gymfg_il.manual.devices import check_person_can_fly
from gymfg_il.manual.perception import DisplayIntent
from gymfg_il.manual.synthetic import SyntheticPilot
from gymfg_il.manual.takeover import Takeover
from gymfg_il.recording.session import session_record
from gymfg_il.rollout.agents import AgentSpec
from gymfg_il.rollout.loop import Rollout
from gymfg_il.tasks.verdicts import TrackedError
from gymfg_il.viz.camera import Camera


@dataclass(frozen=True)
class Plug:
    """Where a session's input comes from and its frames go when not this machine's devices
    and window (module docstring).

    Attributes:
        input: the session's input, made from the pilot's controller and the env.
        window: the session's window (a sink of frames), made from the same and the flight.
        updater: the dataset's updater, shared with other sessions writing the same folder.
        log_tag: the start of the session's log file name (``logs/TAG-....mcap``).
    """

    input: Callable[[ManualController, AircraftEnv], Input]
    window: Callable[[ManualController, AircraftEnv, FlightSpec], Window]
    updater: DatasetUpdater
    log_tag: str = "manual"


@dataclass
class Stages:
    """A built session: its env, the pilot's controller and takeover, and the loop's stages in
    the order they run (``cockpit.session``)."""

    env: AircraftEnv
    human: ManualController
    takeover: Takeover
    pace: Pace
    input: Input
    phases: Phases
    rollout: Rollout
    log: FlightLog
    updater: DatasetUpdater
    window: Window
    stats: SessionStats
    out: Path
    episodes: int  # to save before the session ends (0: until quit)


def build(
    config: ManualConfig,
    *,
    driven: bool,
    realtime: bool | None,
    draw: bool | None,
    plug: Plug | None = None,
) -> Stages:
    """The stages of ``config``'s session. ``driven``: a test or tool drives it (a person's
    devices are not checked); ``realtime`` and ``draw`` default to whether a person flies;
    ``plug``: its input, window and updater come from elsewhere (``Plug``)."""
    synthetic = config.pilot == "synthetic"
    if not driven and not synthetic and plug is None:  # a person at this machine
        check_person_can_fly(config.device)
    check_out_folder(config.out)
    flight = config.flight()
    env = flight.make_env(list(config.view) or None)
    check_appendable(
        config.out, env.observation_names, flight.agent_hz, None, config.images, config.image_size
    )
    realtime = not synthetic if realtime is None else realtime
    draw = not synthetic if draw is None else draw
    camera = _camera(config, draw and plug is None)
    human = _controller(config, env, window_size(camera is not None))
    takeover = Takeover(human, _assistant(config.assist, flight, env))
    # DART noise on what the synthetic pilot flies (drawn from each episode's seed); the
    # label stays its own answer (``rollout.loop``)
    rollout = Rollout(env, [takeover], noise=config.noise)
    person = "synthetic" if synthetic else "human"
    assistant = _assistant_name(config.assist)
    log = _flight_log(config, env, flight, human.device, person, assistant, realtime, plug)
    updater = DatasetUpdater(config.out) if plug is None else plug.updater
    stats = SessionStats()
    # a person's dataset follows each saved episode; the synthetic pilot's is built at the end
    phases = Phases(
        rollout, log, takeover, updater, stats, seed=config.seed, build_each=not synthetic
    )
    if plug is not None:
        ends = (plug.input(human, env), plug.window(human, env, flight))
    else:
        window: Window = NoWindow()
        if draw:
            window = _window(config, flight, env, camera, human, person, assistant)
        ends = (_input(config, env, human, takeover.assistant is not None), window)
    return Stages(
        env=env,
        human=human,
        takeover=takeover,
        pace=Pace(env.dt, realtime, spin=plug is None),
        input=ends[0],
        phases=phases,
        rollout=rollout,
        log=log,
        updater=updater,
        window=ends[1],
        stats=stats,
        out=config.out,
        episodes=config.episodes,
    )


def _camera(config: ManualConfig, shown: bool) -> Camera | None:
    """The pilot's view beside the instruments, in a window that is ``shown``, if asked for."""
    if not shown or config.pilot_view == "none":
        return None
    return Camera(320, 320, view=config.pilot_view, legible=True)


def _window(
    config: ManualConfig,
    flight: FlightSpec,
    env: AircraftEnv,
    camera: Camera | None,
    human: ManualController,
    person: str,
    assistant: str | None,
) -> PygameWindow:
    """The pygame window: the controls GUI, with the pilot's camera beside it if any."""
    title = f"GymFG-IL: {flight.task_label} on {env.aircraft.model}"
    return PygameWindow(
        ControlsGUI(size=window_size(camera is not None), title=title),
        camera,
        env.task,
        env.world.max_steps,
        env.dt,
        briefing=briefing(env.task, env.world.max_steps * env.dt),
        help_lines=help_lines(config.device, human.keys),
        pilot=person,
        assistant=assistant,
    )


def _controller(config: ManualConfig, env: AircraftEnv, size: tuple[int, int]) -> ManualController:
    """The pilot's controller: the device and its bindings from the config's tables."""
    return ManualController(
        config.device,
        from_table(KeyboardBindings, config.keyboard, "[collector.keyboard]"),
        from_table(MouseBindings, config.mouse, "[collector.mouse]"),
        from_table(JoystickBindings, config.joystick, "[collector.joystick]"),
        throttle=env.aircraft.profile.cruise_throttle,
        window_size=size,
        flightgear=from_table(FlightGearBindings, config.flightgear, "[collector.flightgear]"),
    )


def _input(
    config: ManualConfig, env: AircraftEnv, human: ManualController, assisted: bool
) -> Input:
    """A person's devices, or the synthetic pilot's hands on them."""
    devices = DeviceInput(human, env.dt)
    if config.pilot != "synthetic":
        return devices
    throttle = env.aircraft.profile.cruise_throttle
    intent = DisplayIntent(env.task, env.aircraft.model, env.dt, throttle)
    pilot = SyntheticPilot(
        human.device,
        intent,
        env.dt,
        config.skill,
        human.keys,
        human.mouse,
        human.joy,
        human.window_size,
    )
    # the DAgger gate reads the task's tracked error against its tolerance
    gated = TrackedError.of(env.task.describe())
    return SyntheticInput(devices, pilot, assisted=assisted, tracked=gated)


def _assistant_name(assist: str | None) -> str | None:
    return None if assist is None else ("controller" if assist == "controller" else "policy")


def _assistant(assist: str | None, flight: FlightSpec, env: AircraftEnv) -> Agent | None:
    """The task's controller or a policy that flies until the pilot takes over (T)."""
    if assist is None:
        return None
    spec = AgentSpec.controller() if assist == "controller" else AgentSpec.policy(Path(assist))
    if spec.path is not None:
        _check_assist_rate(spec.meta(), flight, spec.path)
    return spec.make(env)


def _check_assist_rate(meta: dict[str, Any], flight: FlightSpec, path: Path) -> None:
    """A policy assists only at the rate it was trained at."""
    rate = int((meta.get("spec") or {}).get("agent_hz") or meta.get("fps") or flight.agent_hz)
    if rate != flight.agent_hz:
        raise ConfigError(
            f"the assisting policy {path} was trained at {rate} Hz and this session flies at "
            f"{flight.agent_hz} Hz; fly the session at {rate} Hz (--fps {rate}) or use a policy "
            "trained at this rate"
        )


def _flight_log(
    config: ManualConfig,
    env: AircraftEnv,
    flight: FlightSpec,
    device: str,
    person: str,
    assistant: str | None,
    realtime: bool,
    plug: Plug | None,
) -> FlightLog:
    """The session's log; the pilot named by the config (the synthetic pilot by its skill),
    the source ``person`` or ``ASSISTANT+person``."""
    source = person if assistant is None else f"{assistant}+{person}"
    record = session_record(
        flight,
        source,
        device=device,
        noise=config.noise,
        images=list(config.images),
        image_size=config.image_size,
    )
    named = config.pilot_name
    if named is None:
        named = f"synthetic-{config.skill:g}" if config.pilot == "synthetic" else ""
    return FlightLog(
        config.out,
        record,
        env.task,
        env.dt,
        source=source,
        pilot_name=named,
        realtime=realtime,
        gusty=flight.gusty,
        throttle=env.aircraft.profile.cruise_throttle,
        sim=env.world.slots[0].sim,
        tag="manual" if plug is None else plug.log_tag,
    )
