import json
import subprocess
import sys

import pytest

from gymfg_il import eval as evaluate


def test_eval_flies_the_controller_and_writes_json_and_figure1(tmp_path, capsys):
    code = evaluate.main(
        [
            "--task",
            "roll",
            "--aircraft",
            "f15",
            "--episodes",
            "2",
            "--episode-time",
            "30",
            "--json",
            str(tmp_path / "rows.json"),
            "--plots",
            str(tmp_path / "plots"),
            "--no-progress",
        ]
    )
    assert code == 0
    out = capsys.readouterr().out
    assert "controller" in out and "success" in out
    rows = json.loads((tmp_path / "rows.json").read_text())["rows"]
    assert len(rows) == 1
    row = rows[0]
    assert (row["agent"], row["task"], row["aircraft"]) == ("controller", "roll", "f15")
    assert row["episodes"] == 2 and row["seeds"] == [0, 1]
    assert row["success_rate"] == 1.0 and row["steady_state_error"] < 2
    png = tmp_path / "plots" / "roll_f15_controller.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 20_000


def test_same_seeds_give_the_same_rows(tmp_path):
    args = [
        "--task",
        "heading",
        "--dynamic",
        "--episodes",
        "2",
        "--episode-time",
        "20",
        "--no-progress",
        "--json",
    ]
    evaluate.main([*args, str(tmp_path / "a.json")])
    evaluate.main([*args, str(tmp_path / "b.json")])
    assert (tmp_path / "a.json").read_text() == (tmp_path / "b.json").read_text()


def test_bad_aircraft_is_a_clear_error(capsys):
    assert evaluate.main(["--aircraft", "c172q", "--no-progress"]) == 2
    assert "c172p" in capsys.readouterr().err


def test_help_explains_every_option():
    out = subprocess.run(
        [sys.executable, "-m", "gymfg_il.eval", "--help"],
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    for option in (
        "--task",
        "--dynamic",
        "--aircraft",
        "--episodes",
        "--seed",
        "--json",
        "--plots",
    ):
        assert option in out
    assert "Figure 1" in out


@pytest.mark.slow
def test_a_policy_flies_at_its_own_rate_and_the_rows_say_so(tmp_path, capsys):
    from gymfg_il.collectors.autopilot import collect_autopilot
    from gymfg_il.collectors.config import CollectConfig
    from gymfg_il.evaluation.config import EvalConfig
    from gymfg_il.evaluation.runner import run_eval
    from gymfg_il.learning.bc import TrainConfig, train_bc

    demo = CollectConfig(
        task="roll", episodes=3, episode_time_s=4, agent_hz=30, seed=1000, out=tmp_path / "demo"
    )
    collect_autopilot(demo)
    policy = train_bc(
        TrainConfig(dataset=tmp_path / "demo" / "dataset", out=tmp_path / "p", epochs=2)
    ).out
    assert json.loads((policy / "config.json").read_text())["spec"]["agent_hz"] == 30
    rows_json = tmp_path / "rows.json"
    args = ["--policy", str(policy), "--episodes", "2", "--no-progress"]
    assert evaluate.main([*args, "--json", str(rows_json)]) == 0
    assert "roll on c172p at 30 Hz" in capsys.readouterr().out
    rows = json.loads(rows_json.read_text())["rows"]
    assert [r["agent"] for r in rows] == ["controller", "policy:p"]
    for row in rows:
        assert (row["agent_hz"], row["task"], row["aircraft"]) == (30, "roll", "c172p")
        assert row["spec"] == demo.flight().to_dict() and row["episode_time_s"] == 4
    run = run_eval(EvalConfig(policy=[policy], episodes=1))
    assert all(len(t[0].rewards) == 4 * 30 for t in run.traces.values())  # 30 steps a second
    # another rate is refused: the policy learnt its actions at 30 Hz
    assert evaluate.main([*args, "--agent-hz", "10"]) == 2
    assert "trained at 30 Hz" in capsys.readouterr().err
    # another aircraft is what the user asked for: flown, and said so
    assert evaluate.main([*args, "--aircraft", "f15", "--json", str(rows_json)]) == 0
    assert "aircraft='f15'" in capsys.readouterr().err
    assert {r["aircraft"] for r in json.loads(rows_json.read_text())["rows"]} == {"f15"}
    # beside the synthetic pilot it is set against the pilot too, not only the controller
    assert evaluate.main([*args, "--pilot", "synthetic"]) == 0
    out = capsys.readouterr().out
    assert "policy:p / controller: return" in out
    assert "policy:p / pilot:synthetic-keyboard: return" in out


def test_a_policy_without_a_single_flight_still_flies_at_its_datasets_rate():
    from pathlib import Path

    from gymfg_il.envs.options import FlightOptions
    from gymfg_il.errors import ConfigError
    from gymfg_il.evaluation.plan import flight_for
    from gymfg_il.evaluation.plots import primary_control

    meta = {"spec": None, "fps": 30, "spec_note": "its episodes were flown in 2 flights"}
    with pytest.raises(ConfigError, match=r"2 flights.*--task and --aircraft"):
        flight_for({Path("p"): meta})
    flight, _ = flight_for({Path("p"): meta}, FlightOptions(task="roll", aircraft="f15"))
    assert (flight.agent_hz, flight.task, flight.aircraft) == (30, "roll", "f15")
    with pytest.raises(ConfigError, match=r"trained at \[30\] Hz"):
        flight_for({Path("p"): meta}, FlightOptions(task="roll", aircraft="f15", agent_hz=10))
    assert primary_control("beta_deg") == 2 and primary_control("my_own_variable") == 1


def test_a_dataset_whose_episodes_differ_only_in_length_keeps_its_flight():
    import numpy as np

    from gymfg_il.envs import FlightSpec
    from gymfg_il.learning.data import Frames

    short, long = (FlightSpec.solo(task="roll", episode_time_s=t) for t in (20, 60))
    frames = Frames(
        obs=np.zeros((2, 1), np.float32),
        action=np.zeros((2, 4), np.float32),
        episode=np.arange(2),
        frame=np.zeros(2, np.int64),
        observation_names=["x"],
        action_names=list("abcd"),
        fps=10,
        obs_stats={},
        action_stats={},
        episodes={"gymfg/spec": [short.to_json(), long.to_json()], "gymfg/callsign": ["ego"] * 2},
    )
    assert frames.flight() == (long, "")
    frames.episodes["gymfg/spec"][0] = FlightSpec.solo(task="roll", agent_hz=20).to_json()
    flight, why = frames.flight()
    assert flight is None and "2 different flights" in why


def test_a_dataset_whose_episodes_differ_only_in_weather_keeps_its_first_episodes_flight():
    from gymfg_il.envs import FlightSpec
    from gymfg_il.learning.frames import flight_of

    calm = FlightSpec.solo(task="heading")
    rough = calm.replace(turbulence="moderate", wind_kt=10.0)
    specs = [calm.to_json(), rough.to_json(), calm.to_json()]
    flight, why = flight_of({"gymfg/spec": specs})
    assert flight == calm
    assert "2 weathers (no turbulence, 0 kt wind; moderate turbulence, 10 kt wind)" in why
    assert flight_of({"gymfg/spec": specs[1:]})[0] == rough  # the first episode's, in order
    specs.append(calm.replace(task="roll", turbulence="moderate").to_json())
    flight, why = flight_of({"gymfg/spec": specs})
    assert flight is None and "2 different flights" in why  # heading and roll
    gusty = calm.replace(gusts="moderate").to_json()
    assert "moderate gusts" in flight_of({"gymfg/spec": [calm.to_json(), gusty]})[1]
