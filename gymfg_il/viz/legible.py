"""The camera's legible mode: what a task needs seen, drawn no smaller than a person can see it
in a small window (``Camera(..., legible=True)``, the manual collector's pilot's view).

At its true size a runway 4 NM out is one pixel of a 320-pixel, 90-degree view, and a wing seen
edge-on is no pixel at all. This mode keeps every landmark where it is and draws it so that it
reads; dataset images use the default mode, which draws true sizes only.

- **runway**: magnified on the screen about its threshold: along the horizon until the
  threshold is at least ``RUNWAY_MIN_PX`` wide, up and down as much but never so far that its
  far end nears the horizon. The threshold stays where it is, so its angle below the horizon
  still reads the glide path; a far runway widens more than it grows tall, which steepens the
  slant its centre line takes when the aircraft is off the course (the cue, exaggerated).
  Drawn with a white edge outline, green threshold lights, and approach lights: a row along
  the extended centre line to ``APPROACH_LIGHTS_FT`` before the threshold with a crossbar at
  1,000 ft, each light ``LIGHT_PX`` square. Its painted markings show at true size only.
- **gate**: its frame as lines at least ``LINE_PX`` thick; a highlighted gate (the next one)
  in ``HIGHLIGHT`` at least ``HIGHLIGHT_LINE_PX`` thick.
- **aircraft**: below ``AIRCRAFT_MIN_PX`` of span it is magnified to the geometric mean of its
  span and that size (so it still grows as it nears: size is how a wingman judges distance), and
  its wing and fin are stroked in a dark line at least ``LINE_PX`` thick, so its bank shows even
  when the wing is seen edge-on.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from gymfg_il.tasks.scenery import Landmark
from gymfg_il.viz.shapes import COLOURS, MARKING, NEAR_FT, quads, rotation

RUNWAY_MIN_PX = 16.0  # the threshold's width, at the least
HORIZON_SHARE = 0.8  # a magnified runway's far end stays this share of the way to the horizon
APPROACH_LIGHTS_FT = 2400.0
AIRCRAFT_MIN_PX = 48.0  # span below which an aircraft is magnified
AIRCRAFT_MAX_ZOOM = 8.0
LINE_PX = 2.0
HIGHLIGHT_LINE_PX = 3.0
LIGHT_PX = 2

LIGHT = (255, 246, 150)  # approach lights
THRESHOLD = (60, 235, 100)  # threshold lights
EDGE = MARKING  # runway outline
RUNWAY, GATE, AIRCRAFT = COLOURS["runway"], COLOURS["gate"], COLOURS["aircraft"]
AIRCRAFT_SHADE = (202, 35, 35)  # every other face, as the default mode shades it
HIGHLIGHT = (255, 40, 230)  # the next gate: magenta, the colour of the active leg on a nav display
WING = (110, 0, 0)

Rgb = tuple[int, int, int]
Point = tuple[float, float, float]  # item-local ft: forward, right, down


class Lens(NamedTuple):
    """A pinhole camera's focal length and image centre, in pixels."""

    focal: float
    cx: float
    cy: float

    def project(self, cam: np.ndarray) -> np.ndarray:
        """Pixels (n, 2: x, y) of camera points (n, 3: forward, right, down; forward > 0)."""
        return np.stack(
            [
                self.cx + self.focal * cam[:, 1] / cam[:, 0],
                self.cy + self.focal * cam[:, 2] / cam[:, 0],
            ],
            axis=1,
        )


class Paint(NamedTuple):
    """One thing to paint: a convex polygon (``pixels``: its vertices, x and y), or (``light_px``
    > 0) square lights that wide centred on each of ``pixels``. ``order`` sorts far to near, as
    the camera's default landmarks."""

    order: tuple[float, int, float]
    pixels: np.ndarray
    colour: Rgb
    light_px: int = 0


