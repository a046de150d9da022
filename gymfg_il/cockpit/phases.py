"""The phases stage of the cockpit session: what the session commands do to the episodes.

    idle --start--> recording <--pause--> paused
      ^                 |  end (E) or the episode's own end: saved, judged
      +-----------------+  discard (Backspace): dropped, its seed flown again

Q or Esc quits (an episode in flight is discarded); T takes over from the assistant or
hands back; G or B marks the last saved episode (the pilot's own verdict); H shows or hides
the help. Each saved episode is already durable in the log (``cockpit.flight_log``); a
person's session also asks for the dataset to follow at once (``cockpit.updater``).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path

from gymfg_il.cockpit.flight_log import FlightLog
from gymfg_il.cockpit.updater import DatasetUpdater
from gymfg_il.manual.takeover import Takeover
from gymfg_il.rollout.loop import Rollout

EPISODE_COMMANDS = ("end", "discard", "pause")  # what a flown (recording or paused) episode takes


@dataclass
class SessionStats:
    """What a session did: episodes saved and discarded, frames run, each loop period (s),
    the dataset once it is built, and the seconds its end took (``closing_s``: the dataset
    catching up with the log, the helper's imports included when it had not finished them)."""

    saved: int = 0
    discarded: int = 0
    frames: int = 0
    periods: list[float] = field(default_factory=list)
    dataset: Path | None = None
    closing_s: float = 0.0


class Phases:
    """The session's phase (``idle``, ``recording`` or ``paused``) and the episodes it starts
    and ends.

    Args:
        rollout: resets the aircraft for each episode.
        log: the session's ``FlightLog``.
        takeover: the pilot that T hands over.
        updater: the dataset, asked to follow each saved episode (and mark) when
            ``build_each``.
        stats: the session's tally (saved, discarded).
        seed: the first episode's seed (a discarded episode is flown again with its seed).
    """

    def __init__(
        self,
        rollout: Rollout,
        log: FlightLog,
        takeover: Takeover,
        updater: DatasetUpdater,
        stats: SessionStats,
        *,
        seed: int,
        build_each: bool,
    ) -> None:
        self.rollout, self.log, self.takeover = rollout, log, takeover
        self.updater, self.stats, self.build_each = updater, stats, build_each
        self.state = "idle"
        self.episode = 0  # episodes saved: the number of the next one
        self.started = 0  # episodes started (a discarded one flown again counts again)
        self.next_seed = seed
        self.marked = -1  # the log's episode that a mark would mark (-1: none to mark)
        self.message = "Space: start an episode"
        self.show_help = True

    @property
    def flying(self) -> bool:
        """An episode is in flight (recording or paused)."""
        return self.state != "idle"

    def apply(self, commands: Iterable[str]) -> bool:
        """Apply this frame's session commands, in order; False once one of them quits."""
        running = True
        for command in commands:
            running = self._apply(command) and running
        return running

    def _apply(self, command: str) -> bool:
        if command == "quit":
            if self.flying:
                self._discard()
            return False
        if command == "help":
            self.show_help = not self.show_help
        elif command == "start" and not self.flying:
            self._start()
        elif command in EPISODE_COMMANDS and self.flying:
            if command == "end":
                self.finish("ended by the pilot")
            elif command == "discard":
                self._discard()
            else:
                self.state = "paused" if self.state == "recording" else "recording"
        elif command == "takeover":
            self.takeover.toggle(self.log.last_action)
        elif command.startswith("mark ") and not self.flying and self.marked >= 0:
            self._mark(command.split()[1])
        return True

    def _start(self) -> None:
        self.updater.warm()  # its imports overlap the flying
        seed = self.next_seed
        self.log.start(seed, self.rollout.reset(seed))
        self.started += 1
        self.marked = -1
        self.state, self.message, self.show_help = "recording", "", False

    def finish(self, outcome: str) -> None:
        """The episode ended (``outcome``: why): judged, saved, the next one's seed taken."""
        self.marked = self.log.finish(outcome)
        if self.build_each:
            self.updater.request()  # the dataset follows in a helper process, off the GIL
        self.stats.saved += 1
        self.episode += 1
        self.next_seed += 1
        self.state = "idle"
        self.message = f"episode saved ({outcome}); Space: next episode"

    def _discard(self) -> None:
        self.log.discard("discarded by the pilot")
        self.stats.discarded += 1
        self.state, self.message = "idle", "episode discarded; Space: fly it again"

    def _mark(self, mark: str) -> None:
        self.log.mark(self.marked, mark)
        self.message = f"episode marked {mark} by you; Space: next episode"
        if self.build_each:
            self.updater.request()  # the dataset shows the mark
