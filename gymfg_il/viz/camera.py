"""A headless camera: what a pilot sees out of the front window, drawn from the state alone.

No display, no GPU, no OpenGL context: every pixel's ray is turned by the aircraft's attitude
(numpy, float32), rays that point down meet a flat ground at the terrain height under the
aircraft, and the ground is a two-scale checkerboard fixed to latitude and longitude (so
motion and height read) fading into haze with distance; rays that point up see a sky graded
from the horizon to the zenith. Landmarks (``tasks.scenery``: runways, gates, other
aircraft) are projected and filled as convex polygons, far to near.

Why not OpenGL: this renderer needs no system library and is bit-for-bit deterministic (the
same state gives the same frame, so datasets and tests reproduce); how its speed compares
with an offscreen moderngl context is measured by ``benchmarks/camera.py`` (docs/results/vision.md).

Views: ``front`` (the pilot's eye, 90 deg horizontal field of view, rolled and pitched with
the aircraft) and ``chase`` (behind and above, turned with the heading and pitch but not the
roll, with the aircraft drawn, so its bank shows).

Landmarks are drawn at their true size (``viz.shapes``); a window a person flies by asks for
the legible mode (``legible=True``, ``viz.legible``), which draws what a task needs seen no
smaller than a person can see it: a runway with its lights from miles out, the next gate
highlighted, another aircraft's bank.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from gymfg_il.errors import ConfigError
from gymfg_il.sim.properties import INDEX
from gymfg_il.tasks.scenery import Landmark
from gymfg_il.units import FT_PER_DEG, wrap_180
from gymfg_il.viz import legible as _legible
from gymfg_il.viz.shapes import COLOURS, MARKING, NEAR_FT, quads, rotation

__all__ = ["VIEWS", "Camera", "rotation"]

VIEWS = ("front", "chase")
_SKY_HORIZON = np.array([200, 222, 240], dtype=np.float32)
_SKY_ZENITH = np.array([60, 110, 190], dtype=np.float32)
_HAZE = np.array([190, 205, 215], dtype=np.float32)
_GROUND = np.array([[96, 128, 64], [120, 148, 78], [110, 112, 70], [136, 134, 88]], np.float32)
_HAZE_LEVELS, _SKY_LEVELS = 64, 32
_HAZE_SPAN_FT = 120000.0  # ground farther than this is all haze
_HAZE_FT = 30000.0  # distance at which the ground is 63 % haze
_CELL_FT = 500.0  # the small checker square; fields are 8 x 8 of them


def _palette() -> np.ndarray:
    """Every colour a background pixel can take: 4 ground colours x haze levels, then the
    sky's elevation bands."""
    distance = (np.arange(_HAZE_LEVELS) + 0.5) * (_HAZE_SPAN_FT / _HAZE_LEVELS)
    fog = np.exp(-distance / _HAZE_FT)[None, :, None]
    ground = _GROUND[:, None, :] * fog + _HAZE * (1.0 - fog)
    up = ((np.arange(_SKY_LEVELS) + 0.5) / _SKY_LEVELS)[:, None]
    sky = _SKY_HORIZON + (_SKY_ZENITH - _SKY_HORIZON) * np.sqrt(up)
    table = np.concatenate([ground.reshape(-1, 3), sky])
    return np.round(table).astype(np.uint8)


_PALETTE = _palette()
# the same colours as one uint32 (RGBA bytes) each: frames gather 4-byte words, not rows of
# 3 bytes
_PALETTE_RGBA = np.concatenate([_PALETTE, np.full((len(_PALETTE), 1), 255, np.uint8)], 1)
_PALETTE_RGBA = _PALETTE_RGBA.view(np.uint32).ravel()
_CHASE_FT = (90.0, 0.0, -30.0)  # camera behind, right, below (negative: above) the aircraft


