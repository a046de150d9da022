"""``python -m gymfg_il.collectors.screenshot PATH``: a PNG of the controls GUI in flight.

Runs the manual session off-screen (``SDL_VIDEODRIVER=dummy``) with the controller assisting,
injects a stick input, and saves the window after a few seconds; the Fly-by-hand guide's
picture (docs/images/gui.png) is made by it.
"""

from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path


def main(argv: list[str] | None = None) -> int:
    args = list(sys.argv[1:] if argv is None else argv)
    if len(args) != 1 or args[0].startswith("-"):
        print(__doc__)
        return 2
    target = Path(args[0])
    os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
    import pygame

    from gymfg_il.collectors.config import ManualConfig
    from gymfg_il.collectors.manual import ManualSession

    def key(k: int, down: bool = True) -> None:
        kind = pygame.KEYDOWN if down else pygame.KEYUP
        pygame.event.post(pygame.event.Event(kind, key=k, mod=0, unicode="", scancode=0))

    def on_frame(frame: int, session: ManualSession) -> None:
        if frame == 1:
            key(pygame.K_SPACE)
        elif frame == 60:
            key(pygame.K_t)  # take over from the controller...
        elif frame == 61:
            key(pygame.K_RIGHT)  # ...and roll right
        elif frame == 75:
            key(pygame.K_RIGHT, False)
        elif frame == 80:
            session.gui.screenshot(target)
            key(pygame.K_q)

    with tempfile.TemporaryDirectory() as tmp:
        cfg = ManualConfig(
            task="altitude",
            episode_time_s=30,
            agent_hz=30,
            seed=3,
            out=Path(tmp),
            assist="controller",  # it flies until the injected T
        )
        ManualSession(cfg, on_frame, realtime=False).run(max_frames=200)
    print(f"screenshot written to {target}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
