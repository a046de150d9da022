"""Foxglove's 3D view and Map in the log: frame transforms, scene entities, LocationFix heading
and velocity; their conventions checked against the logged physics, their messages against
Foxglove's schemas (the copies shipped in the package; test_foxglove_node compares those with
the published ones)."""

import json
import math

import jsonschema
import numpy as np
import pytest
from mcap.reader import make_reader

from gymfg_il import Team
from gymfg_il.agent import ConstantAgent
from gymfg_il.aircraft import c172p, f15
from gymfg_il.collectors.autopilot import record_autopilot
from gymfg_il.collectors.config import CollectConfig
from gymfg_il.envs import OfflineEnv
from gymfg_il.envs.scenarios import head_on_merge
from gymfg_il.recording import foxglove
from gymfg_il.recording.reader import read_log
from gymfg_il.recording.recorder import Recorder
from gymfg_il.sim.properties import INDEX
from gymfg_il.tasks import ReachStaticTargetAltitudeTask

FOXGLOVE = ("foxglove.LocationFix", "foxglove.FrameTransform", "foxglove.SceneUpdate")


def messages(path):
    """{topic: [decoded messages]} and {topic: schema name}."""
    out, names = {}, {}
    with open(path, "rb") as f:
        for schema, channel, m in make_reader(f).iter_messages(log_time_order=False):
            out.setdefault(channel.topic, []).append(json.loads(m.data))
            names[channel.topic] = schema.name
    return out, names


def rotate(q, v):
    """``v`` rotated by the unit quaternion ``q`` ({x, y, z, w})."""
    u = np.array([q["x"], q["y"], q["z"]])
    v = np.asarray(v, float)
    return v + 2 * q["w"] * np.cross(u, v) + 2 * np.cross(u, np.cross(u, v))


def ned_from_body(roll, pitch, heading):
    """JSBSim's direction cosine matrix, body FRD -> local NED (textbook z-y-x)."""
    f, t, p = np.radians([roll, pitch, heading])
    rz = np.array([[np.cos(p), -np.sin(p), 0], [np.sin(p), np.cos(p), 0], [0, 0, 1]])
    ry = np.array([[np.cos(t), 0, np.sin(t)], [0, 1, 0], [-np.sin(t), 0, np.cos(t)]])
    rx = np.array([[1, 0, 0], [0, np.cos(f), -np.sin(f)], [0, np.sin(f), np.cos(f)]])
    return rz @ ry @ rx


NED_TO_ENU = np.array([[0, 1, 0], [1, 0, 0], [0, 0, -1]])
FLU_TO_FRD = np.diag([1, -1, -1])


@pytest.mark.parametrize("seed", range(5))
def test_quaternion_is_the_jsbsim_attitude_in_enu_and_flu(seed):
    rng = np.random.default_rng(seed)
    roll, pitch, heading = rng.uniform(-180, 180), rng.uniform(-89, 89), rng.uniform(0, 360)
    uvw = tuple(rng.uniform(-200, 200, 3))
    q, velocity = foxglove.attitude(roll, pitch, heading, uvw)
    expected = NED_TO_ENU @ ned_from_body(roll, pitch, heading) @ FLU_TO_FRD
    for axis in range(3):
        assert np.allclose(rotate(q, np.eye(3)[axis]), expected[:, axis], atol=1e-12)
    v_enu = NED_TO_ENU @ ned_from_body(roll, pitch, heading) @ np.array(uvw) * 0.3048
    assert np.allclose([velocity["x"], velocity["y"], velocity["z"]], v_enu, atol=1e-9)


def test_local_frame_is_east_north_up_in_metres():
    frame = foxglove.LocalFrame(37.6, -122.4, 1000.0)
    e, n, u = frame.enu(37.6 + 1000 / 111_000, -122.4, 1000.0)  # ~1 km north
    assert abs(e) < 1e-6 and n == pytest.approx(1000, rel=0.01) and abs(u) < 0.2
    e, n, u = frame.enu(37.6, -122.4 + 0.01, 1100.0)  # east and 100 m up
    assert e == pytest.approx(0.01 * 111_320 * math.cos(math.radians(37.6)), rel=0.01)
    assert u == pytest.approx(100.0, abs=0.1) and abs(n) < 0.1


@pytest.fixture(scope="module")
def altitude_log(tmp_path_factory):
    out = tmp_path_factory.mktemp("fox")
    cfg = CollectConfig(task="altitude", dynamic=True, episodes=2, episode_time_s=30, out=out)
    return record_autopilot(cfg).log


