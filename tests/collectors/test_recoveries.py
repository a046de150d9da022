"""Data that shows recoveries from a manual session: DART noise on what the synthetic pilot
flies (``--noise``) and seeded gust events (``--gusts``). The dataset's action is always the
pilot's own answer; what perturbed the flight is in the log and in the dataset card."""

import json
import os

import numpy as np
import pytest

os.environ["SDL_VIDEODRIVER"] = "dummy"

from gymfg_il import collect
from gymfg_il.cockpit.session import ManualSession
from gymfg_il.collectors.config import CollectConfig, ManualConfig
from gymfg_il.errors import ConfigError
from gymfg_il.learning.data import load_frames
from gymfg_il.manual.controller import ManualController
from gymfg_il.recording.reader import read_log
from gymfg_il.sim.properties import NAMES

FLIGHT = {"task": "altitude", "episode_time_s": 10, "agent_hz": 30, "seed": 11, "episodes": 1}


def fly(out, **options):
    """One synthetic keyboard episode: the pilot's input stage, the log and the dataset."""
    cfg = ManualConfig(**FLIGHT, pilot="synthetic", out=out, **options)
    session = ManualSession(cfg)
    session.run()
    (log,) = (read_log(p) for p in sorted((out / "logs").glob("*.mcap")))
    return session.stages.input, log, load_frames(out / "dataset")


@pytest.fixture(scope="module")
def sessions(tmp_path_factory):
    root = tmp_path_factory.mktemp("recoveries")
    asked = {
        "still": {},
        "gusty": {"gusts": "moderate"},
        "both": {"noise": 0.1, "gusts": "moderate"},
        "both again": {"noise": 0.1, "gusts": "moderate"},
    }
    return {name: (root / name, *fly(root / name, **o)) for name, o in asked.items()}


def pilots_own(pilot, first):
    """What the pilot's key events alone make of the controls, frame by frame: a fresh
    controller fed them (the dataset must hold exactly these, not what was flown)."""
    ref = ManualController("keyboard", throttle=0.75)
    ref.start_from(np.asarray(first, np.float64))
    own = [ref.values.copy()]
    for events in pilot.sent:
        ref.handle(events, 1 / 30)
        own.append(ref.values.copy())
    return np.array(own)


def card(out):
    return (out / "dataset" / "README.md").read_text()


@pytest.mark.slow  # its sessions take ~30 s
def test_noise_perturbs_what_the_synthetic_pilot_flies_not_what_the_dataset_records(sessions):
    out, pilot, log, frames = sessions["both"]
    steps = log.complete_episodes[0].steps["ego"]
    assert np.allclose(frames.action, pilots_own(pilot, frames.action[0]), atol=1e-6)
    assert np.array_equal(frames.action, steps.label.astype(np.float32))  # the pilot's answer
    flown = np.abs(steps.action - steps.label)
    # what was flown carries the noise on every control (std 0.1, then clipped)
    assert flown.mean(0).min() > 0.03, flown.mean(0)
    assert log.session["noise"] == 0.1 and frames.episodes["gymfg/noise"] == [0.1]
    assert "| DART noise (action std) | 0.1 (1 episode) |" in card(out)
    still = sessions["still"][2].complete_episodes[0].steps["ego"]
    assert np.array_equal(still.action, still.label) and sessions["still"][2].session["noise"] == 0