class _Placed:
    """A landmark placed before the camera: item-local points (forward, right, down ft) to
    camera points and pixels, magnified on the screen about ``anchor`` by ``zoom`` (a 2 x 2
    map of pixel offsets; None: true size)."""

    def __init__(
        self, item: Landmark, offset: np.ndarray, world_to_cam: np.ndarray, lens: Lens
    ) -> None:
        self.offset, self.world_to_cam, self.lens = offset, world_to_cam, lens
        self.turn = rotation(item.roll_deg, item.pitch_deg, item.heading_deg)
        self.depth = float((world_to_cam @ offset)[0])
        self.zoom: np.ndarray | None = None
        self.anchor = np.zeros(2)

    def cam(self, local: np.ndarray) -> np.ndarray:
        return (
            np.asarray(local, dtype=np.float64) @ self.turn.T + self.offset
        ) @ self.world_to_cam.T

    def magnify(self, along: float, across: float, anchor_local: np.ndarray) -> None:
        """Magnify what follows about where ``anchor_local`` is seen (if it is in front):
        ``along`` the horizon's direction on the screen, ``across`` it (up and down)."""
        anchor = self.cam(anchor_local[None, :])
        if max(along, across) <= 1.0 or anchor[0, 0] < NEAR_FT:
            return
        # the horizon's normal on the screen: where the world's down points (x right, y down)
        down = self.world_to_cam[1:, 2]
        size = float(np.hypot(*down))
        v = down / size if size > 1e-9 else np.array([0.0, 1.0])
        h = np.array([v[1], -v[0]])
        self.zoom = along * np.outer(h, h) + across * np.outer(v, v)
        self.anchor = self.lens.project(anchor)[0]

    def pixels(self, cam: np.ndarray) -> np.ndarray:
        px = self.lens.project(cam)
        return px if self.zoom is None else self.anchor + (px - self.anchor) @ self.zoom.T

    def polygon(self, world_quad: np.ndarray, layer: int, colour: Rgb) -> list[Paint]:
        """A quad already turned to north-east-down (``shapes.quads``), cut at the near plane
        (the default mode drops it whole: a runway under the aircraft would vanish)."""
        cam = _in_front((world_quad + self.offset) @ self.world_to_cam.T)
        if len(cam) < 3:
            return []
        px = self.pixels(cam)
        if np.all(np.ptp(px, axis=0) < 1.0):  # under a pixel: the outlines show it
            return []
        order = (-self.depth, layer, -float(cam[:, 0].mean()))
        return [Paint(order, px, colour)]

    def stroke(self, a: Point, b: Point, width_px: float, layer: int, colour: Rgb) -> list[Paint]:
        """A line from ``a`` to ``b`` (item-local ft), ``width_px`` wide, cut at the near plane."""
        cam = self.cam(np.array([a, b]))
        f0, f1 = cam[0, 0], cam[1, 0]
        if f0 < NEAR_FT and f1 < NEAR_FT:
            return []
        if f0 < NEAR_FT or f1 < NEAR_FT:  # keep the part in front
            t = (NEAR_FT - f0) / (f1 - f0)
            cut = cam[0] + t * (cam[1] - cam[0])
            cam = np.array([cut, cam[1]]) if f0 < NEAR_FT else np.array([cam[0], cut])
        p0, p1 = self.pixels(cam)
        along = p1 - p0
        length = float(np.hypot(*along))
        half = width_px / 2.0
        u = along / length if length > 1e-9 else np.array([1.0, 0.0])
        n = np.array([-u[1], u[0]]) * half
        u = u * half  # square caps: corners of joined lines meet
        quad = np.array([p0 - u + n, p1 + u + n, p1 + u - n, p0 - u - n])
        order = (-self.depth, layer, -float(cam[:, 0].mean()))
        return [Paint(order, quad, colour)]

    def lights(self, at: np.ndarray, colour: Rgb) -> list[Paint]:
        """Lights of one colour at ``at`` (n, 3 item-local ft), those in front."""
        cam = self.cam(at)
        cam = cam[cam[:, 0] >= NEAR_FT]
        if not len(cam):
            return []
        return [Paint((-self.depth, 2, 0.0), self.pixels(cam), colour, LIGHT_PX)]


def _in_front(cam: np.ndarray) -> np.ndarray:
    """The part of the convex polygon ``cam`` (n, 3) at least ``NEAR_FT`` ahead."""
    ahead = cam[:, 0] >= NEAR_FT
    if ahead.all() or not ahead.any():
        return cam if ahead.all() else cam[:0]
    kept = []
    for a, b, a_in, b_in in zip(cam, np.roll(cam, -1, 0), ahead, np.roll(ahead, -1), strict=True):
        if a_in:
            kept.append(a)
        if a_in != b_in:
            kept.append(a + (NEAR_FT - a[0]) / (b[0] - a[0]) * (b - a))
    return np.array(kept)