def test_transforms_and_fixes_agree_with_the_flight(altitude_log):
    log = read_log(altitude_log)
    msgs, _ = messages(altitude_log)
    tfs, fixes = msgs["/gymfg/ego/tf"], msgs["/gymfg/ego/location"]
    steps = [len(ep.steps["ego"]) for ep in log.complete_episodes]
    assert len(fixes) == sum(steps) and len(tfs) == sum(steps) + len(steps)  # + one per reset
    ep = log.complete_episodes[0]
    state = ep.steps["ego"].state
    first = tfs[: steps[0] + 1]
    assert first[0]["parent_frame_id"] == "enu" and first[0]["child_frame_id"] == "ego"
    start = first[0]["translation"]
    assert max(abs(start[k]) for k in "xyz") < 1e-6  # anchored at the aircraft's start
    pos = np.array([[m["translation"][k] for k in "xyz"] for m in first])
    vel = np.array([[f["velocity"][k] for k in "xyz"] for f in fixes[: steps[0]]])
    dt = log.session["dt"]
    # positions step by the logged ground velocity (mean of the two ends of each step)
    travelled = np.diff(pos, axis=0)
    mean_v = np.vstack([vel[:1], (vel[1:] + vel[:-1]) / 2])
    assert np.abs(travelled - mean_v * dt).max() < 0.05 * np.linalg.norm(mean_v, axis=1).min()
    # up is altitude; the vertical velocity is JSBSim's climb rate
    alt_m = state[:, INDEX["altitude_ft"]] * 0.3048
    start_m = ep.start_of("ego")["initial_state"]["altitude_ft"] * 0.3048
    assert np.allclose(pos[1:, 2], alt_m - start_m, atol=0.5)  # < 0.2 m of the Earth's curve
    assert np.allclose(vel[:, 2], state[:, INDEX["vertical_speed_fps"]] * 0.3048, atol=0.05)
    # the nose points where the aircraft goes, within angle of attack and sideslip
    for m, v, s in zip(first[1:], vel, state, strict=True):
        nose = rotate(m["rotation"], [1, 0, 0])
        angle = math.degrees(math.acos(np.dot(nose, v) / np.linalg.norm(v)))
        assert angle < abs(s[INDEX["alpha_deg"]]) + abs(s[INDEX["beta_deg"]]) + 1.0
    heading = np.array([f["heading"] for f in fixes[: steps[0]]])
    assert np.allclose(heading, np.radians(state[:, INDEX["heading_deg"]]))


def test_scene_draws_the_aircraft_and_its_moving_target(altitude_log):
    log = read_log(altitude_log)
    msgs, _ = messages(altitude_log)
    scenes = msgs["/gymfg/ego/scene"]
    resets = [s for s in scenes if s["deletions"]]
    assert len(resets) == 2 and len(scenes) > 2 + 4  # a dynamic target is redrawn as it moves
    entities = {e["id"]: e for e in resets[0]["entities"]}
    assert entities["ego"]["frame_id"] == "ego" and entities["ego"]["frame_locked"]
    assert len(entities["ego"]["cubes"]) == 4 and entities["ego"]["arrows"]
    plane = entities["ego/aim"]["cubes"][0]
    ep = log.complete_episodes[0]
    start_alt_ft = ep.start_of("ego")["initial_state"]["altitude_ft"]
    names = log.aircraft("ego")["observation_names"]
    targets = ep.steps["ego"].observation[:, names.index("altitude_ft_target")]
    assert entities["ego/aim"]["frame_id"] == "enu"
    z0 = plane["pose"]["position"]["z"]
    assert z0 == pytest.approx((targets[0] - start_alt_ft) * 0.3048, abs=0.5)
    assert "altitude target" in entities["ego/target"]["texts"][0]["text"]
    # redraws follow the logged target
    later = [s for s in scenes[1:] if not s["deletions"]][:3]
    for s in later:
        z = {e["id"]: e for e in s["entities"]}["ego/aim"]["cubes"][0]["pose"]["position"]["z"]
        assert np.min(np.abs((targets - start_alt_ft) * 0.3048 - z)) < 0.5


