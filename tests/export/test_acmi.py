"""A recorded team run exported for Tacview, read back with a parser of its own (written from
Tacview's ACMI 2.1 description, not from the exporter), against the log's states."""

import re

import numpy as np
import pytest

from gymfg_il import Team, collect
from gymfg_il.agent import RandomAgent
from gymfg_il.aircraft import c172p, f15
from gymfg_il.envs import OfflineEnv
from gymfg_il.envs.scenarios import head_on_merge
from gymfg_il.errors import ConfigError, GymFGError
from gymfg_il.export.acmi import team_colors, write_acmi
from gymfg_il.recording.reader import read_log
from gymfg_il.recording.recorder import Recorder
from gymfg_il.sim.properties import INDEX
from gymfg_il.tasks import ReachStaticTargetAltitudeTask

STEPS = 20  # 2 s at 10 Hz


@pytest.fixture(scope="module")
def team_log(tmp_path_factory):
    out = tmp_path_factory.mktemp("acmi")
    red = Team(
        "red",
        [(c172p(f"red-{i}"), ReachStaticTargetAltitudeTask) for i in (1, 2)],
        episode_time_s=2,
    )
    blue = Team("blue", [(f15("blue-1"), ReachStaticTargetAltitudeTask)])  # the env's own opponent
    env = Recorder(
        OfflineEnv(opponents=[(blue, [RandomAgent(0.2, 0.8)])], scenario=head_on_merge()), out
    )
    pilots = [RandomAgent(0.3), RandomAgent(0.4)]
    for seed in (3, 4):
        env.reset(red, seed=seed)
        for p in pilots:
            p.reset(seed)
        done = False
        while not done:
            actions = [p.act(np.zeros(1)) for p in pilots]
            *_, terminated, truncated, _ = env.step(np.hstack(actions))
            done = terminated or truncated
    path = env.log
    env.close()
    return out, path


def parse_acmi(text):
    """ACMI 2.1 text -> (global properties, objects in order of appearance), each object with
    its properties, its track [(time, lon, lat, alt, roll, pitch, yaw)] and its removal time."""
    lines = text.split("\n")
    assert lines[0] == "FileType=text/acmi/tacview"
    assert lines[1] == "FileVersion=2.1"
    now, world, objects = 0.0, {}, {}
    for line in lines[2:]:
        if not line:
            continue
        if line[0] == "#":
            now = float(line[1:])
        elif line[0] == "-":
            objects[line[1:]]["removed"] = now
        else:
            oid, *fields = re.split(r"(?<!\\),", line)
            assert re.fullmatch(r"[0-9a-f]+", oid), line  # ids are hexadecimal
            props = dict(f.split("=", 1) for f in fields)
            if oid == "0":
                for k, v in props.items():
                    world.setdefault(k, []).append(v)
                continue
            obj = objects.setdefault(oid, {"props": {}, "track": [], "removed": None})
            coords = props.pop("T", None)
            if coords is not None:
                obj["track"].append((now, *map(float, coords.split("|"))))
            obj["props"].update(props)
    return world, list(objects.values())


