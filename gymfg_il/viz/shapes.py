"""What the landmarks look like, at their true size: the quads (north-east-down ft about a
landmark's position) that draw a runway, a gate or an aircraft, and the attitude rotation
they and the camera turn by. ``viz.camera`` projects and paints them."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from gymfg_il.tasks.scenery import Landmark

COLOURS = {
    "runway": (70, 70, 74),
    "gate": (235, 110, 20),
    "aircraft": (230, 40, 40),
}
MARKING = (235, 235, 235)  # white paint on a runway
NEAR_FT = 1.0  # nothing nearer than this ahead of the eye is drawn

# wing, fuselage seen from above and from the side, tailplane, fin
AIRCRAFT = np.array(
    [
        [(0.0, -1, 0), (0.3, -1, 0), (0.3, 1, 0), (0.0, 1, 0)],
        [(0.6, -0.1, 0), (0.6, 0.1, 0), (-0.4, 0.05, 0), (-0.4, -0.05, 0)],
        [(0.6, 0, -0.06), (0.6, 0, 0.06), (-0.4, 0, 0.03), (-0.4, 0, -0.03)],
        [(-0.3, -0.35, 0), (-0.4, -0.35, 0), (-0.4, 0.35, 0), (-0.3, 0.35, 0)],
        [(-0.28, 0, 0), (-0.4, 0, 0), (-0.42, 0, -0.2), (-0.36, 0, -0.2)],
    ]
)


def rotation(roll_deg: float, pitch_deg: float, heading_deg: float) -> np.ndarray:
    """Body (forward, right, down) to local (north, east, down) rotation matrix."""
    r, p, h = (math.radians(a) for a in (roll_deg, pitch_deg, heading_deg))
    cr, sr, cp, sp, ch, sh = (
        math.cos(r),
        math.sin(r),
        math.cos(p),
        math.sin(p),
        math.cos(h),
        math.sin(h),
    )
    return np.array(
        [
            [cp * ch, sr * sp * ch - cr * sh, cr * sp * ch + sr * sh],
            [cp * sh, sr * sp * sh + cr * ch, cr * sp * sh - sr * ch],
            [-sp, sr * cp, cr * cp],
        ]
    )


def quads(item: Landmark) -> list[tuple[np.ndarray, int]]:
    """Quads (4 x 3 points, north-east-down ft, about the item's position) that draw it, each
    with its layer: 0 the surface, 1 a white marking painted on it."""
    rot = rotation(item.roll_deg, item.pitch_deg, item.heading_deg)
    w, length = item.width_ft, item.length_ft
    body: list[Any]
    marks: list[Any] = []
    if item.kind == "runway":
        body = [
            [(0.0, -w / 2, 0.0), (length, -w / 2, 0.0), (length, w / 2, 0.0), (0.0, w / 2, 0.0)]
        ]
        # threshold bar, then the centre line's dashes
        marks = [
            [
                (20.0, -0.45 * w, 0.0),
                (80.0, -0.45 * w, 0.0),
                (80.0, 0.45 * w, 0.0),
                (20.0, 0.45 * w, 0.0),
            ]
        ]
        for x in np.arange(200.0, length - 150.0, 400.0):
            c = 0.03 * w
            marks.append([(x, -c, 0.0), (x + 150.0, -c, 0.0), (x + 150.0, c, 0.0), (x, c, 0.0)])
    elif item.kind == "gate":
        bar = max(w, length) * 0.06
        hw, hh = w / 2, length / 2
        body = [
            [(0, -hw, -hh), (0, hw, -hh), (0, hw, -hh + bar), (0, -hw, -hh + bar)],
            [(0, -hw, hh - bar), (0, hw, hh - bar), (0, hw, hh), (0, -hw, hh)],
            [(0, -hw, -hh), (0, -hw + bar, -hh), (0, -hw + bar, hh), (0, -hw, hh)],
            [(0, hw - bar, -hh), (0, hw, -hh), (0, hw, hh), (0, hw - bar, hh)],
        ]
    else:  # aircraft: the model's corners in (length, span, length) units
        scale = np.array([length, w / 2, length])
        body = [q * scale for q in AIRCRAFT]
    return [
        (np.asarray(q, dtype=np.float64) @ rot.T, layer)
        for layer, quads in ((0, body), (1, marks))
        for q in quads
    ]
