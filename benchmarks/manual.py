"""The manual session: frame timing at 30 Hz with the GUI and recording on, how fast the
synthetic pilot collects headless, and how soon a real key press reaches the record."""

from __future__ import annotations

import math
import os
import tempfile
from pathlib import Path

import numpy as np

from benchmarks.common import Row


def manual_loop(seconds: float) -> Row:
    """p99 |frame period - 1/30 s| of the manual session at 30 Hz with the GUI and recording
    on, flown by injected keyboard input (pygame's dummy video driver), on the approach: the
    window's busiest task (every guidance reading, the ILS, the runway in the pilot's view)."""
    os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
    import pygame

    from gymfg_il.cockpit.session import ManualSession
    from gymfg_il.collectors.config import ManualConfig

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
        # the approach: the most readings, the ILS, the runway in the view
        cfg = ManualConfig(
            task="approach", episode_time_s=seconds + 5, agent_hz=30, episodes=0, out=Path(tmp)
        )
        stats = ManualSession(cfg, on_frame).run(max_frames=frames)
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


def synthetic_pilot(seconds: float) -> Row:
    """Simulated seconds per wall-clock second of the synthetic pilot collecting through the
    real session loop, headless (two episodes, MCAP log and the dataset built at the end)."""
    os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
    import time

    from gymfg_il.cockpit.session import ManualSession
    from gymfg_il.collectors.config import ManualConfig

    with tempfile.TemporaryDirectory() as tmp:
        cfg = ManualConfig(
            episode_time_s=seconds, agent_hz=30, pilot="synthetic", episodes=2, out=Path(tmp)
        )
        flight = cfg.flight()
        session = ManualSession(cfg)
        started = time.perf_counter()
        stats = session.run()
        wall = time.perf_counter() - started
    env = flight.make_env()  # the ceiling: the same frames of physics alone, nothing else
    action = np.array([0.0, 0.0, 0.0, 0.7], dtype=np.float32)  # cruise throttle
    started = time.perf_counter()
    flown = 0
    for episode in range(2):
        env.reset(seed=episode)
        done = False
        while not done:
            _, _, terminated, truncated, _ = env.step(action)
            done, flown = terminated or truncated, flown + 1
    ceiling = flown / flight.agent_hz / (time.perf_counter() - started)
    return Row(
        "synthetic_pilot_x_realtime",
        2 * seconds / wall,
        "x",
        300.0,
        detail=[
            f"synthetic pilot: {stats.frames} frames at 30 Hz in {wall:.1f} s, of which the "
            f"session's end {stats.closing_s:.1f} s (the dataset built, LeRobot's imports "
            f"waited for); the loop alone {2 * seconds / (wall - stats.closing_s):.0f}x, "
            f"the env alone on the same flights {ceiling:.0f}x "
            "(where a frame goes: docs/experiments/synthetic_profile.py)"
        ],
    )


def input_to_record(presses: int) -> Row:
    """p99 agent steps from a real X key event in a real window (Xvfb, xdotool) to the
    recorded action (``benchmarks.latency``); NaN, saying why, without Xvfb or xdotool."""
    import shutil

    from benchmarks.latency import on_own_display

    missing = [tool for tool in ("Xvfb", "xdotool") if shutil.which(tool) is None]
    if missing:
        detail = [f"input_to_record skipped: needs {', '.join(missing)} (apt-get install)"]
        return Row("input_to_record_p99_steps", math.nan, "steps", 1.0, False, detail)
    found = on_own_display(presses)
    ms, steps = np.array(found["ms"]), np.array(found["steps"])
    return Row(
        "input_to_record_p99_steps",
        float(np.percentile(steps, 99)),
        "steps",
        1.0,
        higher_is_better=False,
        detail=[
            f"input to record, {len(ms)} real key presses at 30 Hz (Xvfb + xdotool, its start-up "
            f"counted): p50 {np.median(ms):.1f} ms, p99 {np.percentile(ms, 99):.1f} ms; steps "
            f"p50 {np.median(steps):g}, max {steps.max()}; {len(found['missed'])} never "
            f"recorded, {found['late_frames']} late frames"
        ],
    )


def rows(quick: bool) -> list[Row]:
    return [
        manual_loop(5 if quick else 20),
        synthetic_pilot(10 if quick else 60),
        input_to_record(10 if quick else 60),
    ]
