"""The controls and state GUI, drawn every step in a pygame window (the paper's "State and
controls visualization"): the stick position, throttle and rudder, the selected state
variables with names and values, the task's target against the actual value, the episode
number, the time left and the recording status, and a help overlay of the keys."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from gymfg_il.manual.pfd import PrimaryFlightDisplay

BG, FG, DIM = (18, 22, 30), (225, 230, 240), (120, 130, 150)
ACCENT, RED, GREEN, AMBER = (90, 170, 255), (235, 80, 80), (90, 200, 120), (240, 180, 60)


@dataclass
class GuiFrame:
    """What one frame shows."""

    action: np.ndarray
    variables: dict[str, tuple[float, str]] = field(default_factory=dict)  # name -> (value, unit)
    target_name: str = ""
    target: float | None = None
    actual: float | None = None
    episode: int = 0
    time_left_s: float = 0.0
    status: str = "idle"  # recording, paused, idle, saving
    pilot: str = "human"  # who flies: human, controller, policy
    message: str = ""
    help_lines: list[str] = field(default_factory=list)
    show_help: bool = False
    view: np.ndarray | None = None  # the camera's frame (H, W, 3) uint8, beside the instruments


class ControlsGUI:
    """A pygame window (or an off-screen surface with ``SDL_VIDEODRIVER=dummy``)."""

    def __init__(self, size: tuple[int, int] = (900, 600), title: str = "GymFG-IL") -> None:
        import pygame

        self.pg = pygame
        pygame.display.init()
        pygame.font.init()
        self.size = size
        self.screen = pygame.display.set_mode(size)
        pygame.display.set_caption(title)
        self.font = pygame.font.Font(None, 24)
        self.small = pygame.font.Font(None, 20)
        self.big = pygame.font.Font(None, 40)
        self._cache: dict[tuple[str, tuple[int, int, int], int], Any] = {}
        self.pfd = PrimaryFlightDisplay(pygame, (self.small, self.big))

    def _text(
        self, text: str, pos: tuple[int, int], color: tuple[int, int, int] = FG, font: Any = None
    ) -> None:
        font = font or self.font
        key = (text, color, id(font))
        surf = self._cache.get(key)
        if surf is None:
            if len(self._cache) > 2000:
                self._cache.clear()
            surf = self._cache[key] = font.render(text, True, color)
        self.screen.blit(surf, pos)

    def draw(self, f: GuiFrame) -> None:
        pg, s = self.pg, self.screen
        s.fill(BG)
        # stick: aileron right, elevator positive (nose down, stick forward) drawn up
        box = pg.Rect(40, 60, 240, 240)
        pg.draw.rect(s, DIM, box, 1)
        pg.draw.line(s, DIM, box.midtop, box.midbottom)
        pg.draw.line(s, DIM, box.midleft, box.midright)
        a = f.action
        dot = (box.centerx + a[0] * box.width / 2, box.centery - a[1] * box.height / 2)
        pg.draw.circle(s, ACCENT, (int(dot[0]), int(dot[1])), 9)
        self._text("stick (aileron, elevator)", (40, 36), DIM, self.small)
        # rudder: horizontal bar under the stick
        rud = pg.Rect(40, 330, 240, 18)
        pg.draw.rect(s, DIM, rud, 1)
        x = rud.centerx + a[2] * rud.width / 2
        pg.draw.line(s, AMBER, (x, rud.top), (x, rud.bottom), 4)
        self._text(f"rudder {a[2]:+.2f}", (40, 352), DIM, self.small)
        # throttle: vertical bar
        thr = pg.Rect(300, 60, 26, 240)
        pg.draw.rect(s, DIM, thr, 1)
        h = int(a[3] * thr.height)
        pg.draw.rect(s, GREEN, (thr.left + 1, thr.bottom - h, thr.width - 2, h))
        self._text(f"throttle {a[3]:.2f}", (286, 306), DIM, self.small)
        self._text(f"aileron {a[0]:+.2f}   elevator {a[1]:+.2f}", (40, 380), FG, self.small)
        # status line
        color = {"recording": RED, "paused": AMBER, "saving": ACCENT}.get(f.status, DIM)
        label = "REC" if f.status == "recording" else f.status.upper()
        pg.draw.circle(s, color, (372, 30), 8)
        self._text(
            f"{label}   episode {f.episode}   {f.time_left_s:5.1f} s left   pilot: {f.pilot}",
            (388, 20),
            FG,
        )
        # target vs actual
        if f.target is not None and f.actual is not None:
            self._text(f.target_name, (372, 50), DIM, self.small)
            err = f.target - f.actual
            self._text(f"target {f.target:8.1f}", (372, 66), ACCENT, self.font)
            self._text(f"actual {f.actual:8.1f}", (560, 66), FG, self.font)
            self._text(f"error {err:+8.1f}", (740, 66), AMBER if abs(err) > 1 else GREEN, self.font)
        # the primary flight display, the target a magenta bug on its instrument
        values = {name: value for name, (value, _) in f.variables.items()}
        target_var = f.target_name.split(" ")[0] if f.target_name else None
        self.pfd.draw(s, pg.Rect(430, 100, 440, 290), values, target_var, f.target)
        # state variables under the stick: names aligned, values aligned
        y = 404
        for name, (value, unit) in f.variables.items():
            self._text(name, (40, y), DIM, self.small)
            self._text(f"{value:12.3f} {unit}", (200, y), FG, self.small)
            y += 18
        if f.view is not None:
            # the pilot's view, right of the instruments
            h, w = f.view.shape[:2]
            image = pg.image.frombuffer(np.ascontiguousarray(f.view).tobytes(), (w, h), "RGB")
            s.blit(image, (self.size[0] - w - 20, 100))
            pg.draw.rect(s, DIM, (self.size[0] - w - 21, 99, w + 2, h + 2), 1)
            self._text("pilot's view", (self.size[0] - w - 20, 76), DIM, self.small)
        if f.message:
            self._text(f.message, (40, self.size[1] - 34), AMBER)
        self._text("H: help", (self.size[0] - 80, self.size[1] - 30), DIM, self.small)
        if f.show_help and f.help_lines:
            panel = pg.Surface((self.size[0] - 80, len(f.help_lines) * 22 + 30), pg.SRCALPHA)
            panel.fill((0, 0, 0, 215))
            s.blit(panel, (40, 40))
            for i, line in enumerate(f.help_lines):
                self._text(line, (60, 55 + 22 * i), FG, self.small)
        pg.display.flip()

    def screenshot(self, path: Path) -> Path:
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        self.pg.image.save(self.screen, str(path))
        return path

    def close(self) -> None:
        self.pg.display.quit()
