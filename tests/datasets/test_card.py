"""The dataset card (README.md through LeRobot's template) and how targets are recorded."""

import json
import math
import os

import pyarrow.parquet as pq
import pytest
import yaml

from gymfg_il.collectors.autopilot import record_autopilot
from gymfg_il.collectors.config import CollectConfig
from gymfg_il.datasets.builder import DatasetBuilder
from gymfg_il.datasets.card import unit_of
from gymfg_il.datasets.features import dataset_features
from gymfg_il.datasets.from_logs import build_from_logs
from gymfg_il.learning.data import load_frames
from gymfg_il.recording.reader import read_log

os.environ["HF_HUB_OFFLINE"] = "1"


def collect(out, **kwargs):
    cfg = CollectConfig(episodes=2, episode_time_s=4, out=out, **kwargs)
    result = record_autopilot(cfg)
    report = build_from_logs([result.log], out / "dataset")
    return result, report


@pytest.fixture(scope="module")
def static(tmp_path_factory):
    return collect(tmp_path_factory.mktemp("card"), task="altitude", turbulence="light")


def split_card(text):
    assert text.startswith("---\n")
    head, body = text[4:].split("\n---\n", 1)
    return yaml.safe_load(head), body


def test_a_collected_dataset_has_a_card_naming_what_it_holds(static):
    result, _ = static
    root = result.log.parent.parent / "dataset"
    front, body = split_card((root / "README.md").read_text())
    assert "LeRobot" in front["tags"] and "jsbsim" in front["tags"]
    assert front["configs"][0]["data_files"] == "data/*/*.parquet"  # LeRobot's own front matter
    log = read_log(result.log)
    assert f"JSBSim {log.session['versions']['jsbsim']}" in body
    assert "| aircraft | c172p |" in body
    assert "| tasks | altitude (2 episodes) |" in body
    assert "| rates | 10 fps (agent steps); JSBSim at 120 Hz |" in body
    assert "| episodes | 2 (80 frames) |" in body
    assert "| cameras | none |" in body
    assert "| starts | trimmed straight, level flight |" in body
    assert "autopilot (2 episodes)" in body and "turbulence light" in body
    assert "| DART noise (action std) | 0.1 (2 episodes) |" in body  # the default
    names = log.aircraft("ego")["observation_names"]
    for i, name in enumerate(names):
        assert f"| {i} | {name} | {unit_of(name)} |" in body
    assert "| 10 | altitude_ft_target | ft |" in body
    assert "| 12 | altitude_ft_error_integral | ft s |" in body
    assert "| 3 | throttle | [0, 1]" in body
    assert f'root="{root}"' in body  # the final folder, not the build's work copy


def test_the_card_fills_the_templates_blanks_and_says_what_the_data_is_not(static):
    import tomllib
    from pathlib import Path

    result, _ = static
    text = (result.log.parent.parent / "dataset/README.md").read_text()
    front, body = split_card(text)
    assert "[More Information Needed]" not in text and "```bibtex" not in text
    pyproject = Path(__file__).resolve().parents[2] / "pyproject.toml"
    license = tomllib.loads(pyproject.read_text())["project"]["license"]
    assert front["license"] == license.lower() == "mit"  # the package's, as a Hub id
    assert "- **License:** mit" in body
    assert "- **Homepage:** none" in body  # a local folder: no invented address
    assert '"GymFG: A Framework with a Gym Interface for FlightGear"' in body
    assert "No BibTeX: no publication describes this dataset" in body
    limits = body[body.index("### Limitations") : body.index("### Loading")]
    log = read_log(result.log)
    assert f"computed by JSBSim ({log.session['versions']['jsbsim']})" in limits
    assert "`c172p`: JSBSim's own model of that name" in limits
    assert "`autopilot`: GymFG-IL's PID autopilot" in limits and "no person flew" in limits
    assert "without the DART noise" in limits  # the default 0.1: labels, not what flew
    assert "lasts at most 4 s" in limits and "no takeoff, taxiing or landing" in limits
    assert "(lat_deg, lon_deg, altitude_agl_ft, heading_deg," in limits  # not observed
    assert "aileron_cmd" not in limits  # the actions are in the dataset
    assert "No images." in limits
    assert "| episode ends | time limit (2 episodes) |" in body


def test_the_cards_sources_say_who_flew():
    from types import SimpleNamespace

    from gymfg_il.datasets.card import limitations

    meta = SimpleNamespace(robot_type="f15", features={"observation.images.front": {
        "dtype": "video"}})  # fmt: skip
    episodes = {
        "gymfg/aircraft": ["f15", "A320"],
        "gymfg/source": ["human", "controller+human", "synthetic", "dagger", "nobody"],
        "gymfg/noise": [0.0] * 5,
    }
    text = "\n".join(limitations(meta, episodes, [], ["lat_deg"]))
    assert "`A320`, `f15`: JSBSim's own models of those names as" in text
    assert "`human`: a person flying" in text and "who they are" in text
    assert "took over from `controller`" in text and "`intervention` column" in text
    assert "`synthetic`: a model of a person" in text and "not a person" in text
    assert "`dagger`: states a learned policy flew into" in text
    assert "`nobody`: not described here" in text
    assert "DART" not in text  # no noise: the labels are what was flown
    assert "`observation.images.front`) are drawn by GymFG-IL's headless renderer" in text
    assert "lon_deg" in text and "(lat_deg" not in text


