"""The pilots of a web server and their cockpit sessions (``web.server``).

Each invite's pilot gets a cockpit session (``cockpit.session``, ``collect manual``'s loop) on
a thread of its own when they first open their invite, with a browser as its input and window
(``web.link``) and the server's one dataset updater; it flies on, idle, while they are away,
and another device starts another session (from the next seed). ``Pilots.close`` ends every
session (an episode in flight is discarded) and finishes the dataset.
"""

from __future__ import annotations

import logging
import re
import threading
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from gymfg_il.cockpit.build import Plug
from gymfg_il.cockpit.updater import DatasetUpdater
from gymfg_il.web.config import WebConfig
from gymfg_il.web.invites import Invite
from gymfg_il.web.link import PilotLink, WebInput, WebWindow
from gymfg_il.web.protocol import JOINS_BURST, JOINS_HZ, RateLimit

log = logging.getLogger(__name__)

START_S = 60  # a session that has not started flying by then is refused


class SharedUpdater(DatasetUpdater):
    """One dataset updater for every pilot's session (``cockpit.updater``: one helper process
    writes the dataset). A session's end leaves it running; ``shutdown`` finishes it."""

    def __init__(self, out: Path) -> None:
        super().__init__(out)
        self.lock = threading.RLock()

    def warm(self) -> None:
        with self.lock:
            super().warm()

    def request(self) -> None:
        with self.lock:
            super().request()

    def poll(self) -> None:
        if self.lock.acquire(blocking=False):  # another pilot's loop is polling: skip
            try:
                super().poll()
            finally:
                self.lock.release()

    def close(self) -> bool:
        """A pilot's session ended: the dataset goes on serving the others."""
        return self.built

    def shutdown(self) -> bool:
        """Finish every outstanding build and stop the helper; True if a dataset was built."""
        with self.lock:
            return super().close()


@dataclass
class Pilot:
    """One invite's pilot: their session (a thread), its link, the socket flying it, the
    episodes they saved in sessions that ended, how often their invite is opened."""

    invite: Invite
    next_seed: int
    link: PilotLink | None = None
    thread: threading.Thread | None = None
    device: str | None = None
    socket: Any = None
    saved: int = 0
    lock: threading.Lock = field(default_factory=threading.Lock)
    joins: RateLimit = field(
        default_factory=lambda: RateLimit(JOINS_HZ, JOINS_BURST, "openings of an invite")
    )


def _file_name(name: str) -> str:
    """A pilot's name as part of a log file's name."""
    return re.sub(r"[^A-Za-z0-9_.-]", "_", name)[:40] or "pilot"


class Pilots:
    """Every invite's pilot and session (module docstring).

    Args:
        config: the server's config (the flight, the folder, the episodes a pilot may save).
        invites: who may fly.
        flight_options: the flight's options, as the page's welcome says them.
        say: prints the server's output.
    """

    def __init__(
        self,
        config: WebConfig,
        invites: list[Invite],
        flight_options: dict[str, Any],
        say: Callable[[str], None],
    ) -> None:
        self.config, self.flight_options, self.say = config, flight_options, say
        self.by_name = {i.name: Pilot(i, i.seed) for i in invites}
        self.updater = SharedUpdater(config.out)
        self.lock = threading.Lock()

    # -- a pilot's session ----------------------------------------------------------------
    def start(self, pilot: Pilot, device: str) -> str | None:
        """Start the pilot's session (or keep it: the same device) and wait until it flies;
        why it could not, or None."""
        with pilot.lock:
            running = pilot.thread is not None and pilot.thread.is_alive()
            if running and pilot.device != device:
                assert pilot.link is not None and pilot.thread is not None
                pilot.link.stop = True  # another device: a new session, the next seed on
                pilot.thread.join(START_S)
                if pilot.thread.is_alive():
                    return "the session of the other device does not end"
            if not running or pilot.device != device:
                pilot.link, pilot.device = PilotLink(pilot.invite.name, self.say), device
                pilot.thread = threading.Thread(
                    target=self._run,
                    args=(pilot, pilot.link, device),
                    name=f"pilot-{pilot.invite.name}",
                    daemon=True,
                )
                pilot.thread.start()
            link = pilot.link
            assert link is not None
        if not link.ready.wait(START_S):  # (a page that came while it starts waits here too)
            return f"it did not start within {START_S} s; try again"
        return link.failed

    def _run(self, pilot: Pilot, link: PilotLink, device: str) -> None:
        from gymfg_il.cockpit.session import ManualSession

        left = self.config.episodes - pilot.saved if self.config.episodes else 0
        config = self.config.pilot_session(pilot.invite.name, pilot.next_seed, device, left)
        options = self.flight_options
        say = self.say

        def window(human: Any, env: Any, flight: Any) -> WebWindow:
            return WebWindow(link, human, env, flight, options, say)

        plug = Plug(
            input=lambda human, env: WebInput(link, human, env.dt),
            window=window,
            updater=self.updater,
            log_tag=f"web-{_file_name(pilot.invite.name)}",
        )
        try:
            session = ManualSession(config, plug=plug, realtime=True, draw=True)
            # a first reset builds and trims what later ones reuse (tens of ms): done now, not
            # in a frame while other pilots fly (a reset is seeded: the flight is the same)
            session.stages.env.reset(seed=config.seed)
        except Exception as err:  # said to the page, and here
            link.failed = f"{type(err).__name__}: {err}"
            log.exception("pilot %s: the session did not start", pilot.invite.name)
            link.ready.set()
            return
        link.ready.set()
        try:
            session.run()
        except Exception as err:  # a fault of this pilot's session: the others fly on
            log.exception("pilot %s: the session failed", pilot.invite.name)
            link.close_page(f"the session failed ({type(err).__name__}); nothing saved is lost")
            return
        finally:
            pilot.next_seed = session.stages.phases.next_seed
            pilot.saved += session.stats.saved
        if not link.stop:  # the pilot saved every episode asked for
            link.close_page(f"thank you: you saved your {pilot.saved} episode(s)")

    def close(self) -> tuple[int, bool]:
        """End every session and finish the dataset: episodes saved, whether one was built."""
        for pilot in self.by_name.values():
            if pilot.link is not None:
                pilot.link.stop = True
        for pilot in self.by_name.values():
            if pilot.thread is not None:
                pilot.thread.join(timeout=30)
        built = self.updater.shutdown()
        return sum(p.saved for p in self.by_name.values()), built