class Camera:
    """Render frames (height, width, 3) uint8 RGB from catalogue-ordered states.

    Args:
        width, height: frame size in pixels.
        view: ``front`` or ``chase``.
        fov_deg: horizontal field of view (default 90 deg in front, 60 deg for the chase).
        legible: draw landmarks for a person's eyes (``viz.legible``: a runway seen from
            miles out, the highlighted next gate, another aircraft's bank) instead of at
            their true size. Off (the default) for dataset images, which it would change.
    """

    def __init__(
        self,
        width: int = 128,
        height: int = 128,
        view: str = "front",
        fov_deg: float | None = None,
        *,
        legible: bool = False,
    ) -> None:
        fov_deg = fov_deg if fov_deg is not None else (90.0 if view == "front" else 60.0)
        if view not in VIEWS:
            raise ConfigError(f"camera view {view!r} is not one of {VIEWS}")
        if not (8 <= width <= 4096 and 8 <= height <= 4096):
            raise ConfigError(f"camera size {width}x{height}: each side must be 8-4096 pixels")
        if not 10.0 <= fov_deg <= 150.0:
            raise ConfigError(f"fov_deg={fov_deg}: give a field of view of 10-150 degrees")
        self.width, self.height, self.view, self.legible = width, height, view, legible
        self.focal = (width / 2.0) / math.tan(math.radians(fov_deg) / 2.0)
        self.lens = _legible.Lens(self.focal, width / 2.0, height / 2.0)
        u = (np.arange(width, dtype=np.float32) + 0.5 - width / 2.0) / self.focal
        v = (np.arange(height, dtype=np.float32) + 0.5 - height / 2.0) / self.focal
        self._right, self._down = (a.ravel() for a in np.meshgrid(u, v))
        n = width * height
        self._buf = {k: np.empty(n, np.float32) for k in ("n", "e", "d", "t", "a", "b")}
        # the sky band of a ray is its elevation (sin) in bands: -down / |ray| (rays turn
        # without changing length)
        norm = np.sqrt(1.0 + self._right**2 + self._down**2)
        self._sky_scale = (-_SKY_LEVELS / norm).astype(np.float32)
        self._rows, self._cols = np.mgrid[0:height, 0:width].astype(np.float32) + 0.5

    def frame(self, state: np.ndarray, landmarks: Sequence[Landmark] = ()) -> np.ndarray:
        """The frame seen from ``state`` (a catalogue-ordered state vector)."""
        roll, pitch, heading = (
            float(state[INDEX[k]]) for k in ("roll_deg", "pitch_deg", "heading_deg")
        )
        alt = float(state[INDEX["altitude_ft"]])
        agl = float(state[INDEX["altitude_agl_ft"]])
        lat, lon = float(state[INDEX["lat_deg"]]), float(state[INDEX["lon_deg"]])
        cos_lat = math.cos(math.radians(lat))
        eye = np.zeros(3)  # camera position (north, east, down) from the aircraft, in ft
        if self.view == "front":
            rot = rotation(roll, pitch, heading)
        else:
            rot = rotation(0.0, pitch, heading)
            eye = rot @ np.array([-_CHASE_FT[0], _CHASE_FT[1], _CHASE_FT[2]])
        image = self._background(
            rot, lat * FT_PER_DEG + eye[0], lon * FT_PER_DEG * cos_lat + eye[1], agl - eye[2]
        )
        items = list(landmarks)
        if self.view == "chase":
            items.append(Landmark("aircraft", lat, lon, alt, heading, roll, pitch))
        if items:
            self._draw(image, rot, (lat, lon, alt), eye, cos_lat, items)
        return image

    # -- sky and ground ------------------------------------------------------------------
    def _background(self, rot: np.ndarray, north: float, east: float, height: float) -> np.ndarray:
        """Sky and ground as one palette index per pixel, then one lookup: ground pixels index
        (checker colour, haze level), sky pixels the elevation band."""
        b = self._buf
        dirs = []
        for row, key in zip(rot, ("n", "e", "d"), strict=True):
            out = np.multiply(self._right, np.float32(row[1]), out=b[key])
            out += np.float32(row[0])
            out += np.multiply(self._down, np.float32(row[2]), out=b["a"])
            dirs.append(out)
        dn_, de_, dd_ = dirs
        ground = dd_ > 1e-4
        # distance along each ray to the ground plane ``height`` ft below the eye (the sky's
        # rays count as nearly level: their ground colour is replaced below)
        t = np.maximum(dd_, np.float32(1e-4), out=b["t"])
        np.divide(np.float32(max(height, 1.0)), t, out=t)
        # checker squares, counted from an origin that keeps the numbers small and positive
        span = 8.0 * _CELL_FT * 64.0
        gn = np.multiply(t, dn_, out=b["a"])
        gn += np.float32(north % span + span)
        ge = np.multiply(t, de_, out=b["b"])
        ge += np.float32(east % span + span)
        gn *= np.float32(1.0 / _CELL_FT)
        ge *= np.float32(1.0 / _CELL_FT)
        cn = gn.astype(np.int32)
        ce = ge.astype(np.int32)
        colour = (cn + ce) & 1
        colour += (((cn >> 3) + (ce >> 3)) & 1) << 1
        t *= np.float32(_HAZE_LEVELS / _HAZE_SPAN_FT)
        np.minimum(t, np.float32(_HAZE_LEVELS - 1), out=t)
        index = colour * _HAZE_LEVELS + t.astype(np.int32)
        # sky: the elevation of the ray, in bands
        up = np.multiply(dd_, self._sky_scale, out=b["a"])
        np.clip(up, 0.0, np.float32(_SKY_LEVELS - 1), out=up)
        sky = up.astype(np.int32)
        sky += 4 * _HAZE_LEVELS
        np.copyto(index, sky, where=~ground)
        rgba = _PALETTE_RGBA[index].view(np.uint8).reshape(self.height, self.width, 4)
        return np.ascontiguousarray(rgba[..., :3])

    # -- landmarks -----------------------------------------------------------------------
    def _draw(
        self,
        image: np.ndarray,
        rot: np.ndarray,
        own: tuple[float, float, float],
        eye: np.ndarray,
        cos_lat: float,
        items: list[Landmark],
    ) -> None:
        # (item's distance, layer, quad's distance) orders the painting: far items first, an
        # item's markings over its surface, its nearer faces over its farther ones
        polygons: list[tuple[tuple[float, int, float], np.ndarray, tuple[int, ...]]] = []
        paints: list[_legible.Paint] = []
        world_to_cam = rot.T
        for item in items:
            offset = (
                np.array(
                    [
                        (item.lat_deg - own[0]) * FT_PER_DEG,
                        wrap_180(item.lon_deg - own[1]) * FT_PER_DEG * cos_lat,
                        own[2] - item.alt_ft,
                    ]
                )
                - eye
            )
            if self.legible:
                paints += _legible.paints(item, offset, world_to_cam, self.lens)
                continue
            colour = COLOURS.get(item.kind, (255, 0, 255))
            depth = float((offset @ world_to_cam.T)[0])
            for k, (quad, layer) in enumerate(quads(item)):
                cam = (quad + offset) @ world_to_cam.T  # (forward, right, down)
                if np.any(cam[:, 0] < NEAR_FT):
                    continue
                px = np.stack(
                    [
                        self.width / 2.0 + self.focal * cam[:, 1] / cam[:, 0],
                        self.height / 2.0 + self.focal * cam[:, 2] / cam[:, 0],
                    ],
                    axis=1,
                )
                tint = MARKING if layer else tuple(int(c * (1.0 - 0.12 * (k % 2))) for c in colour)
                polygons.append(((-depth, layer, -float(cam[:, 0].mean())), px, tint))
        for _, px, tint in sorted(polygons, key=lambda p: p[0]):
            self._fill(image, px, tint)  # type: ignore[arg-type]
        for paint in sorted(paints, key=lambda p: p.order):
            if paint.light_px:
                for at in paint.pixels:
                    self._light(image, at, paint.light_px, paint.colour)
            else:
                self._fill(image, paint.pixels, paint.colour)

    def _light(
        self, image: np.ndarray, at: np.ndarray, side: int, colour: tuple[int, int, int]
    ) -> None:
        """A square light ``side`` pixels wide centred on ``at`` (x, y pixels)."""
        left, top = math.floor(at[0] - side / 2.0 + 0.5), math.floor(at[1] - side / 2.0 + 0.5)
        x0, x1 = max(0, left), min(self.width, left + side)
        y0, y1 = max(0, top), min(self.height, top + side)
        if x0 < x1 and y0 < y1:
            image[y0:y1, x0:x1] = colour

    def _fill(self, image: np.ndarray, px: np.ndarray, colour: tuple[int, int, int]) -> None:
        """Fill the convex polygon with vertices ``px`` (x, y pixels, either winding)."""
        x0, y0 = max(0, int(px[:, 0].min())), max(0, int(px[:, 1].min()))
        x1 = min(self.width, math.ceil(px[:, 0].max()) + 1)
        y1 = min(self.height, math.ceil(px[:, 1].max()) + 1)
        if x0 >= x1 or y0 >= y1:
            return
        xs, ys = self._cols[y0:y1, x0:x1], self._rows[y0:y1, x0:x1]
        inside_pos = np.ones(xs.shape, bool)
        inside_neg = np.ones(xs.shape, bool)
        for a, b in zip(px, np.roll(px, -1, axis=0), strict=True):
            cross = (b[0] - a[0]) * (ys - a[1]) - (b[1] - a[1]) * (xs - a[0])
            inside_pos &= cross >= 0
            inside_neg &= cross <= 0
        image[y0:y1, x0:x1][inside_pos | inside_neg] = colour
