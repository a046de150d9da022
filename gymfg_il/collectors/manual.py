"""The manual collection session: a person (or the synthetic pilot) flies, in real time, and
every completed episode becomes data at once.

Keys (``collectors.manual_keys``; also shown by the help overlay, H): Space starts an episode,
E ends and saves it, Backspace discards it (the same case is flown again), P pauses, T takes
over from the assisting controller or policy and hands back, Q or Esc quits. Each completed
episode is made durable in the MCAP log and then added to the LeRobot dataset before the next
one starts, so quitting or a crash loses nothing completed. What the window shows is
``collectors.manual_view``.
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from gymfg_il.cockpit.inputs.keys import COMMAND_KEYS, help_lines
from gymfg_il.cockpit.timing import WARN_S, EpisodeTiming
from gymfg_il.cockpit.updater import DatasetUpdater
from gymfg_il.cockpit.windows.gui import ControlsGUI
from gymfg_il.collectors.config import ManualConfig
from gymfg_il.collectors.manual_view import window_frame
from gymfg_il.collectors.session import DATASET, check_appendable, check_out_folder
from gymfg_il.display.briefing import Debrief, briefing, debrief
from gymfg_il.display.readings import Display, display_of
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
from gymfg_il.manual.takeover import Takeover
from gymfg_il.recording.recorder import new_log_path
from gymfg_il.recording.session import session_record
from gymfg_il.recording.writer import TrajectoryWriter
from gymfg_il.rollout.agents import AgentSpec
from gymfg_il.rollout.loop import Rollout
from gymfg_il.viz.camera import Camera

log = logging.getLogger(__name__)
FrameHook = Callable[[int, "ManualSession"], None]


def _check_assist_rate(meta: dict[str, Any], flight: FlightSpec, path: Path) -> None:
    """A policy assists only at the rate it was trained at."""
    rate = int((meta.get("spec") or {}).get("agent_hz") or meta.get("fps") or flight.agent_hz)
    if rate != flight.agent_hz:
        raise ConfigError(
            f"the assisting policy {path} was trained at {rate} Hz and this session flies at "
            f"{flight.agent_hz} Hz; fly the session at {rate} Hz (--fps {rate}) or use a policy "
            "trained at this rate"
        )


@dataclass
class SessionStats:
    saved: int = 0
    discarded: int = 0
    frames: int = 0
    periods: list[float] = field(default_factory=list)
    dataset: Path | None = None


class ManualSession:
    """Run the collection loop of one ``ManualConfig``.

    Args:
        config: what to fly and how (``collectors.config.ManualConfig``): the flight, the
            session folder, the device and its bindings, an assistant (``controller`` or a
            policy that flies until the pilot takes over, T; the pilot's frames are flagged
            as interventions), the seed of the first episode (a discarded episode is flown
            again with its seed), the episodes to save (0: until quit), FlightGear views, the
            dataset's camera views and the window's camera.
        on_frame: called at the start of each frame with the frame's number and the session
            (tests inject events with it). A synthetic pilot's session is driven by
            ``collectors.synthetic.SyntheticDriver`` unless another hook is given. Without a
            hook a person flies: a session with no window they can see, or no joystick for
            ``device="joystick"``, is refused at once (``manual.devices``), never left
            waiting for input that cannot come.
        realtime: pace frames to the wall clock at the flight's rate (default: for a person;
            the synthetic pilot flies as fast as the machine allows).
        draw: draw the window every frame (default: for a person; the synthetic pilot needs
            no pictures).

    A person's session brings the dataset up to date after every saved episode (so that
    quitting loses nothing); the synthetic pilot's once, at the end (the log keeps every
    episode durable either way). The dataset calls the pilot ``human`` or ``synthetic``
    (``controller+human`` and so on with an assistant).
    """

    def __init__(
        self,
        config: ManualConfig,
        on_frame: FrameHook | None = None,
        *,
        realtime: bool | None = None,
        draw: bool | None = None,
    ) -> None:
        synthetic = config.pilot == "synthetic"
        if on_frame is None and synthetic:
            from gymfg_il.collectors.synthetic import SyntheticDriver

            on_frame = SyntheticDriver(config.skill)
        elif on_frame is None:  # a person at the controls
            check_person_can_fly(config.device)
        out = config.out
        check_out_folder(out)
        flight = self.flight = config.flight()
        self.config, self.out, self.on_frame = config, out, on_frame
        self.seed, self.max_episodes = config.seed, config.episodes
        self.realtime = not synthetic if realtime is None else realtime
        self.draw = not synthetic if draw is None else draw
        self.build_each = not synthetic
        self.env = flight.make_env(list(config.view) or None)
        self.timing = EpisodeTiming(self.env.dt)  # collectors.timing, for real-time sessions
        self._period: float | None = None  # the loop period that produced this frame
        self._late_at = -math.inf  # when a frame last came late
        self._read_at = -1.0  # the wall clock when this frame's input was read
        self.images, self.image_size = list(config.images), config.image_size
        names = self.env.observation_names
        check_appendable(out, names, flight.agent_hz, None, self.images, self.image_size)
        self.kb = from_table(KeyboardBindings, config.keyboard, "[collector.keyboard]")
        self.human = ManualController(
            config.device,
            self.kb,
            from_table(MouseBindings, config.mouse, "[collector.mouse]"),
            from_table(JoystickBindings, config.joystick, "[collector.joystick]"),
            throttle=self.env.aircraft.profile.cruise_throttle,
            flightgear=from_table(FlightGearBindings, config.flightgear, "[collector.flightgear]"),
        )
        assist = config.assist
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
        self.person = person = "synthetic" if synthetic else "human"
        named = config.pilot_name
        self.pilot_name = (
            named if named is not None else f"synthetic-{config.skill:g}" if synthetic else ""
        )
        self.marked = -1  # the log's episode that a mark would mark (-1: none to mark)
        self.source = person if assist is None else f"{self.assist_name}+{person}"
        self.help = help_lines(config.device, self.kb)
        title = f"GymFG-IL: {flight.task_label} on {self.env.aircraft.model}"
        pilot_view = None if config.pilot_view == "none" else config.pilot_view
        self.camera = (
            Camera(320, 320, view=pilot_view, legible=True) if pilot_view and self.draw else None
        )
        self.gui = ControlsGUI(size=(1250, 700) if self.camera else (900, 700), title=title)
        self.human.window_size = self.gui.size
        self.stats = SessionStats()
        self.state = "idle"
        self.show_help = True
        self.episode = 0
        self.next_seed = config.seed  # a discarded episode is flown again with its seed
        self.last_action = np.array([0.0, 0.0, 0.0, self.env.aircraft.profile.cruise_throttle])
        self.message = "Space: start an episode"
        self.writer: TrajectoryWriter | None = None
        self.updater = DatasetUpdater(out)
        self.briefing = briefing(self.env.task, self.env.world.max_steps * self.env.dt)
        self.debrief: Debrief | None = None
        tracked = self.env.task.tracked()
        self._error_at = names.index(tracked["error"]) if tracked else None
        self._flown: list[np.ndarray] = []  # this episode's states, the reset's first
        self._errors: list[float] = []
        self._return = 0.0
        self.display = self._look()

    def _look(self) -> Display:
        """What the window shows now (``display.readings``): the pilot's only source."""
        world = self.env.world
        flying = self.state != "idle"
        return display_of(self.env.task, world.slots[0].state, world.steps, flying)

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
        self._flown, self._errors, self._return = [starts[0].state.copy()], [], 0.0
        self.debrief = None
        self.step_count, self.interventions = 0, 0
        self.timing = EpisodeTiming(self.env.dt)
        self._writer().start_episode(seed, starts, source=self.source, pilot=self.pilot_name)
        self.marked = -1
        self.state, self.message, self.show_help = "recording", "", False

    def _finish(self, outcome: str) -> None:
        writer = self._writer()
        gusty = self.flight.turbulence != "none"
        states, errors = np.array(self._flown), np.array(self._errors)
        dt = self.env.dt
        self.debrief = debrief(self.env.task, states, errors, dt, outcome, self._return, gusty)
        writer.end_episode(
            outcome=outcome,
            steps=self.step_count,
            interventions=self.interventions,
            success=self.debrief.success,
            verdict=self.debrief.detail,
            grade=self.debrief.grade,
            **(self.timing.record() if self.realtime else {}),
        )
        self.marked = writer.episode
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
        elif command.startswith("mark ") and self.state == "idle" and self.marked >= 0:
            mark = command.split()[1]
            self._writer().mark_episode(self.marked, mark)
            self.message = f"episode marked {mark} by you; Space: next episode"
            if self.build_each:
                self.updater.request()  # the dataset shows the mark
        return True

    def _step(self) -> None:
        tick = self.rollout.step()
        self._writer().log_tick(tick, self._read_at if self.realtime else None)
        (step,) = tick.steps
        self.last_action = step.action
        self._flown.append(step.state.copy())
        self._return += step.reward
        if self._error_at is not None:
            self._errors.append(float(self.observation[self._error_at]))
        self.step_count += 1
        self.interventions += int(step.intervention)
        if self.realtime and self._period is not None and self.timing.add(self._period):
            self._late_at = time.perf_counter()
        if tick.done:
            self._finish(step.reason or "terminated" if step.terminated else "time limit")

    @property
    def late_warning(self) -> str:
        """The window's warning while frames come late (``collectors.timing``), else ""."""
        if time.perf_counter() - self._late_at > WARN_S or self.state != "recording":
            return ""
        return (
            f"LATE: {self.timing.late} frame(s) came late this episode; the flight slowed "
            "(the data stays exact)"
        )

    def _draw(self) -> None:
        self.gui.draw(window_frame(self))

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
                self._period = None if last_start is None else start - last_start
                if self._period is not None:
                    self.stats.periods.append(self._period)
                last_start = start
                if self.on_frame is not None:
                    self.on_frame(frame, self)
                events = pygame.event.get()
                self._read_at = time.time()  # the input this frame flies by is read now
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
                # once a frame, after what changed it: the window draws it now, and the
                # synthetic pilot reads the same at the start of the next frame
                self.display = self._look()
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
