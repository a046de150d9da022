import dataclasses
import hashlib
import math

import numpy as np
import pytest

from gymfg_il.errors import ConfigError
from gymfg_il.sim.properties import INDEX, NAMES
from gymfg_il.tasks.scenery import Landmark, aircraft_landmark
from gymfg_il.viz.camera import Camera


def state(roll=0.0, pitch=0.0, heading=0.0, alt=5000.0, agl=5000.0, lat=37.6, lon=-122.4):
    s = np.zeros(len(NAMES))
    values = {"roll_deg": roll, "pitch_deg": pitch, "heading_deg": heading, "altitude_ft": alt,
              "altitude_agl_ft": agl, "lat_deg": lat, "lon_deg": lon}  # fmt: skip
    for k, v in values.items():
        s[INDEX[k]] = v
    return s


def horizon_angle(frame):
    """The angle (deg, counter-clockwise) of the line between sky and ground, fitted to
    the first ground pixel of each column (ground is greener than it is blue)."""
    ground = frame[..., 1].astype(int) > frame[..., 2].astype(int) + 8
    xs, ys = [], []
    for x in range(frame.shape[1]):
        col = ground[:, x]
        edges = np.flatnonzero(col[1:] != col[:-1])
        if len(edges) == 1:
            xs.append(x)
            ys.append(edges[0])
    slope = np.polyfit(xs, ys, 1)[0]
    return math.degrees(math.atan(-slope))


@pytest.mark.parametrize("roll", [-40.0, -15.0, 0.0, 10.0, 30.0])
def test_the_horizon_rolls_with_the_aircraft(roll):
    frame = Camera(128, 128).frame(state(roll=roll, pitch=2.0, heading=70.0))
    # a right bank turns the world (and its horizon) anticlockwise in the pilot's eye
    assert horizon_angle(frame) == pytest.approx(roll, abs=2.0)


def test_the_horizon_moves_down_when_the_nose_pitches_up():
    camera = Camera(128, 128)

    def horizon_row(pitch):
        ground = camera.frame(state(pitch=pitch))[..., 1].astype(int)
        col = ground[:, 64] > camera.frame(state(pitch=pitch))[:, 64, 2].astype(int) + 8
        return int(np.argmax(col))

    level, up = horizon_row(0.0), horizon_row(10.0)
    # 10 deg up moves the horizon focal * tan(10 deg) = 11 px down (90 deg FOV, 128 px)
    assert up - level == pytest.approx(64 * math.tan(math.radians(10.0)), abs=2)


def test_the_same_state_gives_the_same_frame_and_motion_changes_it():
    a = Camera().frame(state(roll=12.3, pitch=-3.0, heading=200.0))
    b = Camera().frame(state(roll=12.3, pitch=-3.0, heading=200.0))
    assert a.dtype == np.uint8 and a.shape == (128, 128, 3)
    assert np.array_equal(a, b)
    moved = Camera().frame(state(roll=12.3, pitch=-3.0, heading=200.0, lat=37.601))
    lower = Camera().frame(state(roll=12.3, pitch=-3.0, heading=200.0, agl=1000.0))
    assert not np.array_equal(a, moved) and not np.array_equal(a, lower)


def test_landmarks_are_drawn_where_they_are():
    own = state(heading=0.0)
    north = 2000.0 / (math.pi / 180.0 * 20902230.97)  # 2,000 ft ahead in degrees of latitude
    gate = Landmark("gate", 37.6 + north, -122.4, 5000.0, 0.0, width_ft=600.0, length_ft=300.0)
    camera = Camera(128, 128)
    plain, drawn = camera.frame(own), camera.frame(own, [gate])
    changed = np.argwhere(np.any(plain != drawn, axis=2))
    assert len(changed) > 20
    # centred ahead: half of 600 ft at 2,000 ft spans focal (64 px) * 300 / 2000 = 9.6 px
    assert changed[:, 1].min() == pytest.approx(64 - 9.6, abs=1.5)
    assert changed[:, 1].max() == pytest.approx(64 + 9.6, abs=1.5)
    behind = Landmark("gate", 37.6 - north, -122.4, 5000.0, 0.0, width_ft=600.0, length_ft=300.0)
    assert np.array_equal(camera.frame(own, [behind]), plain)


def test_the_chase_view_shows_the_bank_of_the_aircraft():
    chase = Camera(128, 128, view="chase")
    level, banked = chase.frame(state()), chase.frame(state(roll=45.0))
    red = [np.argwhere((f[..., 0] > 200) & (f[..., 1] < 80)) for f in (level, banked)]
    assert len(red[0]) > 30 and len(red[1]) > 30
    # level wings span left to right; banked 45 deg right, the right wing drops
    height = [int(np.ptp(r[:, 0])) for r in red]
    assert height[1] > 2 * height[0]
    assert aircraft_landmark(state(roll=45.0)).roll_deg == 45.0


def test_bad_camera_settings_are_clear_errors():
    with pytest.raises(ConfigError, match="view"):
        Camera(view="cockpit")
    with pytest.raises(ConfigError, match="pixels"):
        Camera(4, 4)


def _scene():
    """A runway, a gate and another aircraft in one front view, banked and pitched."""
    ft = math.pi / 180.0 * 20902230.97  # ft per degree of latitude
    marks = [
        Landmark("runway", 37.6 + 6000 / ft, -122.4 + 300 / ft, 0.0, 15.0, 0.0, 0.0, 150.0, 5000.0),
        Landmark("gate", 37.6 + 2500 / ft, -122.4 - 400 / ft, 1400.0, 5.0, 0.0, 0.0, 600.0, 300.0),
        Landmark("aircraft", 37.6 + 400 / ft, -122.4 - 150 / ft, 1480.0, 12.0, 20.0, 3.0),
    ]
    return state(roll=8.0, pitch=-2.0, heading=10.0, alt=1500.0, agl=1500.0), marks


@pytest.mark.parametrize(
    ("view", "size", "digest"),
    [
        ("front", 128, "cc8446074011be07"),
        ("front", 320, "adb3f64c4b461a3b"),
        ("chase", 128, "241dcd562dcb2953"),
    ],
)
def test_the_default_frames_are_the_ones_datasets_were_made_with(view, size, digest):
    # hashes taken before the legible mode existed: dataset images must not change
    own, marks = _scene()
    frame = Camera(size, size, view=view).frame(own, marks)
    assert hashlib.sha256(frame.tobytes()).hexdigest()[:16] == digest
    # the default mode ignores a highlight (it is the window's, not the dataset's)
    lit = [dataclasses.replace(m, highlight=True) for m in marks]
    assert np.array_equal(Camera(size, size, view=view).frame(own, lit), frame)
