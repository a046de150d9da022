"""The camera's legible mode: what a task needs seen is visible in the window's 320 x 320 view."""

import math

import numpy as np
import pytest

from gymfg_il.envs.flight import FlightSpec
from gymfg_il.sim.properties import INDEX, NAMES
from gymfg_il.tasks.geometry import offset_position
from gymfg_il.tasks.scenery import Landmark, landmarks_of
from gymfg_il.viz import legible
from gymfg_il.viz.camera import Camera

SIZE = 320  # the manual window's pilot's view
LAT, LON = 37.6, -122.4
ATTITUDE = ("roll_deg", "pitch_deg", "heading_deg")
PLACE = ("altitude_ft", "altitude_agl_ft", "lat_deg", "lon_deg")


def state(roll=0.0, pitch=0.0, heading=0.0, alt=5000.0, north=0.0, east=0.0):
    s = np.zeros(len(NAMES))
    lat, lon = offset_position(LAT, LON, north, east)
    values = (roll, pitch, heading, alt, alt, lat, lon)
    for k, v in zip(ATTITUDE + PLACE, values, strict=True):
        s[INDEX[k]] = v
    return s


def pixels_of(frame, colour):
    """(row, column) of every pixel of exactly ``colour``."""
    return np.argwhere(np.all(frame == np.array(colour, np.uint8), axis=2))


def runway(**kw):
    return Landmark("runway", LAT, LON, 0.0, 0.0, width_ft=150.0, length_ft=5000.0, **kw)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_runway_and_its_lights_are_seen_from_the_approach_start(seed):
    env = FlightSpec.solo("c172p", "approach").make_env()
    env.reset(seed=seed)
    own, marks = env.world.slots[0].state, landmarks_of(env.task, env.task.plan, 0)
    window, plain = Camera(SIZE, SIZE, legible=True), Camera(SIZE, SIZE)
    seen, true_size = window.frame(own, marks), plain.frame(own, marks)
    # at true size, 3.5-4 NM out, the runway is about a pixel and has no lights
    assert len(pixels_of(true_size, legible.LIGHT)) == 0
    assert np.count_nonzero(np.any(seen != plain.frame(own), axis=2)) > 60
    assert len(pixels_of(seen, legible.LIGHT)) >= 12
    assert len(pixels_of(seen, legible.THRESHOLD)) >= 10
    edge = pixels_of(seen, legible.EDGE)
    assert len(edge) >= 20 and np.ptp(edge[:, 1]) >= legible.RUNWAY_MIN_PX


def test_the_magnified_runway_keeps_the_glide_path_and_stays_below_the_horizon():
    # on a 3 degree path 4 NM out, level: the horizon is the middle row
    out = 4 * 6076.1
    own = state(alt=out * math.tan(math.radians(3.0)), north=-out)
    frame = Camera(SIZE, SIZE, legible=True).frame(own, [runway()])
    drawn = np.argwhere(np.any(frame != Camera(SIZE, SIZE).frame(own), axis=2))
    assert drawn[:, 0].min() >= SIZE / 2 + 1
    # the threshold is where it truly is: 3 degrees below the horizon, straight ahead
    threshold = pixels_of(frame, legible.THRESHOLD).mean(axis=0)
    focal = SIZE / 2  # 90 degree field of view
    assert threshold[0] + 0.5 == pytest.approx(
        SIZE / 2 + focal * math.tan(math.radians(3)), abs=1.5
    )
    assert threshold[1] + 0.5 == pytest.approx(SIZE / 2, abs=1.0)


def test_the_runway_under_the_aircraft_is_drawn_to_the_bottom_of_the_view():
    own = state(alt=30.0, north=1500.0)
    frame = Camera(SIZE, SIZE, legible=True).frame(own, [runway()])
    bottom = frame[-40:, SIZE // 2 - 60 : SIZE // 2 - 20]  # left of the centre line's dashes
    assert np.all(bottom == np.array(legible.RUNWAY, np.uint8), axis=2).mean() > 0.9


def test_the_highlighted_gate_stands_out_and_every_gate_frame_is_two_pixels_thick():
    own = state(alt=5000.0)
    gates = []
    for north, east in ((8000.0, -1500.0), (15000.0, 0.0), (25000.0, 2500.0)):
        lat, lon = offset_position(LAT, LON, north, east)
        size = {"width_ft": 600.0, "length_ft": 300.0, "highlight": north == 8000.0}
        gates.append(Landmark("gate", lat, lon, 5000.0, 0.0, **size))
    frame = Camera(SIZE, SIZE, legible=True).frame(own, gates)
    lit, plain = pixels_of(frame, legible.HIGHLIGHT), pixels_of(frame, legible.GATE)
    assert len(lit) > 40 and len(plain) > 40
    assert lit[:, 1].max() < SIZE / 2 < plain[:, 1].max()  # the next gate is the left one
    # the far gate's frame: its top bar covers at least 2 rows in the column through its middle
    far = plain[plain[:, 1] > plain[:, 1].max() - 12]
    column = far[far[:, 1] == int(np.median(far[:, 1]))]
    rows = np.sort(column[:, 0])
    assert np.count_nonzero(rows < rows.mean()) >= 2 and np.count_nonzero(rows > rows.mean()) >= 2
    assert len(pixels_of(Camera(SIZE, SIZE).frame(own, gates), legible.HIGHLIGHT)) == 0


def slot_view(bank_deg, behind=150.0, right=100.0):
    """The window's frame from the formation slot (``behind`` and ``right`` of the lead, at its
    altitude and heading), the lead banked ``bank_deg``."""
    lead = Landmark("aircraft", LAT, LON, 5000.0, 30.0, bank_deg, 0.0)
    h = math.radians(30.0)
    north = -behind * math.cos(h) - right * math.sin(h)
    east = -behind * math.sin(h) + right * math.cos(h)
    own = state(heading=30.0, north=north, east=east)
    return Camera(SIZE, SIZE, legible=True).frame(own, [lead])


def wing_line(frame):
    """Length (px) and slope (rows per column, down to the right) of the drawn wing."""
    wing = pixels_of(frame, legible.WING)
    assert len(wing) > 10
    slope = np.polyfit(wing[:, 1], wing[:, 0], 1)[0]
    return math.hypot(np.ptp(wing[:, 1]), np.ptp(wing[:, 0])), slope


def test_the_lead_is_in_the_front_view_at_the_slot_and_its_wing_is_long():
    frame = slot_view(0.0)
    wing = pixels_of(frame, legible.WING)
    assert wing[:, 1].min() > 2 and wing[:, 1].max() < SIZE / 2  # ahead-left, inside the view
    length, slope = wing_line(frame)
    assert length >= 30
    assert abs(slope) < 0.05


@pytest.mark.parametrize("bank", [10.0, 25.0])
def test_the_lead_wing_slope_follows_its_bank(bank):
    (_, right_bank), (_, left_bank) = wing_line(slot_view(bank)), wing_line(slot_view(-bank))
    # banked right, its right wing drops: the line runs down to the right (rows grow)
    assert right_bank > 0.1 and left_bank < -0.1
    assert wing_line(slot_view(2 * bank))[1] > right_bank


def test_a_far_aircraft_is_magnified_but_still_shrinks_with_distance():
    sizes = []
    for behind in (150.0, 450.0, 1500.0):
        length, _ = wing_line(slot_view(0.0, behind=behind, right=0.0))
        sizes.append(length)
    true_far = SIZE / 2 * 36.0 / 1500.0  # the wing's true span 1,500 ft ahead, ~4 px
    assert sizes[0] > sizes[1] > sizes[2] > 2.5 * true_far
