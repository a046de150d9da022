"""``python -m gymfg_il.collectors.screenshot PATH [--task T] [--at S]``: a PNG of the
collector's window in flight.

Runs the manual session off-screen (``SDL_VIDEODRIVER=dummy`` unless a display is set) and
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


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="python -m gymfg_il.collectors.screenshot",
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


def main(argv: list[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    target: Path = args.path
    if not os.environ.get("DISPLAY"):
        os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
    import pygame

    from gymfg_il.collectors.config import ManualConfig
    from gymfg_il.collectors.manual import ManualSession

    def key(k: int, down: bool = True) -> None:
        kind = pygame.KEYDOWN if down else pygame.KEYUP
        pygame.event.post(pygame.event.Event(kind, key=k, mod=0, unicode="", scancode=0))

    hz = 30
    with tempfile.TemporaryDirectory() as tmp:
        if args.task is None:
            shot = round((args.at or 2.5) * hz) + 5

            def on_frame(frame: int, session: ManualSession) -> None:
                if frame == 1:
                    key(pygame.K_SPACE)
                elif frame == 60:
                    key(pygame.K_t)  # take over from the controller...
                elif frame == 61:
                    key(pygame.K_RIGHT)  # ...and roll right
                elif frame == 75:
                    key(pygame.K_RIGHT, False)
                elif frame == shot:
                    session.gui.screenshot(target)
                    key(pygame.K_q)

            cfg = ManualConfig(
                task="altitude",
                episode_time_s=30,
                agent_hz=hz,
                seed=args.seed,
                out=Path(tmp),
                assist="controller",  # it flies until the injected T
            )
            ManualSession(cfg, on_frame, realtime=False).run(max_frames=shot + 10)
        else:
            from gymfg_il.collectors.synthetic import SyntheticDriver

            shot = round((args.at or 20.0) * hz) + 2
            pilot = SyntheticDriver()

            def on_frame(frame: int, session: ManualSession) -> None:
                if frame == shot:
                    session.gui.screenshot(target)
                    key(pygame.K_q)
                    return
                pilot(frame, session)

            cfg = ManualConfig(
                task=args.task,
                agent_hz=hz,
                seed=args.seed,
                out=Path(tmp),
                pilot="synthetic",
                episodes=1,
            )
            ManualSession(cfg, on_frame, realtime=False, draw=True).run(max_frames=shot + 5)
    print(f"screenshot written to {target}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
