"""The cockpit session (``collect manual``): a person or the synthetic pilot flies in a window,
in real time, and every completed episode becomes data at once.

It is a loop of small stages, each passed what it needs, in the order LeRobot's record loop
uses; ``cockpit.build`` makes them from the config. Each frame:

    pace -> input.poll -> phases.apply(commands) -> rollout.step -> log.log -> updater.poll
         -> display model -> window.draw

- ``pace`` (``cockpit.pace``): waits for the frame's start (real time), gives the loop period;
- ``input.poll`` (``cockpit.inputs``): a person's devices or the synthetic pilot move the
  controls and give the session commands (keys in ``cockpit.inputs.keys``; also shown by the
  help overlay, H);
- ``phases.apply`` (``cockpit.phases``): Space starts an episode, E ends and saves it,
  Backspace discards it (the same case is flown again), P pauses, T takes over from the
  assisting controller or policy and hands back, G or B marks it, Q or Esc quits;
- ``rollout.step`` (``rollout.loop``): while recording, the aircraft flies one step;
- ``log.log`` (``cockpit.flight_log``): the step goes to the MCAP log at once, so quitting
  or a crash loses nothing completed;
- ``updater.poll`` (``cockpit.updater``): the dataset follows each saved episode in a helper
  process;
- the display model (``display.readings``): what the window shows, and all the synthetic
  pilot reads, at the start of the next frame;
- ``window.draw`` (``cockpit.windows``): pygame's window, or none.
"""

from __future__ import annotations

import time
from collections.abc import Callable

from gymfg_il.cockpit.build import Plug, Stages, build
from gymfg_il.cockpit.inputs.source import Seen
from gymfg_il.cockpit.phases import SessionStats
from gymfg_il.cockpit.windows.view import CockpitView
from gymfg_il.collectors.config import ManualConfig
from gymfg_il.collectors.session import DATASET
from gymfg_il.display.readings import Display, display_of

FrameHook = Callable[[int, "ManualSession"], None]

__all__ = ["FrameHook", "ManualSession", "SessionStats"]


class ManualSession:
    """Run the cockpit session of one ``ManualConfig``.

    Args:
        config: what to fly and how (``collectors.config.ManualConfig``): the flight, the
            session folder, who flies (a person, or the synthetic pilot at its skill), the
            device and its bindings, an assistant (``controller`` or a policy that flies
            until the pilot takes over, T; the pilot's frames are flagged as interventions),
            the seed of the first episode (a discarded episode is flown again with its seed),
            the episodes to save (0: until quit), FlightGear views, the dataset's camera
            views and the window's camera.
        on_frame: called at the start of each frame with the frame's number and the session,
            for tests and tools (which post pygame events, take screenshots, look at the
            stages); no stage sees it. Without one a person's session is refused at once if
            it could never get input (no window they can see, no joystick for
            ``device="joystick"``: ``manual.devices``).
        realtime: pace frames to the wall clock at the flight's rate (default: for a person;
            the synthetic pilot flies as fast as the machine allows).
        draw: draw the window every frame (default: for a person; the synthetic pilot needs
            no pictures).
        plug: the input, window and dataset updater of a session flown from elsewhere
            (``cockpit.build.Plug``: ``collect web``'s browser pilots).

    A person's session brings the dataset up to date after every saved episode (so that
    quitting loses nothing); the synthetic pilot's once, at the end (the log keeps every
    episode durable either way). The dataset calls the pilot ``human`` or ``synthetic``
    (``controller+human`` and so on with an assistant). The stages are ``stages``
    (``cockpit.build.Stages``).
    """

    def __init__(
        self,
        config: ManualConfig,
        on_frame: FrameHook | None = None,
        *,
        realtime: bool | None = None,
        draw: bool | None = None,
        plug: Plug | None = None,
    ) -> None:
        self.stages: Stages = build(
            config, driven=on_frame is not None, realtime=realtime, draw=draw, plug=plug
        )
        self.on_frame = on_frame
        self.display = self._look()

    @property
    def stats(self) -> SessionStats:
        return self.stages.stats

    def run(self, max_frames: int | None = None) -> SessionStats:
        """Fly frames until the pilot quits, the episodes asked for are saved, or
        ``max_frames`` have run; the session is closed at the end."""
        stats, episodes = self.stages.stats, self.stages.episodes
        try:
            while max_frames is None or stats.frames < max_frames:
                running = self._frame(stats.frames)
                stats.frames += 1
                if not running or (episodes and stats.saved >= episodes):
                    break
        finally:
            self.close()
        return stats

    def _frame(self, frame: int) -> bool:
        """One frame through every stage (module docstring); False once the pilot quit."""
        s = self.stages
        period = s.pace.wait()
        if period is not None:
            s.stats.periods.append(period)
        if self.on_frame is not None:
            self.on_frame(frame, self)
        polled = s.input.poll(self._seen())
        started = s.phases.started
        running = s.phases.apply(polled.commands)
        if running and s.phases.state == "recording":
            tick = s.rollout.step()
            ended = s.log.log(tick, s.rollout.current[0], polled.read_at, period, polled.remote)
            if ended is not None:
                s.phases.finish(ended)
        s.updater.poll()
        if s.phases.started != started:  # the reset's trimming took part of this frame
            s.pace.restart()
        # once a frame, after what changed it: the window draws it now, and the synthetic
        # pilot reads the same at the start of the next frame
        self.display = self._look()
        if s.window.shown:
            s.window.draw(self._view())
        return running

    def _look(self) -> Display:
        """The display model now (``display.readings``): the pilot's only source."""
        world = self.stages.env.world
        flying = self.stages.phases.flying
        return display_of(self.stages.env.task, world.slots[0].state, world.steps, flying)

    def _seen(self) -> Seen:
        s = self.stages
        current = s.rollout.current
        return Seen(
            s.phases.state,
            s.phases.started,
            s.phases.next_seed,
            self.display,
            s.takeover.human_flies,
            current[0] if current else None,
        )

    def _view(self) -> CockpitView:
        s = self.stages
        world, phases, human = s.env.world, s.phases, s.human
        return CockpitView(
            status=phases.state,
            episode=phases.episode,
            steps=world.steps,
            state=world.slots[0].state,
            display=self.display,
            controls=human.values,
            trim=human.neutral,
            flown=s.log.last_action,
            human_flies=s.takeover.human_flies,
            debrief=s.log.debrief,
            message=phases.message or human.status,
            late=s.log.late_warning(phases.state == "recording"),
            show_help=phases.show_help,
            seed=phases.next_seed,
            started=phases.started,
        )

    def close(self) -> None:
        """Close the log, the env, the input and the window; the dataset catches up with the
        log (``stats.dataset`` says where it is once built)."""
        s = self.stages
        started = time.perf_counter()
        s.log.close()
        s.env.close()
        s.input.close()
        s.window.close()
        if not s.phases.build_each and s.stats.saved:
            s.updater.request()
        if s.updater.close():
            s.stats.dataset = s.out / DATASET
        s.stats.closing_s = time.perf_counter() - started
