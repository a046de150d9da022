"""The controls and state GUI, drawn every step in a pygame window (the paper's "State and
controls visualization"): the stick position, throttle and rudder, the selected state
variables with names and values, the primary flight display with every target of the task as
a bug, the task's guidance panel, the briefing before an episode and the debrief after it,
the episode number, the time left and the recording status, and a help overlay of the keys.

What the instruments and the panel show is the display model (``display.readings``);
``ControlsGUI.drawn`` names every reading of the last frame that was drawn."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from gymfg_il.cockpit.windows.pfd import MAGENTA, PrimaryFlightDisplay
from gymfg_il.display.readings import Display, Reading
from gymfg_il.units import FT_PER_NM

BG, FG, DIM = (18, 22, 30), (225, 230, 240), (120, 130, 150)
ACCENT, RED, GREEN, AMBER = (90, 170, 255), (235, 80, 80), (90, 200, 120), (240, 180, 60)


@dataclass
class GuiFrame:
    """What one frame shows."""

    action: np.ndarray
    trim: np.ndarray | None = None  # the surfaces' neutral (aileron, elevator, rudder)
    variables: dict[str, tuple[float, str]] = field(default_factory=dict)  # name -> (value, unit)
    display: Display | None = None  # the instruments' and the panel's readings
    notes: list[str] = field(default_factory=list)  # the briefing, or the debrief
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

    def __init__(self, size: tuple[int, int] = (900, 700), title: str = "GymFG-IL") -> None:
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
        self.drawn: set[str] = set()  # the readings of the last frame that were drawn

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
        """Draw one frame and show it."""
        self.screen.fill(BG)
        self._controls(f.action, f.trim)
        self._status(f)
        # the primary flight display, every target a magenta bug on its instrument, and
        # the task's guidance below it
        self.drawn = set()
        if f.display is not None:
            self.drawn |= self.pfd.draw(self.screen, self.pg.Rect(430, 50, 440, 350), f.display)
            self._panel(f.display, self.pg.Rect(372, 416, 520, 170))
        self._words(f)
        if f.view is not None:
            self._view(f.view)
        self._overlay(f)
        self.pg.display.flip()

    def _controls(self, a: np.ndarray, trim: np.ndarray | None) -> None:
        """The stick (aileron right, elevator positive: nose down, stick forward, drawn up),
        the rudder bar under it, the trim's ticks on both and the throttle's bar."""
        pg, s = self.pg, self.screen
        box = pg.Rect(40, 60, 240, 240)
        pg.draw.rect(s, DIM, box, 1)
        pg.draw.line(s, DIM, box.midtop, box.midbottom)
        pg.draw.line(s, DIM, box.midleft, box.midright)
        dot = (box.centerx + a[0] * box.width / 2, box.centery - a[1] * box.height / 2)
        pg.draw.circle(s, ACCENT, (int(dot[0]), int(dot[1])), 9)
        if trim is not None:  # the trim: ticks on the box's left edge and the rudder bar
            ty = int(box.centery - trim[1] * box.height / 2)
            pg.draw.line(s, AMBER, (box.left - 10, ty), (box.left + 6, ty), 3)
            tx = int(40 + 120 + trim[2] * 120)
            pg.draw.line(s, AMBER, (tx, 348), (tx, 356), 3)
        self._text("stick (aileron, elevator)", (40, 36), DIM, self.small)
        rud = pg.Rect(40, 330, 240, 18)
        pg.draw.rect(s, DIM, rud, 1)
        x = rud.centerx + a[2] * rud.width / 2
        pg.draw.line(s, AMBER, (x, rud.top), (x, rud.bottom), 4)
        rudder = f"rudder {a[2]:+.2f}"
        if trim is not None:
            rudder += f"   trim: elevator {trim[1]:+.2f}  rudder {trim[2]:+.2f}"
        self._text(rudder, (40, 358), DIM, self.small)
        thr = pg.Rect(300, 60, 26, 240)
        pg.draw.rect(s, DIM, thr, 1)
        h = int(a[3] * thr.height)
        pg.draw.rect(s, GREEN, (thr.left + 1, thr.bottom - h, thr.width - 2, h))
        self._text(f"throttle {a[3]:.2f}", (286, 306), DIM, self.small)
        self._text(f"aileron {a[0]:+.2f}   elevator {a[1]:+.2f}", (40, 380), FG, self.small)

    def _status(self, f: GuiFrame) -> None:
        """The status line: recording or not, the episode, the time left, who flies."""
        color = {"recording": RED, "paused": AMBER, "saving": ACCENT}.get(f.status, DIM)
        label = "REC" if f.status == "recording" else f.status.upper()
        self.pg.draw.circle(self.screen, color, (372, 30), 8)
        self._text(
            f"{label}   episode {f.episode}   {f.time_left_s:5.1f} s left   pilot: {f.pilot}",
            (388, 20),
            FG,
        )

    def _words(self, f: GuiFrame) -> None:
        """The briefing or debrief at the bottom, and the state variables under the stick
        (names aligned, values aligned)."""
        y = self.size[1] - 100
        for line in f.notes[:5]:
            color = GREEN if line.startswith("SUCCESS") else RED if line.startswith("FAIL") else FG
            self._text(line, (40, y), color, self.small)
            y += 19
        y = 404
        for name, (value, unit) in f.variables.items():
            self._text(name, (40, y), DIM, self.small)
            self._text(f"{value:12.3f} {unit}", (200, y), FG, self.small)
            y += 18

    def _view(self, view: np.ndarray) -> None:
        """The pilot's view, right of the instruments."""
        pg, s = self.pg, self.screen
        h, w = view.shape[:2]
        image = pg.image.frombuffer(np.ascontiguousarray(view).tobytes(), (w, h), "RGB")
        s.blit(image, (self.size[0] - w - 20, 70))
        pg.draw.rect(s, DIM, (self.size[0] - w - 21, 69, w + 2, h + 2), 1)
        self._text("pilot's view", (self.size[0] - w - 20, 48), DIM, self.small)

    def _overlay(self, f: GuiFrame) -> None:
        """The message line, the help hint and, when asked, the help over everything."""
        if f.message:
            self._text(f.message, (40, self.size[1] - 128), AMBER)
        self._text("H: help", (self.size[0] - 80, self.size[1] - 30), DIM, self.small)
        if f.show_help and f.help_lines:
            panel = self.pg.Surface(
                (self.size[0] - 80, len(f.help_lines) * 22 + 30), self.pg.SRCALPHA
            )
            panel.fill((0, 0, 0, 215))
            self.screen.blit(panel, (40, 40))
            for i, line in enumerate(f.help_lines):
                self._text(line, (60, 55 + 22 * i), FG, self.small)

    def _panel(self, display: Display, rect: Any) -> None:
        """The task's targets and guidance in words, and the formation slot's diagram."""
        shown = [r for r in display.readings if r.role in ("bug", "guidance")]
        y = rect.top
        for reading in shown[:8]:
            self._text(reading.label, (rect.left, y), DIM, self.small)
            self._text(
                spoken(reading),
                (rect.left + 230, y),
                MAGENTA if reading.role == "bug" else FG,
                self.small,
            )
            self.drawn.add(reading.name)
            y += 20
        slot = {r.name: r.value for r in display.on("slot")}
        if slot:
            self._slot(slot, self.pg.Rect(rect.right - 130, rect.top, 120, 140))

    def _slot(self, slot: dict[str, float], box: Any) -> None:
        """The slot from above (the aircraft a dot, the slot the square; up is ahead) and its
        height on a bar beside it."""
        pg, s = self.pg, self.screen
        pg.draw.rect(s, DIM, box, 1)
        scale = 0.25  # px per ft
        cx, cy = box.center
        pg.draw.rect(s, MAGENTA, (cx - 6, cy - 6, 12, 12), 2)
        x = cx + max(-55.0, min(55.0, slot.get("right_of_slot_ft", 0.0) * scale))
        y = cy + max(-65.0, min(65.0, slot.get("behind_slot_ft", 0.0) * scale))
        pg.draw.circle(s, ACCENT, (int(x), int(y)), 5)
        bar = pg.Rect(box.right + 4, box.top, 6, box.height)
        pg.draw.rect(s, DIM, bar, 1)
        below = max(-65.0, min(65.0, slot.get("below_slot_ft", 0.0) * scale))
        pg.draw.line(s, MAGENTA, (bar.left - 2, bar.centery), (bar.right + 2, bar.centery), 2)
        pg.draw.circle(s, ACCENT, (bar.centerx, int(bar.centery + below)), 4)

    def screenshot(self, path: Path) -> Path:
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        self.pg.image.save(self.screen, str(path))
        return path

    def close(self) -> None:
        self.pg.display.quit()


