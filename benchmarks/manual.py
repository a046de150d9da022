"""The real-time manual session: frame timing at 30 Hz with the GUI and recording on."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

import numpy as np

from benchmarks.common import Row


def manual_loop(seconds: float) -> Row:
    """p99 |frame period - 1/30 s| of the manual session at 30 Hz with the GUI and recording
    on, flown by injected keyboard input (pygame's dummy video driver)."""
    os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
    import pygame

    from gymfg_il.collectors.manual import ManualSession
    from gymfg_il.envs.flight import FlightSpec

    frames = int(seconds * 30)
    keys = [pygame.K_LEFT, pygame.K_UP, pygame.K_RIGHT, pygame.K_DOWN]

    def on_frame(frame: int, session: ManualSession) -> None:
        if frame == 1:
            kind, key = pygame.KEYDOWN, pygame.K_SPACE
        elif frame % 15 == 0:  # a key goes down or up twice a second
            kind = pygame.KEYDOWN if frame % 30 == 0 else pygame.KEYUP
            key = keys[(frame // 30) % 4]
        else:
            return
        pygame.event.post(pygame.event.Event(kind, key=key, mod=0, unicode="", scancode=0))

    with tempfile.TemporaryDirectory() as tmp:
        flight = FlightSpec.solo(episode_time_s=seconds + 5, agent_hz=30)
        stats = ManualSession(flight, Path(tmp), on_frame=on_frame).run(max_frames=frames)
    errors = np.abs(np.array(stats.periods[2:]) - 1 / 30) * 1000
    return Row(
        "manual_loop_p99_period_error_ms",
        float(np.percentile(errors, 99)),
        "ms",
        5.0,
        higher_is_better=False,
        detail=[
            f"manual loop at 30 Hz (GUI + MCAP), {len(errors)} frames: period error median "
            f"{np.median(errors):.2f} ms"
        ],
    )


def rows(quick: bool) -> list[Row]:
    return [manual_loop(5 if quick else 20)]
