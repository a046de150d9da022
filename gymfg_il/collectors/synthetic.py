"""The synthetic pilot at the real collection session: it presses Space to start each episode
and, while one is flown, looks at the session's display (what the window draws) and puts its
key, joystick or mouse events into pygame's queue, where the session loop reads them as it
reads a person's (``collect manual --pilot synthetic``).

With an assistant (``--assist POLICY``) it is a human-gated DAgger teacher: it takes over (T)
when the task's error grows past ``gate`` times the task's tolerance and hands back once the
error has stayed within the tolerance for ``settle_s``; its frames are the interventions.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from gymfg_il.manual.perception import DisplayIntent
from gymfg_il.manual.synthetic import SyntheticPilot, key_codes

if TYPE_CHECKING:
    from gymfg_il.collectors.manual import ManualSession


def _post(kind: str, key: str) -> None:
    import pygame

    code = key_codes()[key]
    pygame.event.post(
        pygame.event.Event(getattr(pygame, kind), key=code, mod=0, unicode="", scancode=0)
    )


def _tap(key: str) -> None:
    _post("KEYDOWN", key)
    _post("KEYUP", key)


class SyntheticDriver:
    """An ``on_frame`` hook of ``ManualSession`` that flies like a person (module docstring).

    Args:
        skill: the pilot's level in [0, 1].
        gate: with an assistant, take over when |error| exceeds this many tolerances.
        settle_s: hand back after the error has stayed within the tolerance this long.
    """

    def __init__(self, skill: float = 0.7, gate: float = 3.0, settle_s: float = 3.0) -> None:
        self.skill, self.gate, self.settle_s = skill, gate, settle_s
        self.pilot: SyntheticPilot | None = None
        self._settled = 0.0
        self._episode = -1
        self.sent: list[list[Any]] = []  # per recorded frame: the device events it made

    def _build(self, session: ManualSession) -> SyntheticPilot:
        env = session.env
        throttle = env.aircraft.profile.cruise_throttle
        intent = DisplayIntent(env.task, env.aircraft.model, env.dt, throttle)
        pilot = SyntheticPilot(
            session.human.device,
            intent,
            env.dt,
            self.skill,
            session.human.keys,
            session.human.mouse,
            session.human.joy,
            session.gui.size,
        )
        tracked = env.task.tracked() or {}
        names = list(env.observation_names)
        self._error_at = names.index(tracked["error"]) if tracked else None
        self._tolerance = float(tracked.get("tolerance", 0.0))
        return pilot

    def __call__(self, frame: int, session: ManualSession) -> None:
        if self.pilot is None:
            self.pilot = self._build(session)
        if session.state == "idle":
            _tap("space")  # the next episode
            return
        if session.state != "recording":
            return
        if session.episode != self._episode:  # a new episode: a fresh pilot, its own seed
            self._episode = session.episode
            self.pilot.reset(session.next_seed)
            self.pilot.start_from(session.human.start_controls)
            self._settled = 0.0
        if session.pilot.assistant is not None:
            self._gate(session)
        if session.human_flies:
            for event in self.pilot.events(session.display, session.human.values):
                _post_event(event)
            self.sent.append(list(self.pilot.sent))
        else:
            self.sent.append([])

    def _gate(self, session: ManualSession) -> None:
        """Take over when the error grows too large; hand back once it has settled."""
        if self._error_at is None:
            return
        error = abs(float(session.observation[self._error_at]))
        if not session.human_flies:
            if error > self.gate * self._tolerance:
                _tap("t")
                self._settled = 0.0
            return
        self._settled = self._settled + session.env.dt if error <= self._tolerance else 0.0
        if self._settled >= self.settle_s:
            _tap("t")


def _post_event(event: Any) -> None:
    import pygame

    pygame.event.post(event)
