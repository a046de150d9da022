"""A primary flight display, as pilots know it: an attitude indicator (sky over ground, a
pitch ladder, a bank scale, and an ILS's localizer and glide-slope scales when the task has
them), an airspeed tape on its left, an altitude tape and a vertical speed scale on its
right, a heading tape below and a slip ball under it. Every target of the task is a magenta
bug on the instrument that shows its variable (a bank or pitch bar on the attitude
indicator), as the display model (``display.readings``) places it.

A person can fly an altitude task from this; nobody can from a column of numbers.
"""

from __future__ import annotations

import math
from typing import Any

from gymfg_il.display.readings import Display
from gymfg_il.units import wrap_180

SKY, GROUND = (40, 110, 190), (125, 85, 45)
WHITE, YELLOW, MAGENTA = (235, 235, 235), (250, 210, 40), (235, 80, 235)
TAPE, EDGE = (35, 40, 50), (120, 130, 150)
PX_PER_DEG = 4.0  # attitude indicator: pitch scale
PX_PER_DOT = 20.0  # ILS scales
SLIP_PX_PER_DEG = 8.0


class PrimaryFlightDisplay:
    """Draws onto ``surface`` inside ``rect`` (a pygame Rect); ``fonts`` = (small, big)."""

    def __init__(self, pygame: Any, fonts: tuple[Any, Any]) -> None:
        self.pg = pygame
        self.small, self.big = fonts
        self._text_cache: dict[tuple[str, tuple[int, int, int]], Any] = {}

    def _label(self, text: str, color: tuple[int, int, int] = WHITE) -> Any:
        key = (text, color)
        surf = self._text_cache.get(key)
        if surf is None:
            if len(self._text_cache) > 4000:
                self._text_cache.clear()
            surf = self._text_cache[key] = self.small.render(text, True, color)
        return surf

    def draw(self, surface: Any, rect: Any, display: Display) -> set[str]:
        """Draw ``display``'s PFD readings; the names of the readings drawn."""
        pg = self.pg
        drawn: set[str] = set()
        values = {r.name: r.value for r in display.readings if r.role == "value"}
        drawn.update(values)

        def bugs(instrument: str) -> list[float]:
            found = display.on(instrument, "bug")
            drawn.update(r.name for r in found)
            return [r.value for r in found]

        ai = pg.Rect(0, 0, 200, 200)
        ai.center = (rect.centerx, rect.top + 110)
        self._attitude(surface, ai, values, bugs("pitch"), bugs("bank"))
        for needle in display.on("localizer", "needle") + display.on("glideslope", "needle"):
            self._ils(surface, ai, needle.instrument, needle.value)
            drawn.add(needle.name)
        speed = pg.Rect(ai.left - 70, ai.top, 60, ai.height)
        self._tape(surface, speed, values["airspeed_kts"], 10.0, 4.0, "kt", bugs("airspeed"))
        alt = pg.Rect(ai.right + 10, ai.top, 70, ai.height)
        self._tape(surface, alt, values["altitude_ft"], 100.0, 0.4, "ft", bugs("altitude"))
        self._vertical_speed(surface, pg.Rect(alt.right + 6, ai.top, 18, ai.height), values)
        heading = pg.Rect(ai.left, ai.bottom + 10, ai.width, 30)
        self._heading(surface, heading, values["heading_deg"], bugs("heading"))
        slip = pg.Rect(ai.centerx - 50, heading.bottom + 8, 100, 16)
        self._slip(surface, slip, values["beta_deg"], bugs("slip"))
        return drawn

    def _attitude(
        self,
        surface: Any,
        ai: Any,
        values: dict[str, float],
        pitch_bugs: list[float],
        bank_bugs: list[float],
    ) -> None:
        pg = self.pg
        roll, pitch = values.get("roll_deg", 0.0), values.get("pitch_deg", 0.0)
        size = int(ai.width * 1.6)
        ball = pg.Surface((size, size))
        horizon = size / 2 + pitch * PX_PER_DEG  # nose up: the horizon sinks
        ball.fill(SKY)
        pg.draw.rect(ball, GROUND, (0, int(horizon), size, size))
        pg.draw.line(ball, WHITE, (0, int(horizon)), (size, int(horizon)), 2)
        for deg in range(-30, 35, 5):  # the pitch ladder
            if deg == 0:
                continue
            y = horizon - deg * PX_PER_DEG
            half = 28 if deg % 10 == 0 else 14
            pg.draw.line(ball, WHITE, (size / 2 - half, y), (size / 2 + half, y), 1)
            if deg % 10 == 0:
                ball.blit(self._label(f"{abs(deg)}"), (size / 2 + half + 4, y - 7))
        for target in pitch_bugs:  # the target pitch: a magenta bar
            y = horizon - target * PX_PER_DEG
            pg.draw.line(ball, MAGENTA, (size / 2 - 40, y), (size / 2 + 40, y), 3)
        turned = pg.transform.rotate(ball, roll)  # bank right: the horizon turns left
        clip = surface.get_clip()
        surface.set_clip(ai)
        surface.blit(turned, turned.get_rect(center=ai.center))
        surface.set_clip(clip)
        pg.draw.rect(surface, EDGE, ai, 1)
        cx, cy = ai.center
        pg.draw.line(surface, YELLOW, (cx - 45, cy), (cx - 15, cy), 4)  # the aircraft
        pg.draw.line(surface, YELLOW, (cx + 15, cy), (cx + 45, cy), 4)
        pg.draw.circle(surface, YELLOW, (cx, cy), 3)
        radius = ai.width / 2 - 6
        for mark in (-60, -45, -30, -20, -10, 0, 10, 20, 30, 45, 60):  # the bank scale
            a = math.radians(mark - 90)
            inner = radius - (10 if mark % 30 == 0 else 5)
            pg.draw.line(
                surface, WHITE,
                (cx + inner * math.cos(a), cy + inner * math.sin(a)),
                (cx + radius * math.cos(a), cy + radius * math.sin(a)), 2,
            )  # fmt: skip
        pointer = math.radians(-roll - 90)
        tip = (cx + (radius - 12) * math.cos(pointer), cy + (radius - 12) * math.sin(pointer))
        pg.draw.circle(surface, YELLOW, (int(tip[0]), int(tip[1])), 4)
        for target in bank_bugs:  # the target bank on the scale
            a = math.radians(-target - 90)
            bug = (cx + (radius + 4) * math.cos(a), cy + (radius + 4) * math.sin(a))
            pg.draw.circle(surface, MAGENTA, (int(bug[0]), int(bug[1])), 5)

    def _tape(
        self,
        surface: Any,
        rect: Any,
        value: float,
        step: float,
        px_per_unit: float,
        unit: str,
        targets: list[float],
    ) -> None:
        """A vertical tape centred on ``value``, ticks every ``step``."""
        pg = self.pg
        pg.draw.rect(surface, TAPE, rect)
        clip = surface.get_clip()
        surface.set_clip(rect)
        first = math.floor((value - rect.height / 2 / px_per_unit) / step) * step
        tick = first
        while tick <= value + rect.height / 2 / px_per_unit:
            y = rect.centery - (tick - value) * px_per_unit
            pg.draw.line(surface, EDGE, (rect.right - 10, y), (rect.right, y), 1)
            surface.blit(self._label(f"{tick:.0f}"), (rect.left + 3, y - 7))
            tick += step
        for target in targets:
            y = rect.centery - (target - value) * px_per_unit
            y = max(rect.top + 4, min(rect.bottom - 4, y))  # pinned at the edge when far
            pg.draw.rect(surface, MAGENTA, (rect.right - 8, y - 4, 8, 8))
        surface.set_clip(clip)
        box = pg.Rect(rect.left, rect.centery - 12, rect.width, 24)
        pg.draw.rect(surface, (0, 0, 0), box)
        pg.draw.rect(surface, WHITE, box, 1)
        surface.blit(self._label(f"{value:.0f}"), (box.left + 4, box.top + 4))
        surface.blit(self._label(unit, EDGE), (rect.left, rect.bottom + 2))

    def _vertical_speed(self, surface: Any, rect: Any, values: dict[str, float]) -> None:
        """A scale of +-2,000 ft/min; the needle shows the climb rate."""
        pg = self.pg
        pg.draw.rect(surface, TAPE, rect)
        fpm = values.get("vertical_speed_fps", 0.0) * 60.0
        y = rect.centery - max(-1.0, min(1.0, fpm / 2000.0)) * rect.height / 2
        pg.draw.line(surface, EDGE, (rect.left, rect.centery), (rect.right, rect.centery), 1)
        pg.draw.line(surface, WHITE, (rect.left, y), (rect.right, y), 3)
        surface.blit(self._label(f"{fpm:+.0f}"), (rect.left - 10, rect.bottom + 2))

    def _heading(self, surface: Any, rect: Any, heading: float, targets: list[float]) -> None:
        pg = self.pg
        pg.draw.rect(surface, TAPE, rect)
        px_per_deg = 3.0
        clip = surface.get_clip()
        surface.set_clip(rect)
        first = math.floor((heading - 40) / 10) * 10
        for tick in range(int(first), int(heading + 45), 10):
            x = rect.centerx + (tick - heading) * px_per_deg
            pg.draw.line(surface, EDGE, (x, rect.top), (x, rect.top + 8), 1)
            surface.blit(self._label(f"{tick % 360:03d}"), (x - 12, rect.top + 10))
        for target in targets:
            off = wrap_180(target - heading)
            x = max(rect.left + 4, min(rect.right - 4, rect.centerx + off * px_per_deg))
            pg.draw.rect(surface, MAGENTA, (x - 4, rect.top, 8, 6))
        surface.set_clip(clip)
        pg.draw.line(surface, YELLOW, (rect.centerx, rect.top), (rect.centerx, rect.bottom), 2)

    def _ils(self, surface: Any, ai: Any, instrument: str, dots: float) -> None:
        """An ILS scale inside the attitude indicator: the glide slope on its right edge
        (the diamond above the centre: the path is above), the localizer along its bottom
        (the diamond left of the centre: the centre line is to the left); two dots each way,
        the diamond pinned at the end beyond them."""
        pg = self.pg
        shown = max(-2.5, min(2.5, dots)) * PX_PER_DOT
        cx, cy = ai.center
        if instrument == "glideslope":
            x = ai.right - 14
            for k in (-2, -1, 1, 2):
                pg.draw.circle(surface, WHITE, (x, int(cy - k * PX_PER_DOT)), 3, 1)
            pg.draw.line(surface, WHITE, (x - 6, cy), (x + 6, cy), 2)
            centre = (x, int(cy - shown))
        else:
            y = ai.bottom - 14
            for k in (-2, -1, 1, 2):
                pg.draw.circle(surface, WHITE, (int(cx + k * PX_PER_DOT), y), 3, 1)
            pg.draw.line(surface, WHITE, (cx, y - 6), (cx, y + 6), 2)
            centre = (int(cx - shown), y)
        x, y = centre
        diamond = [(x, y - 7), (x + 7, y), (x, y + 7), (x - 7, y)]
        pg.draw.polygon(surface, MAGENTA, diamond)

    def _slip(self, surface: Any, rect: Any, beta: float, targets: list[float]) -> None:
        """The slip ball: sideslip to the right moves it right; a target is a magenta tick."""
        pg = self.pg
        pg.draw.rect(surface, TAPE, rect, border_radius=8)
        cx, cy = rect.center
        for side in (-1, 1):
            x = cx + side * 9
            pg.draw.line(surface, EDGE, (x, rect.top), (x, rect.bottom), 1)
        half = rect.width / 2 - 8
        for target in targets:
            x = cx + max(-half, min(half, target * SLIP_PX_PER_DEG))
            pg.draw.line(surface, MAGENTA, (x, rect.top - 4), (x, rect.bottom + 4), 3)
        x = cx + max(-half, min(half, beta * SLIP_PX_PER_DEG))
        pg.draw.circle(surface, WHITE, (int(x), cy), 6)
