"""What a person needs before a manual session starts: a window they can see, and the device
they fly with. Without either the session would wait, silently, for input that cannot come
(pygame with no display picks its ``offscreen`` driver and draws nowhere; a joystick session
with no joystick reads nothing), so it refuses at once and says what is missing.

``SDL_VIDEODRIVER=dummy`` (or ``offscreen``) means no window on purpose: right for the
synthetic pilot and for tests, which inject their events, and refused for a person, whose
keys and mouse could never reach it.

Looking for a display, SDL tries each of its video drivers, and the libraries behind them
write to the process's stderr as they fail (libwayland's "error: XDG_RUNTIME_DIR is invalid
or not set in the environment.", which read as a second error before the session's own):
what they write during the probe is held back, dropped where the session is refused (its one
line says what is missing) and passed on where a window can open.
"""

from __future__ import annotations

import contextlib
import os
import sys
import tempfile
from collections.abc import Iterator
from typing import Any

from gymfg_il.errors import ConfigError, join_problems

HEADLESS_DRIVERS = ("dummy", "offscreen")


class NoPersonInputError(ConfigError):
    """A manual session for a person with no window to see or no device to fly with."""


def window_problem(pygame: Any) -> str | None:
    """Why a person could not see and type into the session's window, or None.

    Initialises pygame's display (the session's window opens on it next)."""
    asked = os.environ.get("SDL_VIDEODRIVER", "")
    if asked.lower() in HEADLESS_DRIVERS:
        return (
            f"SDL_VIDEODRIVER={asked} draws the window nowhere, so no key or mouse can reach "
            "it: unset SDL_VIDEODRIVER where a display is (DISPLAY or WAYLAND_DISPLAY), or "
            "collect headless with --pilot synthetic"
        )
    said: list[str] = []
    with _stderr_held(said):
        problem = _display_problem(pygame)
    if problem is None and said:  # a window opens: what SDL said may matter
        print("\n".join(said), file=sys.stderr, flush=True)
    return problem


def _display_problem(pygame: Any) -> str | None:
    try:
        pygame.display.init()
    except pygame.error as err:
        return f"pygame cannot open a display ({err}): set DISPLAY to a running X server"
    driver = pygame.display.get_driver()
    if driver in HEADLESS_DRIVERS:
        pygame.display.quit()
        shown = {v: os.environ.get(v) for v in ("DISPLAY", "WAYLAND_DISPLAY")}
        if shown["WAYLAND_DISPLAY"]:  # Wayland finds its socket in XDG_RUNTIME_DIR
            shown["XDG_RUNTIME_DIR"] = os.environ.get("XDG_RUNTIME_DIR")
        where = ", ".join(f"{k}={v}" if v else f"{k} unset" for k, v in shown.items())
        return (
            f"no display to open the window on ({where}; pygame fell back to its {driver!r} "
            "driver, which draws nowhere): fly in a desktop session, set DISPLAY to a running "
            "X server (ssh -X, or Xvfb with a VNC viewer), or collect headless with "
            "--pilot synthetic"
        )
    return None


@contextlib.contextmanager
def _stderr_held(said: list[str]) -> Iterator[None]:
    """The lines written to the process's stderr (file descriptor 2, where C libraries
    write) while the block runs, into ``said`` instead of the terminal."""
    sys.stderr.flush()
    try:
        saved = os.dup(2)
    except OSError:  # no stderr to hold back
        yield
        return
    with tempfile.TemporaryFile() as held:
        os.dup2(held.fileno(), 2)
        try:
            yield
        finally:
            sys.stderr.flush()
            os.dup2(saved, 2)
            os.close(saved)
            held.seek(0)
            said += held.read().decode(errors="replace").splitlines()


def joystick_problem(pygame: Any) -> str | None:
    """Why a joystick session has no joystick to read, or None."""
    pygame.joystick.init()
    if pygame.joystick.get_count() > 0:
        return None
    return (
        "--device joystick: no joystick is connected (SDL sees none): plug one in and start "
        "again (check it under /dev/input, and that this user may read it), or fly with "
        "--device keyboard or mouse"
    )


def check_person_can_fly(device: str) -> None:
    """Refuse, before anything is built, a person's session that could never get input:
    every missing thing in one message."""
    import pygame

    problems = [p for p in (window_problem(pygame),) if p]
    if device == "joystick" and (problem := joystick_problem(pygame)):
        problems.insert(0, problem)
    if problems:
        raise NoPersonInputError(join_problems("collect manual", problems))