def test_every_aircraft_of_a_team_run_reads_back_as_logged(team_log, tmp_path):
    _, path = team_log
    summary = write_acmi(path, tmp_path / "run.acmi")
    assert summary.episodes == 2 and summary.objects == 6
    world, objects = parse_acmi((tmp_path / "run.acmi").read_text(encoding="utf-8"))
    assert re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ", world["ReferenceTime"][0])
    assert [b.split("|")[0] for b in world["Event"]] == ["Bookmark", "Bookmark"]
    assert "seed 3" in world["Event"][0] and "seed 4" in world["Event"][1]
    log = read_log(path)
    expected = {
        "red-1": ("C172", "red", "Red"),
        "red-2": ("C172", "red", "Red"),
        "blue-1": ("F-15C", "blue", "Blue"),
    }
    assert len(objects) == 6
    starts = []
    for k, ep in enumerate(log.complete_episodes):
        for callsign, obj in zip(ep.steps, objects[3 * k : 3 * k + 3], strict=True):
            p = obj["props"]
            assert p["CallSign"] == callsign
            assert (p["Name"], p["Coalition"], p["Color"]) == expected[callsign]
            assert p["Type"] == "Air+FixedWing"
            track = np.array(obj["track"])
            assert track.shape == (STEPS + 1, 7)  # the reset, then after every step
            states = np.vstack([ep.start_of(callsign)["state"], ep.steps[callsign].state])
            times = track[:, 0] - track[0, 0]
            assert np.allclose(times, np.arange(STEPS + 1) * 0.1, atol=1e-4)
            assert obj["removed"] == pytest.approx(track[-1, 0] + 0.1)
            lon, lat, alt, roll, pitch, yaw = track[:, 1:].T
            assert np.allclose(lon, states[:, INDEX["lon_deg"]], atol=6e-8, rtol=0)
            assert np.allclose(lat, states[:, INDEX["lat_deg"]], atol=6e-8, rtol=0)
            assert np.allclose(alt, states[:, INDEX["altitude_ft"]] * 0.3048, atol=0.006, rtol=0)
            assert np.allclose(roll, states[:, INDEX["roll_deg"]], atol=0.006, rtol=0)
            assert np.allclose(pitch, states[:, INDEX["pitch_deg"]], atol=0.006, rtol=0)
            turn = (yaw - states[:, INDEX["heading_deg"]] + 180.0) % 360.0 - 180.0
            assert np.abs(turn).max() < 0.006
            assert float(p["TAS"]) > 50.0  # m/s: flying, in Tacview's units
            starts.append(track[0, 0])
    # the aircraft flew apart (head-on merge) and the episodes follow one another in time
    assert starts[0] == starts[1] == starts[2] < starts[3] == starts[4] == starts[5]
    assert starts[3] >= objects[0]["removed"]


def test_the_cli_writes_one_episode_beside_the_log(team_log, capsys):
    out, path = team_log
    assert collect.main(["export", "acmi", str(out), "--episode", "1"]) == 0
    written = path.with_suffix(".acmi")
    assert "1 episode(s), 3 aircraft tracks" in capsys.readouterr().out
    world, objects = parse_acmi(written.read_text(encoding="utf-8"))
    assert len(objects) == 3 and "seed 4" in world["Event"][0]


def test_bad_inputs_are_clear_errors(team_log, tmp_path, capsys):
    _, path = team_log
    with pytest.raises(GymFGError, match="no trajectory log"):
        write_acmi(tmp_path / "absent.mcap")
    (tmp_path / "notes.mcap").write_text("hello")
    with pytest.raises(GymFGError, match="not an MCAP file"):
        write_acmi(tmp_path / "notes.mcap")
    with pytest.raises(ConfigError, match=re.escape("no completed episode 9; it has [0, 1]")):
        write_acmi(path, tmp_path / "x.acmi", episode=9)
    with pytest.raises(ConfigError, match=re.escape("named *.acmi")):
        write_acmi(path, tmp_path / "x.csv")
    (tmp_path / "logs").mkdir()
    with pytest.raises(ConfigError, match=re.escape("no logs/*.mcap: give one .mcap log")):
        write_acmi(tmp_path)
    assert collect.main(["export", "acmi", str(tmp_path / "absent.mcap")]) == 2
    assert "error: no trajectory log" in capsys.readouterr().err
    assert not (tmp_path / "x.acmi").exists()


def test_team_colours_follow_their_names_then_a_palette():
    assert team_colors(["red", "blue"]) == {"red": "Red", "blue": "Blue"}
    assert team_colors(["ego"]) == {"ego": "Blue"}
    assert team_colors(["blue", "hawks", "owls"]) == {
        "blue": "Blue",
        "hawks": "Red",
        "owls": "Green",
    }