@pytest.mark.slow  # its sessions take ~30 s
def test_gusts_knock_the_aircraft_about_and_the_dataset_keeps_the_pilots_answers(sessions):
    out, pilot, log, frames = sessions["gusty"]
    assert np.allclose(frames.action, pilots_own(pilot, frames.action[0]), atol=1e-6)
    episode = log.complete_episodes[0]
    assert np.array_equal(episode.steps["ego"].action, episode.steps["ego"].label)
    gusts = episode.start["gusts"]  # the log's start event lists them
    assert gusts and all(20 <= np.linalg.norm([g["north_fps"], g["east_fps"], g["down_fps"]])
                         <= 35 for g in gusts)  # fmt: skip
    assert gusts[0]["start_s"] < FLIGHT["episode_time_s"] - gusts[0]["duration_s"]
    assert json.loads(frames.episodes["gymfg/gusts"][0]) == gusts
    assert log.spec.gusts == "moderate" and log.spec.gusty
    still = sessions["still"][3]
    assert "gymfg/gusts" not in still.episodes  # a flight without gusts is as it was
    assert not np.array_equal(frames.obs, still.obs)
    calm = sessions["still"][2].complete_episodes[0].steps["ego"].state
    off = np.abs(episode.steps["ego"].state - calm).max(axis=0)
    bump, height = off[NAMES.index("load_factor_g")], off[NAMES.index("altitude_ft")]
    assert bump > 0.2 and height > 5.0, f"the gusts knocked it {bump:.2f} g, {height:.1f} ft"
    text = card(out)
    assert "moderate gusts" in text and f"| gusts | {len(gusts)} in 1 episode(s)" in text


def dataset_bits(out):
    """The dataset's frames (the synthetic pilot keeps no wall clock) and episode records,
    less what says when and into which file."""
    import pyarrow.parquet as pq

    root = out / "dataset"
    frames = [pq.read_table(p) for p in sorted(root.glob("data/**/*.parquet"))]
    unstable = ("gymfg/wall_start", "gymfg/log")
    records = [
        pq.read_table(p).select([c for c in pq.read_schema(p).names if c.startswith("gymfg/")
                                 and c not in unstable])
        for p in sorted(root.glob("meta/episodes/**/*.parquet"))
    ]  # fmt: skip
    return frames, records


@pytest.mark.slow  # its sessions take ~30 s
def test_a_seed_reproduces_the_noise_and_the_gusts_bit_for_bit(sessions):
    out, _, log, frames = sessions["both"]
    again_out, _, again_log, again = sessions["both again"]
    (frames_ours, records_ours), (frames_theirs, records_theirs) = map(
        dataset_bits, (out, again_out)
    )
    tables = zip(frames_ours + records_ours, frames_theirs + records_theirs, strict=True)
    assert frames_ours and records_ours and all(a.equals(b) for a, b in tables)
    ours, theirs = log.complete_episodes[0], again_log.complete_episodes[0]
    assert np.array_equal(ours.steps["ego"].action, theirs.steps["ego"].action)  # the noise
    assert ours.start["gusts"] == theirs.start["gusts"]
    assert frames.episodes["gymfg/gusts"] == again.episodes["gymfg/gusts"]
    gusty = sessions["gusty"][2].complete_episodes[0]
    assert ours.start["gusts"] == gusty.start["gusts"]  # the noise draws none of the gusts'


@pytest.mark.parametrize(
    ("options", "match"),
    [
        ({"pilot": "synthetic", "noise": -0.1}, r"noise=-0\.1 must be a number >= 0"),
        ({"noise": 0.05}, r"noise=0\.05 perturbs the synthetic pilot.*add --pilot synthetic"),
        ({"gusts": "gale"}, r"gusts='gale'.*'light' or 'moderate' or 'severe'"),
    ],
)
def test_bad_noise_or_gusts_say_what_to_give(tmp_path, options, match):
    with pytest.raises(ConfigError, match=match):
        ManualConfig(out=tmp_path, **options)


def test_the_flags_are_the_manual_sessions(capsys):
    manual = vars(collect.parse_args(["manual", "--gusts", "light", "--noise", "0.2"]))
    assert (manual["gusts"], manual["noise"]) == ("light", 0.2)
    assert vars(collect.parse_args(["manual"]))["noise"] == 0.0  # a person is not perturbed
    assert "gusts" not in vars(collect.parse_args(["autopilot"]))
    with pytest.raises(SystemExit):
        collect.parse_args(["manual", "--gusts", "gale"])
    assert "invalid choice: 'gale'" in capsys.readouterr().err
    with pytest.raises(ConfigError, match="gust events are flown and logged in manual"):
        CollectConfig(gusts="light")  # an autopilot's episodes would not list theirs
