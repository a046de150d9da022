"""The manual collection session: a person flies, in real time, and every completed episode
becomes data at once.

Keys (also shown by the help overlay, H): Space starts an episode, E ends and saves it,
Backspace discards it (the same case is flown again), P pauses, T takes over from the assisting
controller or policy and hands back, Q or Esc quits. Each completed episode is made durable in
the MCAP log and then added to the LeRobot dataset before the next one starts, so quitting or a
crash loses nothing completed.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from gymfg_il.collectors.session import DATASET, check_appendable, check_out_folder
from gymfg_il.collectors.updater import DatasetUpdater
from gymfg_il.datasets.videos import DEFAULT_IMAGE_SIZE
from gymfg_il.envs.flight import FlightSpec
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
from gymfg_il.manual.gui import ControlsGUI, GuiFrame
from gymfg_il.manual.takeover import Takeover
from gymfg_il.recording.recorder import new_log_path
from gymfg_il.recording.session import session_record
from gymfg_il.recording.writer import TrajectoryWriter
from gymfg_il.rollout.agents import AgentSpec
from gymfg_il.rollout.loop import Rollout
from gymfg_il.sim.properties import BY_NAME, INDEX
from gymfg_il.tasks.scenery import landmarks_of
from gymfg_il.viz.camera import Camera

log = logging.getLogger(__name__)

COMMAND_KEYS = {
    "space": "start",
    "e": "end",
    "backspace": "discard",
    "p": "pause",
    "t": "takeover",
    "q": "quit",
    "escape": "quit",
    "h": "help",
    "f1": "help",
}
SHOWN = (
    "altitude_ft", "airspeed_kts", "vertical_speed_fps", "heading_deg", "roll_deg", "pitch_deg",
    "alpha_deg", "beta_deg", "thrust_lbs",
)  # fmt: skip


def _check_assist_rate(meta: dict[str, Any], flight: FlightSpec, path: Path) -> None:
    """A policy assists only at the rate it was trained at."""
    rate = int((meta.get("spec") or {}).get("agent_hz") or meta.get("fps") or flight.agent_hz)
    if rate != flight.agent_hz:
        raise ConfigError(
            f"the assisting policy {path} was trained at {rate} Hz and this session flies at "
            f"{flight.agent_hz} Hz; fly the session at {rate} Hz (--fps {rate}) or use a policy "
            "trained at this rate"
        )


def help_lines(device: str, kb: KeyboardBindings) -> list[str]:
    def keys(names: list[str]) -> str:
        return " / ".join(names)

    lines = [
        "SESSION  Space: start episode   E: end + save   Backspace: discard + fly again",
        "         P: pause   T: take over / hand back   Q or Esc: quit   H: this help",
    ]
    if device == "mouse":
        lines.append("STICK    the mouse pointer (offset from the window centre)")
    elif device == "joystick":
        lines.append("STICK    joystick axes (see the recipe's [collector.joystick])")
    elif device == "flightgear":
        return [*lines, "CONTROLS FlightGear's cockpit (its --native-ctrls stream)"]
    else:
        lines += [
            f"AILERON  {keys(kb.aileron_left)}  |  {keys(kb.aileron_right)}",
            f"ELEVATOR {keys(kb.elevator_down)} (nose down)  |  {keys(kb.elevator_up)} (nose up)",
        ]
    lines += [
        f"RUDDER   {keys(kb.rudder_left)}  |  {keys(kb.rudder_right)}",
        f"THROTTLE {keys(kb.throttle_up)}  |  {keys(kb.throttle_down)}",
        f"CENTRE   {keys(kb.center)}  (surfaces return to the trim at {kb.centering:g}/s)",
    ]
    return lines


@dataclass
class SessionStats:
    saved: int = 0
    discarded: int = 0
    frames: int = 0
    periods: list[float] = field(default_factory=list)
    dataset: Path | None = None


class ManualSession:
    """Run the collection loop.

    Args:
        flight: what to fly (a solo flight spec).
        out: session folder (``logs/``, ``dataset/``).
        device: keyboard, mouse, joystick or flightgear (FlightGear's cockpit).
        bindings: recipe tables ``{"keyboard": {...}, "mouse": {...}, "joystick": {...},
            "flightgear": {...}}``.
        assist: None, ``"controller"`` or a policy checkpoint path: it flies unless the human
            takes over (T); the human's frames are flagged as interventions.
        seed: seed of the first episode (a discarded episode is flown again with its seed).
        max_episodes: stop after this many saved episodes (0 = until quit).
        realtime: pace frames to the wall clock at the env's rate.
        on_frame: called at the start of each frame (tests and the synthetic pilot inject
            events with it). Without it a person flies: a session with no window they can
            see, or no joystick for ``device="joystick"``, is refused at once
            (``manual.devices``), never left waiting for input that cannot come.
        views: FlightGear UDP ports showing the aircraft (out-the-window views).
        source: what the dataset calls the pilot (default: human, or ASSIST+human).
        draw: draw the window every frame (a headless synthetic pilot needs no pictures).
        build_each: bring the dataset up to date after every saved episode (a person's
            session, so that quitting loses nothing); else once, at the end (the log keeps
            every episode durable either way).
        images, image_size: camera views the dataset holds as video (``datasets.videos``).
        pilot_view: the camera the window shows beside the instruments (``front``, ``chase``),
            so a person can fly without FlightGear; ``None``: instruments only.
    """

    def __init__(
        self,
        flight: FlightSpec,
        out: Path,
        device: str = "keyboard",
        bindings: dict[str, dict[str, Any]] | None = None,
        assist: str | None = None,
        seed: int = 0,
        max_episodes: int = 0,
        realtime: bool = True,
        on_frame: Callable[[int, ManualSession], None] | None = None,
        views: tuple[int, ...] = (),
        source: str | None = None,
        draw: bool = True,
        build_each: bool = True,
        images: Sequence[str] = (),
        image_size: int = DEFAULT_IMAGE_SIZE,
        pilot_view: str | None = "front",
    ) -> None:
        if on_frame is None:  # a person at the controls
            check_person_can_fly(device)
        bindings, out = bindings or {}, Path(out)
        check_out_folder(out)
        self.flight, self.out, self.seed, self.max_episodes = flight, out, seed, max_episodes
        self.realtime, self.on_frame = realtime, on_frame
        self.env = flight.make_env(list(views) or None)
        self.images, self.image_size = list(images), image_size
        check_appendable(out, self.env.observation_names, flight.agent_hz, None, images, image_size)
        self.kb = from_table(KeyboardBindings, bindings.get("keyboard"), "[collector.keyboard]")
        self.human = ManualController(
            device,
            self.kb,
            from_table(MouseBindings, bindings.get("mouse"), "[collector.mouse]"),
            from_table(JoystickBindings, bindings.get("joystick"), "[collector.joystick]"),
            throttle=self.env.aircraft.profile.cruise_throttle,
            flightgear=from_table(
                FlightGearBindings, bindings.get("flightgear"), "[collector.flightgear]"
            ),
        )
        self.assist_name = (
            None if assist is None else ("controller" if assist == "controller" else "policy")
        )
        assistant = None
        if assist is not None:
            spec = (
                AgentSpec.controller() if assist == "controller" else AgentSpec.policy(Path(assist))
            )
            if spec.path is not None:
                _check_assist_rate(spec.meta(), flight, spec.path)
            assistant = spec.make(self.env)
        self.pilot = Takeover(self.human, assistant)
        self.rollout = Rollout(self.env, [self.pilot])
        person = source or "human"
        self.source = person if assist is None else f"{self.assist_name}+{person}"
        self.draw, self.build_each = draw, build_each
        self.help = help_lines(device, self.kb)
        title = f"GymFG-IL: {flight.task_label} on {self.env.aircraft.model}"
        self.camera = Camera(320, 320, view=pilot_view) if pilot_view and draw else None
        self.gui = ControlsGUI(size=(1250, 600) if self.camera else (900, 600), title=title)
        self.human.window_size = self.gui.size
        self.stats = SessionStats()
        self.state = "idle"
        self.show_help = True
        self.episode = 0
        self.next_seed = seed  # a discarded episode is flown again with its seed
        self.last_action = np.array([0.0, 0.0, 0.0, self.env.aircraft.profile.cruise_throttle])
        self.message = "Space: start an episode"
        self.writer: TrajectoryWriter | None = None
        self.updater = DatasetUpdater(out)

    @property
    def human_flies(self) -> bool:
        return self.pilot.human_flies

    @property
    def observation(self) -> np.ndarray:
        """What the aircraft's pilot chooses the next action from."""
        return self.rollout.current[0]

    # -- episodes --------------------------------------------------------------------------
    def _writer(self) -> TrajectoryWriter:
        if self.writer is None:
            record = session_record(
                self.flight,
                self.source,
                device=self.human.device,
                images=self.images,
                image_size=self.image_size,
            )
            self.writer = TrajectoryWriter(new_log_path(self.out, "manual"), record)
        return self.writer

    def _start(self) -> None:
        self.updater.warm()  # its imports overlap the flying
        seed = self.next_seed
        starts = self.rollout.reset(seed)
        self.step_count, self.interventions = 0, 0
        self._writer().start_episode(seed, starts, source=self.source)
        self.state, self.message, self.show_help = "recording", "", False

    def _finish(self, outcome: str) -> None:
        writer = self._writer()
        writer.end_episode(outcome=outcome, steps=self.step_count, interventions=self.interventions)
        if self.build_each:
            self.updater.request()  # the dataset follows in a helper process, off the GIL
        self.stats.saved += 1
        self.episode += 1
        self.next_seed += 1
        self.state = "idle"
        self.message = f"episode saved ({outcome}); Space: next episode"

    def _discard(self) -> None:
        self._writer().discard_episode("discarded by the pilot")
        self.stats.discarded += 1
        self.state, self.message = "idle", "episode discarded; Space: fly it again"

    # -- loop ------------------------------------------------------------------------------
    def _command(self, command: str) -> bool:
        """Apply a session command; False to quit."""
        if command == "quit":
            if self.state in ("recording", "paused"):
                self._discard()
            return False
        if command == "help":
            self.show_help = not self.show_help
        elif command == "start" and self.state == "idle":
            self._start()
        elif command == "end" and self.state in ("recording", "paused"):
            self._finish("ended by the pilot")
        elif command == "discard" and self.state in ("recording", "paused"):
            self._discard()
        elif command == "pause" and self.state in ("recording", "paused"):
            self.state = "paused" if self.state == "recording" else "recording"
        elif command == "takeover":
            self.pilot.toggle(self.last_action)
        return True

    def _step(self) -> None:
        tick = self.rollout.step()
        self._writer().log_tick(tick)
        (step,) = tick.steps
        self.last_action = step.action
        self.step_count += 1
        self.interventions += int(step.intervention)
        if tick.done:
            self._finish(step.reason or "terminated" if step.terminated else "time limit")

    def _draw(self) -> None:
        env = self.env
        slot = env.world.slots[0]
        state = slot.state
        names = env.observation_names
        target = actual = None
        target_name = ""
        target_names = [n for n in names if n.endswith("_target")]
        if target_names and self.state != "idle":
            var = target_names[0].removesuffix("_target")
            target_name = f"{var} ({BY_NAME[var].unit})"
            target = env.task.target_value(env.world.steps)
            actual = float(state[INDEX[var]])
        left = (
            max(0.0, (env.world.max_steps - env.world.steps) * env.dt)
            if self.state != "idle"
            else env.world.max_steps * env.dt
        )
        pilot = "human" if self.human_flies else str(self.assist_name)
        frame = GuiFrame(
            action=self.human.values
            if self.human_flies or self.state == "idle"
            else getattr(self, "last_action", self.human.values),
            variables={n: (float(state[INDEX[n]]), BY_NAME[n].unit) for n in SHOWN},
            target_name=target_name,
            target=target,
            actual=actual,
            episode=self.episode,
            time_left_s=left,
            status=self.state,
            pilot=pilot,
            message=self.message or self.human.status,
            help_lines=self.help,
            show_help=self.show_help,
            view=None
            if self.camera is None
            else self.camera.frame(
                state, landmarks_of(env.task, getattr(env.task, "plan", None), env.world.steps)
            ),
        )
        self.gui.draw(frame)

    def run(self, max_frames: int | None = None) -> SessionStats:
        import pygame

        period = self.env.dt
        frame = 0
        next_deadline = time.perf_counter()
        last_start: float | None = None
        running = True
        try:
            while running and (max_frames is None or frame < max_frames):
                start = time.perf_counter()
                if last_start is not None:
                    self.stats.periods.append(start - last_start)
                last_start = start
                if self.on_frame is not None:
                    self.on_frame(frame, self)
                events = pygame.event.get()
                commands = self.human.handle(events, period)
                for ev in events:
                    if ev.type == pygame.QUIT:
                        commands.append("quit")
                    elif ev.type == pygame.KEYDOWN:
                        cmd = COMMAND_KEYS.get(pygame.key.name(ev.key))
                        if cmd:
                            commands.append(cmd)
                for command in commands:
                    running = self._command(command) and running
                if running and self.state == "recording":
                    self._step()
                self.updater.poll()
                if self.draw:
                    self._draw()
                frame += 1
                self.stats.frames = frame
                if self.max_episodes and self.stats.saved >= self.max_episodes:
                    break
                if self.realtime:
                    next_deadline += period
                    now = time.perf_counter()
                    if next_deadline < now - period:  # far behind: no catch-up burst
                        next_deadline = now
                    _sleep_until(next_deadline)
        finally:
            self.close()
        return self.stats

    def close(self) -> None:
        if self.writer is not None:
            self.writer.close()
            self.writer = None
        self.env.close()
        self.human.close()
        self.gui.close()
        if not self.build_each and self.stats.saved:
            self.updater.request()
        if self.updater.close():
            self.stats.dataset = self.out / DATASET


def _sleep_until(deadline: float) -> None:
    """Sleep coarsely, then spin the last millisecond (sleep alone overshoots by ~0.1-1 ms)."""
    remaining = deadline - time.perf_counter()
    if remaining > 0.0015:
        time.sleep(remaining - 0.001)
    while time.perf_counter() < deadline:
        pass
