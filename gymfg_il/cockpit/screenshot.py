"""``python -m gymfg_il.cockpit.screenshot PATH [--task T] [--at S]``: a PNG of the
cockpit's window in flight.

Runs the cockpit session off-screen (``SDL_VIDEODRIVER=dummy`` unless a display is set) and
saves the window ``--at`` seconds into the first episode. With the default task (altitude)
the controller assists and a stick input is injected (the Fly-by-hand guide's picture,
docs/images/gui.png); with ``--task`` the synthetic pilot flies the task through the
keyboard, as a person would, from what the window shows (docs/images/window_approach.png,
window_formation.png: ``make pictures``).
"""

from __future__ import annotations

import argparse
import os
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # the session's imports wait until a picture is asked for (--help is quick)
    from gymfg_il.cockpit.session import ManualSession


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="python -m gymfg_il.cockpit.screenshot",
        description=__doc__.split("\n\n", 1)[1],
    )
    parser.add_argument("path", type=Path, help="where to write the PNG")
    parser.add_argument(
        "--task", default=None, help="fly this task with the synthetic pilot (default: altitude)"
    )
    parser.add_argument(
        "--at", type=float, default=None, help="seconds into the episode (default 2.5, or 20)"
    )
    parser.add_argument("--seed", type=int, default=3, help="the episode's seed (default 3)")
    return parser


HZ = 30


def main(argv: list[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    if not os.environ.get("DISPLAY"):
        os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
    with tempfile.TemporaryDirectory() as tmp:
        if args.task is None:
            _assisted(args.path, Path(tmp), args.seed, args.at or 2.5)
        else:
            _flown(args.path, Path(tmp), args.task, args.seed, args.at or 20.0)
    print(f"screenshot written to {args.path}")
    return 0


def _key(k: int, down: bool = True) -> None:
    import pygame

    kind = pygame.KEYDOWN if down else pygame.KEYUP
    pygame.event.post(pygame.event.Event(kind, key=k, mod=0, unicode="", scancode=0))


def _shoot(session: ManualSession, target: Path) -> None:
    from gymfg_il.cockpit.windows.pygame_window import PygameWindow

    window = session.stages.window
    assert isinstance(window, PygameWindow)  # the session was built to draw
    window.gui.screenshot(target)


def _assisted(target: Path, out: Path, seed: int, at_s: float) -> None:
    """The controller flies the altitude task; at 2 s the pilot takes over and rolls right."""
    import pygame

    from gymfg_il.cockpit.session import ManualSession
    from gymfg_il.collectors.config import ManualConfig

    shot = round(at_s * HZ) + 5

    def on_frame(frame: int, session: ManualSession) -> None:
        if frame == 1:
            _key(pygame.K_SPACE)
        elif frame == 60:
            _key(pygame.K_t)  # take over from the controller...
        elif frame == 61:
            _key(pygame.K_RIGHT)  # ...and roll right
        elif frame == 75:
            _key(pygame.K_RIGHT, False)
        elif frame == shot:
            _shoot(session, target)
            _key(pygame.K_q)

    cfg = ManualConfig(
        task="altitude",
        episode_time_s=30,
        agent_hz=HZ,
        seed=seed,
        out=out,
        assist="controller",  # it flies until the injected T
    )
    ManualSession(cfg, on_frame, realtime=False).run(max_frames=shot + 10)


def _flown(target: Path, out: Path, task: str, seed: int, at_s: float) -> None:
    """The synthetic pilot flies ``task``; the shot, then Q."""
    import pygame

    from gymfg_il.cockpit.session import ManualSession
    from gymfg_il.collectors.config import ManualConfig

    shot = round(at_s * HZ) + 2

    def on_frame(frame: int, session: ManualSession) -> None:
        if frame == shot:
            _shoot(session, target)
            _key(pygame.K_q)

    cfg = ManualConfig(task=task, agent_hz=HZ, seed=seed, out=out, pilot="synthetic", episodes=1)
    ManualSession(cfg, on_frame, realtime=False, draw=True).run(max_frames=shot + 5)


if __name__ == "__main__":
    raise SystemExit(main())