def test_foxglove_messages_validate_against_foxglove_schemas(altitude_log):
    msgs, names = messages(altitude_log)
    checked = set()
    for topic, schema_name in names.items():
        if schema_name in FOXGLOVE:
            validator = jsonschema.Draft7Validator(foxglove.schema(schema_name))
            for m in msgs[topic][:50] + msgs[topic][-50:]:
                validator.validate(m)
            checked.add(schema_name)
    assert checked == set(FOXGLOVE)
    bad = dict(msgs["/gymfg/ego/tf"][0], rotation={"x": 0, "y": 0, "z": 0})
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(bad, foxglove.schema("foxglove.FrameTransform"))


def test_team_run_shows_every_aircraft(tmp_path):
    red = Team(
        "red",
        [(c172p(f"red-{i}"), ReachStaticTargetAltitudeTask) for i in (1, 2)],
        episode_time_s=2,
    )
    blue = Team("blue", [(f15("blue-1"), ReachStaticTargetAltitudeTask)])
    env = OfflineEnv(opponents=[(blue, [ConstantAgent()])], scenario=head_on_merge())
    env = Recorder(env, tmp_path, source="dogfight")
    env.reset(red, seed=3)
    states = {s.callsign: s for s in env.world.slots}
    done = False
    while not done:
        out = env.step(np.tile([0.0, 0.0, 0.0, 0.7], 2))
        done = out[3] or out[4]
    path = env.log
    env.close()
    msgs, _ = messages(path)
    log = read_log(path)
    ep = log.complete_episodes[0]
    colours = {}
    for callsign in states:
        tfs = msgs[f"/gymfg/{callsign}/tf"]
        assert len(tfs) == len(ep.steps[callsign]) + 1
        assert {m["child_frame_id"] for m in tfs} == {callsign}
        (scene,) = msgs[f"/gymfg/{callsign}/scene"]
        body = {e["id"]: e for e in scene["entities"]}[callsign]
        colours[callsign] = tuple(body["cubes"][0]["color"].values())
    assert colours["red-1"] == colours["red-2"] != colours["blue-1"]
    # one frame for all: red-1 at its origin, the others where their positions put them
    first = {c: msgs[f"/gymfg/{c}/tf"][0]["translation"] for c in states}
    assert max(abs(v) for v in first["red-1"].values()) < 1e-6
    s0 = {c: ep.start_of(c)["initial_state"] for c in states}
    frame = foxglove.LocalFrame(
        s0["red-1"]["lat_deg"], s0["red-1"]["lon_deg"], s0["red-1"]["altitude_ft"] * 0.3048
    )
    blue_at = frame.enu(
        s0["blue-1"]["lat_deg"], s0["blue-1"]["lon_deg"], s0["blue-1"]["altitude_ft"] * 0.3048
    )
    assert np.allclose([first["blue-1"][k] for k in "xyz"], blue_at, atol=1e-6)
    assert np.hypot(*blue_at[:2]) > 1000  # head-on merge: far apart, not drawn on top


def test_shipped_layout_shows_what_an_altitude_log_holds(altitude_log):
    """docs/foxglove-layout.json: every topic and field it plots exists in an altitude log,
    and observation[10] is the altitude target."""
    from pathlib import Path

    layout = json.loads((Path(__file__).parents[2] / "docs/foxglove-layout.json").read_text())
    panels = layout["configById"]
    msgs, names = messages(altitude_log)
    three_d = panels["3D!gymfg3d"]
    assert three_d["followTf"] == "ego" and set(three_d["topics"]) <= set(msgs)
    assert names[panels["map!gymfgmap"]["followTopic"]] == "foxglove.LocationFix"
    log = read_log(altitude_log)
    target_index = log.aircraft("ego")["observation_names"].index("altitude_ft_target")
    plotted = [p["value"] for p in panels["Plot!gymfgalt"]["paths"]]
    assert plotted == [
        f"/gymfg/ego/step.observation[{target_index}]",
        "/gymfg/ego/state.altitude_ft",
    ]
    step, state = msgs["/gymfg/ego/step"][0], msgs["/gymfg/ego/state"][0]
    assert step["observation"][target_index] == log.complete_episodes[0].steps["ego"].observation[
        0, target_index
    ]  # fmt: skip
    assert "altitude_ft" in state and "elevator" in step["action"]
    used = {layout["layout"]["first"], *json.dumps(layout["layout"]).split('"')}
    assert set(panels) <= used