def paints(item: Landmark, offset: np.ndarray, world_to_cam: np.ndarray, lens: Lens) -> list[Paint]:
    """What the legible mode paints for ``item``, ``offset`` (north, east, down ft) from the
    eye, seen through ``world_to_cam`` and ``lens``."""
    placed = _Placed(item, offset, world_to_cam, lens)
    if item.kind == "runway":
        return _runway(item, placed)
    if item.kind == "gate":
        return _gate(item, placed)
    return _aircraft(item, placed)


def _runway(item: Landmark, at: _Placed) -> list[Paint]:
    w, length = item.width_ft, item.length_ft
    distance = float(np.linalg.norm(at.offset))
    zoom = RUNWAY_MIN_PX * distance / (at.lens.focal * w) if w > 0 else 1.0
    # the far end sits ``share`` of the way from the threshold to the horizon (ground points
    # on one line: the share is 1 - near distance / far distance); magnified, it must not reach it
    far = at.offset + at.turn @ np.array([length, 0.0, 0.0])
    near_h, far_h = math.hypot(at.offset[0], at.offset[1]), math.hypot(far[0], far[1])
    share = 1.0 - near_h / far_h if far_h > 0 else 0.0
    across = min(zoom, HORIZON_SHARE / share) if at.offset[2] > 0 and share > 0 else zoom
    at.magnify(zoom, max(1.0, across), np.zeros(3))
    shapes = quads(item)
    found = at.polygon(shapes[0][0], 0, RUNWAY)
    if at.zoom is None:  # its painted markings, at true size only (magnified, they blot it)
        for quad, layer in shapes[1:]:
            found += at.polygon(quad, layer, MARKING)
    half = w / 2
    corners = [(0.0, -half, 0.0), (length, -half, 0.0), (length, half, 0.0), (0.0, half, 0.0)]
    for a, b in zip(corners, corners[1:] + corners[:1], strict=True):
        found += at.stroke(a, b, LINE_PX, 1, EDGE)
    found += at.stroke((0.0, -w / 2, 0.0), (0.0, w / 2, 0.0), LINE_PX, 2, THRESHOLD)
    return found + at.lights(_approach_lights(w), LIGHT)


def _approach_lights(width_ft: float) -> np.ndarray:
    """A row along the extended centre line every 100 ft from 200 ft before the threshold,
    and a crossbar at 1,000 ft (runway-local ft)."""
    row = -np.arange(200.0, APPROACH_LIGHTS_FT + 1.0, 100.0)
    bar = np.linspace(-0.35 * width_ft, 0.35 * width_ft, 7)
    along = np.concatenate([row, np.full(len(bar), -1000.0)])
    across = np.concatenate([np.zeros(len(row)), bar])
    return np.stack([along, across, np.zeros(len(along))], axis=1)


def _gate(item: Landmark, at: _Placed) -> list[Paint]:
    bar = max(item.width_ft, item.length_ft) * 0.06
    hw, hh = item.width_ft / 2 - bar / 2, item.length_ft / 2 - bar / 2
    true_px = at.lens.focal * bar / max(at.depth, NEAR_FT)
    least, colour = (HIGHLIGHT_LINE_PX, HIGHLIGHT) if item.highlight else (LINE_PX, GATE)
    corners = [(0.0, -hw, -hh), (0.0, hw, -hh), (0.0, hw, hh), (0.0, -hw, hh)]
    found: list[Paint] = []
    for a, b in zip(corners, corners[1:] + corners[:1], strict=True):
        found += at.stroke(a, b, max(true_px, least), 0, colour)
    return found


def _aircraft(item: Landmark, at: _Placed) -> list[Paint]:
    span, length = item.width_ft, item.length_ft
    distance = float(np.linalg.norm(at.offset))
    true_px = at.lens.focal * span / max(distance, NEAR_FT)
    if 0 < true_px < AIRCRAFT_MIN_PX:
        zoom = min(AIRCRAFT_MAX_ZOOM, math.sqrt(AIRCRAFT_MIN_PX / true_px))
        at.magnify(zoom, zoom, np.zeros(3))
    found: list[Paint] = []
    for k, (quad, _) in enumerate(quads(item)):
        found += at.polygon(quad, 0, AIRCRAFT if k % 2 == 0 else AIRCRAFT_SHADE)
    chord = 0.15 * length
    found += at.stroke((chord, -span / 2, 0.0), (chord, span / 2, 0.0), LINE_PX, 1, WING)
    found += at.stroke(
        (-0.34 * length, 0.0, 0.0), (-0.39 * length, 0.0, -0.2 * length), LINE_PX, 1, WING
    )
    return found