def test_units_of_task_columns():
    assert unit_of("roll_deg_error") == "deg" and unit_of("q_rad_s") == "rad/s"
    assert unit_of("gate_distance_ft") == "ft" and unit_of("behind_slot_rate_fps") == "ft/s"
    assert unit_of("gates_left") == "1" and unit_of("airspeed_kts_error_integral") == "kt s"


def test_the_card_leaves_stock_loading_and_metadata_alone(static):
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    result, _ = static
    root = result.log.parent.parent / "dataset"
    ds = LeRobotDataset("gymfg/altitude-c172p", root=root)
    assert ds.num_episodes == 2 and len(ds) == 80
    assert not any(p.name == "README.md" for p in (root / "meta").iterdir())


def test_static_and_dynamic_targets_are_recorded_as_such(static, tmp_path):
    result, _ = static
    root = result.log.parent.parent / "dataset"
    eps = pq.read_table(root / "meta/episodes/chunk-000/file-000.parquet").to_pylist()
    log = read_log(result.log)
    for ep, logged in zip(eps, log.complete_episodes, strict=True):
        assert ep["gymfg/target_kind"] == "static" and ep["gymfg/target_plan"] == ""
        assert ep["gymfg/target"] == pytest.approx(logged.start_of("ego")["target"])
    collect(tmp_path / "d", task="roll", dynamic=True)
    eps = pq.read_table(tmp_path / "d/dataset/meta/episodes/chunk-000/file-000.parquet").to_pylist()
    for ep in eps:
        assert math.isnan(ep["gymfg/target"]) and ep["gymfg/target_kind"] == "dynamic"
        plan = json.loads(ep["gymfg/target_plan"])
        assert plan["variable"] == "roll_deg" and plan["rate"] == 5.0 and plan["hold_s"] == 20.0
        assert plan["target_range"] == [-30.0, 30.0] and abs(plan["start"]) < 1e-6
    assert "dynamic (2 episodes)" in (tmp_path / "d/dataset/README.md").read_text()
    assert len(load_frames(tmp_path / "d/dataset")) == 80  # trains as before


def test_appending_to_an_older_dataset_keeps_its_episode_columns(static, tmp_path):
    """A dataset written before target_kind, target_plan and jsbsim existed takes new
    episodes without them (LeRobot refuses episode files whose columns differ)."""
    import shutil

    result, _ = static
    log = read_log(result.log)
    old = tmp_path / "old"
    builder = DatasetBuilder(old, "gymfg/old", 10, dataset_features(log.aircraft("ego")[
        "observation_names"]))  # fmt: skip
    from gymfg_il.datasets.episode_record import episode_columns, episode_metadata

    ep = log.complete_episodes[0]
    meta = episode_metadata(log, ep, "ego")
    for key in ("target_kind", "target_plan", "jsbsim"):
        del meta[key]
    builder.add_episode(episode_columns(ep, "ego"), "hold", meta)
    builder.finalize()
    shutil.copy(result.log, tmp_path / "x.mcap")
    report = build_from_logs([tmp_path / "x.mcap"], old)
    # the copy's episode 0 is the one the dataset holds (the same frames): taken once
    assert report.added == 1 and report.total_episodes == 2
    frames = load_frames(old)
    assert len(frames) == 80 and "gymfg/target_kind" not in frames.episodes


def set_episode_column(root, name, values):
    import pyarrow as pa

    (path,) = sorted((root / "meta" / "episodes").rglob("*.parquet"))
    table = pq.read_table(path)
    at = table.schema.get_field_index(name)
    table = table.set_column(at, name, pa.array(values))
    pq.write_table(table, path)


@pytest.mark.parametrize(
    "pilots, success",
    [
        (["ann\n## Pwned\n<script>alert(1)</script>", "bob"], [0, 1]),
        (["nul\x00here", "a|b|c"], [1, 0]),
        (["x" * 2_000_000, " "], [0, 0]),
        (["ann", "ann"], [None, 1]),  # #52.2: a null verdict
        (["ann", "bob"], ["yes", "no"]),  # #52.2: verdicts that are not integers
    ],
)
def test_a_card_shows_hostile_records_escaped_and_bounded(
    static, tmp_path, capsys, pilots, success
):
    """#52.4 and #52.2: `collect repair` copied gymfg/pilot into the card's table as it was
    (a newline escaped the table into a heading and raw <script>, a NUL made the card binary,
    a 2 MB name was copied whole) and died on a null or non-integer gymfg/success."""
    import shutil

    from gymfg_il import collect as collect_cli

    result, _ = static
    root = tmp_path / "dataset"
    shutil.copytree(result.log.parent.parent / "dataset", root)
    set_episode_column(root, "gymfg/pilot", pilots)
    set_episode_column(root, "gymfg/success", success)
    (root / "README.md").unlink()
    assert collect_cli.main(["repair", str(root)]) == 0
    assert "Traceback" not in capsys.readouterr().err
    card = (root / "README.md").read_text(encoding="utf-8")
    assert "\x00" not in card and "<script>" not in card and len(card) < 20_000
    (row,) = [line for line in card.splitlines() if line.startswith("| pilots |")]
    assert row.count("|") - row.count("\\|") == 3  # the row's own three bars, no more
    assert not any(line.startswith("## Pwned") for line in card.splitlines())