@pytest.mark.parametrize("task", ["waypoints", "approach", "formation"])
def test_scene_draws_what_a_maneuver_places(task, tmp_path):
    """Gates, the runway and a formation's lead are in the 3D view where the task's own
    landmarks (what the camera draws) put them; the lead moves with its track."""
    from gymfg_il.tasks.library import task_landmarks

    cfg = CollectConfig(task=task, episodes=1, episode_time_s=3, out=tmp_path)
    path = record_autopilot(cfg).log
    msgs, _ = messages(path)
    log = read_log(path)
    start = log.complete_episodes[0].start_of("ego")
    plan = start["plan"]
    s0 = start["initial_state"]
    frame = foxglove.LocalFrame(s0["lat_deg"], s0["lon_deg"], s0["altitude_ft"] * 0.3048)
    marks = task_landmarks(task, plan, 0)
    (scene,) = msgs["/gymfg/ego/scene"]
    entities = {e["id"]: e for e in scene["entities"]}
    validator = jsonschema.Draft7Validator(foxglove.schema("foxglove.SceneUpdate"))
    validator.validate(scene)
    if task == "waypoints":
        loops = entities["ego/scenery"]["lines"]
        assert len(loops) == len(marks) == 3 and entities["ego/scenery"]["frame_id"] == "enu"
        for loop, mark in zip(loops, marks, strict=True):
            centre = np.mean([[p[k] for k in "xyz"] for p in loop["points"]], axis=0)
            want = frame.enu(mark.lat_deg, mark.lon_deg, mark.alt_ft * 0.3048)
            assert np.allclose(centre, want, atol=1e-6)
            side = np.subtract(*[[loop["points"][i][k] for k in "xyz"] for i in (1, 0)])
            assert np.linalg.norm(side) == pytest.approx(mark.width_ft * 0.3048)
            facing = (
                math.sin(math.radians(mark.heading_deg)),
                math.cos(math.radians(mark.heading_deg)),
            )
            assert abs(np.dot(side[:2], facing)) < 1e-6  # across the leg that leads to it
    elif task == "approach":
        (slab,) = entities["ego/scenery"]["cubes"]
        (mark,) = marks
        threshold = np.array(frame.enu(mark.lat_deg, mark.lon_deg, mark.alt_ft * 0.3048))
        centre = np.array([slab["pose"]["position"][k] for k in "xyz"])
        along = rotate(slab["pose"]["orientation"], [1, 0, 0])  # the slab's length axis
        course = np.radians(mark.heading_deg)
        assert np.allclose(along, [math.sin(course), math.cos(course), 0], atol=1e-9)
        half = mark.length_ft * 0.3048 / 2
        assert np.allclose(centre, threshold + along * half, atol=1e-6)
        assert slab["size"]["y"] == pytest.approx(mark.width_ft * 0.3048)
    else:
        assert entities["ego/lead"]["frame_id"] == "ego/lead"
        leads = [m for m in msgs["/gymfg/ego/tf"] if m["child_frame_id"] == "ego/lead"]
        steps = len(log.complete_episodes[0].steps["ego"])
        assert len(leads) == steps + 1  # at the reset and after every step
        for k in (0, steps):
            (mark,) = task_landmarks(task, plan, k)
            want = frame.enu(mark.lat_deg, mark.lon_deg, mark.alt_ft * 0.3048)
            assert np.allclose([leads[k]["translation"][c] for c in "xyz"], want, atol=1e-6)
        moved = np.subtract(*[[leads[i]["translation"][c] for c in "xy"] for i in (steps, 0)])
        assert np.linalg.norm(moved) > 100  # 3 s of the lead's flight


def test_a_users_own_maneuver_records_without_scenery(tmp_path):
    """A maneuver the library does not know (a user's subclass, named its own way) has a
    plan but no landmarks the writer can look up: the log is written, with no scenery."""
    from gymfg_il.tasks.maneuvers import TurnTask

    class MyTurn(TurnTask):
        name = "my-turn"

    env = Recorder(OfflineEnv(), tmp_path)
    env.reset(Team("ego", [(c172p("ego"), MyTurn)], episode_time_s=1), seed=0)
    done = False
    while not done:
        *_, terminated, truncated, _ = env.step(np.array([0.0, 0.0, 0.0, 0.6]))
        done = terminated or truncated
    path = env.log
    env.close()
    log = read_log(path)
    assert log.complete_episodes[0].start_of("ego")["plan"]  # a maneuver's plan, recorded
    msgs, _ = messages(path)
    (scene,) = msgs["/gymfg/ego/scene"]
    assert "ego/scenery" not in {e["id"] for e in scene["entities"]}