# how a signed reading is said: (word for positive, word for negative)
_SIDES = {
    "turn_remaining_deg": ("right", "left"),
    "next_turn_deg": ("right", "left"),
    "right_of_slot_ft": ("right", "left"),
    "behind_slot_ft": ("behind", "ahead"),
    "below_slot_ft": ("below", "above"),
    "behind_slot_rate_fps": ("falling back", "closing"),
    "centerline_offset_ft": ("right", "left"),
    "glidepath_error_ft": ("below", "above"),
}
_HEADINGS = ("heading", "bearing", "course")


def spoken(reading: Reading) -> str:
    """A reading as a pilot says it: headings in three digits, distances in NM beyond a mile,
    signed offsets with their direction."""
    value, unit, name = reading.value, reading.unit, reading.name
    if name in _SIDES:
        positive, negative = _SIDES[name]
        return f"{abs(value):,.0f} {unit} {positive if value >= 0 else negative}"
    if unit == "deg" and any(word in name for word in _HEADINGS):
        return f"{value % 360:03.0f}"
    if unit == "ft" and "distance" in name:
        return f"{value / FT_PER_NM:.1f} NM" if abs(value) >= FT_PER_NM else f"{value:,.0f} ft"
    if unit == "1":
        return f"{value:.0f}"
    return f"{value:,.1f} {unit}" if abs(value) < 100 else f"{value:,.0f} {unit}"
