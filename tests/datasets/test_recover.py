"""`collect recover` checks the dataset against the logs and sets aside what it cannot use
(red team findings #32.10, 12, 14, 15): the logs are the truth."""

import json
import os
import shutil
import subprocess
import sys

import numpy as np
import pyarrow.parquet as pq
import pytest

from gymfg_il import collect
from gymfg_il.collectors.autopilot import collect_autopilot
from gymfg_il.collectors.config import CollectConfig
from gymfg_il.recording.reader import read_log

EPISODES, STEPS = 4, 60


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    out = tmp_path_factory.mktemp("recover") / "s"
    cfg = CollectConfig(task="roll", episodes=EPISODES, episode_time_s=6, seed=3, out=out)
    result, report = collect_autopilot(cfg)
    assert report is not None and report.total_episodes == EPISODES
    return out, result.log


@pytest.fixture
def copy(session, tmp_path):
    out, _ = session
    shutil.copytree(out, tmp_path / "s")
    return tmp_path / "s"


def frames(root):
    table = pq.read_table(next((root / "data").rglob("*.parquet")))
    return table.to_pydict()


def log_states(folder):
    """observation.state of every episode, as the log holds it (float32, in order)."""
    (path,) = sorted((folder / "logs").glob("*.mcap"))
    return np.concatenate(
        [e.steps["ego"].observation.astype(np.float32) for e in read_log(path).complete_episodes]
    )


def test_damage_inside_a_data_page_is_found_and_rebuilt(copy, capsys):
    """#32.10: flipped bytes inside a data page of the data file read back as other values;
    recover said "4 episodes (+0)" and training read them."""
    data = next((copy / "dataset" / "data").rglob("*.parquet"))
    raw = data.read_bytes()
    truth = log_states(copy)
    column = (
        pq.ParquetFile(data)
        .metadata.row_group(0)
        .column(pq.ParquetFile(data).schema_arrow.get_field_index("observation.state"))
    )
    start = column.data_page_offset
    damaged = None
    for offset in range(start + 64, start + column.total_compressed_size - 64, 97):
        bad = bytearray(raw)
        bad[offset] ^= 0x20
        data.write_bytes(bytes(bad))
        try:  # a flip that still reads, as other numbers
            states = np.array(pq.read_table(data)["observation.state"].to_pylist(), np.float32)
        except Exception:
            continue
        if states.shape == truth.shape and not np.array_equal(states, truth):
            damaged = offset
            break
    assert damaged is not None
    assert collect.main(["recover", str(copy)]) == 0
    out = capsys.readouterr().out
    assert "rebuilt from the logs" in out and "observation.state" in out
    assert np.array_equal(np.array(frames(copy / "dataset")["observation.state"]), truth)
    (aside,) = copy.glob("dataset.broken-*")  # the damaged copy is kept, never deleted
    assert (next((aside / "data").rglob("*.parquet"))).read_bytes() == bytes(bad)


def test_a_value_that_differs_from_the_log_is_rebuilt(copy, capsys):
    """#32.10 without any checksum to help: a well-formed data file whose altitude is not
    what the log says."""
    data = next((copy / "dataset" / "data").rglob("*.parquet"))
    table = pq.read_table(data)
    states = np.array(table["observation.state"].to_pylist(), np.float32)
    states[70, 0] = -0.0011
    import pyarrow as pa

    column = pa.FixedSizeListArray.from_arrays(pa.array(states.ravel()), states.shape[1])
    index = table.schema.get_field_index("observation.state")
    pq.write_table(table.set_column(index, table.schema.field(index), column), data)
    assert collect.main(["recover", str(copy)]) == 0
    out = capsys.readouterr().out
    assert "episode 1" in out and "observation.state" in out
    assert np.array_equal(np.array(frames(copy / "dataset")["observation.state"]), log_states(copy))


def test_a_dataset_whose_features_were_damaged_is_set_aside_and_rebuilt(copy, capsys):
    """#32.15: info.json's observation.state shape changed; recover refused to append."""
    info = copy / "dataset" / "meta" / "info.json"
    record = json.loads(info.read_text())
    record["features"]["observation.state"]["shape"] = [99]
    info.write_text(json.dumps(record))
    assert collect.main(["recover", str(copy)]) == 0
    assert "rebuilt from the logs" in capsys.readouterr().out
    rebuilt = json.loads(info.read_text())["features"]["observation.state"]
    assert rebuilt["shape"] == [len(rebuilt["names"])]
    assert len(frames(copy / "dataset")["index"]) == EPISODES * STEPS
    assert list(copy.glob("dataset.broken-*"))


def test_a_dataset_whose_feature_names_were_damaged_is_rebuilt(copy, capsys):
    info = copy / "dataset" / "meta" / "info.json"
    record = json.loads(info.read_text())
    record["features"]["observation.state"]["names"][0] = "roll_deh"
    info.write_text(json.dumps(record))
    assert collect.main(["recover", str(copy)]) == 0
    assert "rebuilt from the logs" in capsys.readouterr().out
    record = json.loads(info.read_text())
    assert record["features"]["observation.state"]["names"][0] != "roll_deh"


def test_a_copied_log_adds_nothing(copy, capsys):
    """#32.14: the same log under another name doubled the dataset (8 episodes, not 4)."""
    (log,) = (copy / "logs").glob("*.mcap")
    shutil.copy(log, copy / "logs" / "aaa-copy.mcap")  # sorts before the original
    assert collect.main(["recover", str(copy)]) == 0
    out = capsys.readouterr().out
    assert f"{EPISODES} episodes (+0" in out
    assert "aaa-copy.mcap" in out and f"the same episodes as {log.name}" in out
    shutil.rmtree(copy / "dataset")  # and rebuilt from both logs: each episode once
    assert collect.main(["recover", str(copy)]) == 0
    assert f"{EPISODES} episodes (+{EPISODES}" in capsys.readouterr().out


def test_a_dataset_that_holds_an_episode_twice_is_rebuilt(copy, capsys):
    """What the old recover made of a copied log: every episode twice."""
    from gymfg_il.datasets.builder import DatasetBuilder
    from gymfg_il.datasets.episode_record import episode_columns, episode_metadata
    from gymfg_il.datasets.features import dataset_features

    (log,) = (copy / "logs").glob("*.mcap")
    twin = copy / "logs" / "zz-copy.mcap"
    shutil.copy(log, twin)
    shutil.rmtree(copy / "dataset")
    first = read_log(log)
    names = first.aircraft("ego")["observation_names"]
    builder = DatasetBuilder(copy / "dataset", "gymfg/twice", 10, dataset_features(names))
    for lg in (first, read_log(twin)):
        for ep in lg.complete_episodes:
            task = lg.aircraft("ego")["task_description"]
            builder.add_episode(episode_columns(ep, "ego"), task, episode_metadata(lg, ep, "ego"))
    builder.finalize()
    assert collect.main(["recover", str(copy)]) == 0
    out = capsys.readouterr().out
    assert f"{EPISODES} episodes" in out and "rebuilt from the logs" in out
    assert "the same episode as dataset episode 0" in out


@pytest.mark.slow
def test_unreadable_logs_are_set_aside_and_the_rest_rebuilt(copy, tmp_path):
    """#32.12: 4,000 random bytes, a FIFO and a symlink to /dev/zero beside a good log
    stopped the whole folder (exit 2, or a hang); each is set aside, named, and the rest
    rebuilt. Run as a process: before, the FIFO blocked recover for ever."""
    logs = copy / "logs"
    (log,) = logs.glob("*.mcap")
    (logs / "random.mcap").write_bytes(np.random.default_rng(0).bytes(4000))
    os.mkfifo(logs / "fifo.mcap")
    (logs / "zero.mcap").symlink_to("/dev/zero")
    outside = tmp_path / "elsewhere.mcap"
    shutil.copy(log, outside)
    (logs / "outside.mcap").symlink_to(outside)
    shutil.rmtree(copy / "dataset")
    env = {**os.environ, "HF_HUB_OFFLINE": "1"}

    def collect_(*argv):
        return subprocess.run(
            [sys.executable, "-m", "gymfg_il.collect", *argv],
            capture_output=True,
            text=True,
            env=env,
            timeout=600,  # a deadline for the FIFO's old hang, not a timing
        )

    replayed = collect_("replay", str(copy))  # names them too, and re-flies the good log
    assert replayed.returncode == 1 and "could not read fifo.mcap" in replayed.stderr
    assert replayed.stdout.count("identical") == EPISODES
    run = collect_("recover", str(copy))
    assert run.returncode == 1, run.stderr
    text = run.stdout + run.stderr
    assert f"{EPISODES} episodes (+{EPISODES}" in text
    for name in ("random.mcap", "fifo.mcap", "zero.mcap", "outside.mcap"):
        assert f"set aside {name}" in text
        assert not (logs / name).exists(follow_symlinks=False)
        assert (logs / f"{name}.set-aside").exists(follow_symlinks=False)
    assert "not an MCAP file" in text and "a FIFO" in text and "symbolic link" in text
    assert log.exists() and outside.exists()  # nothing deleted, nothing outside touched
    # the next recover finds a clean folder
    again = collect_("recover", str(copy))
    assert again.returncode == 0, again.stderr


def set_episode_column(root, name, values):
    """Write ``values`` (one per episode) as the episode table's column ``name``."""
    import pyarrow as pa

    (path,) = sorted((root / "meta" / "episodes").rglob("*.parquet"))
    table = pq.read_table(path)
    index = table.schema.get_field_index(name)
    table = table.set_column(index, name, pa.array(values))
    pq.write_table(table, path)


@pytest.mark.parametrize(
    "name, values",
    [
        ("gymfg/success", [1] * EPISODES),
        ("gymfg/pilot", ["mallory"] * EPISODES),
        ("gymfg/wall_start", [float("nan")] * EPISODES),
        ("gymfg/wall_start", ["yesterday"] * EPISODES),
        ("gymfg/seed", [7] * EPISODES),
    ],
)
def test_an_episode_record_that_differs_from_the_log_is_rebuilt(copy, capsys, name, values):
    """#52.1: recover compared frames only; every episode's gymfg/success set to 1 (or its
    pilot, its wall-clock start) was kept ("took 4 episodes, 0 new") and `train bc --select
    success` trained on the failed episodes. The record comes from the log like the frames."""
    from gymfg_il.datasets.card import episode_columns as records

    truth = records(copy / "dataset")
    assert repr(truth[name]) != repr(values)  # the tampering changes something
    set_episode_column(copy / "dataset", name, values)
    assert collect.main(["recover", str(copy)]) == 0
    out = capsys.readouterr().out
    assert "rebuilt from the logs" in out and f"{name} is " in out
    assert records(copy / "dataset") == truth
    (aside,) = copy.glob("dataset.broken-*")
    assert repr(records(aside)[name]) == repr(values)  # kept aside as it was found (NaN too)


def test_a_mark_given_after_the_build_is_taken_in_place(copy, capsys):
    """A person marks an episode after the session's dataset took it: the log's mark is the
    truth, and the dataset takes it in place (not set aside as damaged)."""
    from gymfg_il.datasets.card import episode_columns as records

    truth = records(copy / "dataset")
    set_episode_column(copy / "dataset", "gymfg/mark", ["failure"] * EPISODES)
    assert collect.main(["recover", str(copy)]) == 0
    assert "rebuilt" not in capsys.readouterr().out
    assert records(copy / "dataset") == truth
    assert not list(copy.glob("dataset.broken-*"))


def test_a_lerobot_merge_of_two_sessions_recovers_from_both_logs(session, tmp_path, capsys):
    """#52.11: LeRobot's merge_datasets output (plain list columns, not fixed-size ones) in
    a session folder holding both sessions' logs: recover died in verify.digest (ValueError).
    Its frames and records are the logs', so it is kept as it is."""
    from lerobot.datasets.dataset_tools import merge_datasets
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    first, _ = session
    cfg = CollectConfig(task="roll", episodes=2, episode_time_s=6, seed=50, out=tmp_path / "b")
    collect_autopilot(cfg)
    parts = [
        LeRobotDataset(f"gymfg/{k}", root=f / "dataset") for k, f in enumerate([first, cfg.out])
    ]
    merged = tmp_path / "m"
    merge_datasets(parts, output_repo_id="gymfg/m", output_dir=merged / "dataset")
    (merged / "logs").mkdir()
    for folder in (first, cfg.out):
        for log in (folder / "logs").glob("*.mcap"):
            shutil.copy(log, merged / "logs" / log.name)
    capsys.readouterr()
    assert collect.main(["recover", str(merged)]) == 0
    out = capsys.readouterr().out
    assert f"{EPISODES + 2} episodes (+0" in out and "rebuilt" not in out


def test_after_lerobots_delete_episodes_recover_says_what_it_did(copy, capsys):
    """#52.12: after `lerobot-edit-dataset delete_episodes` (which drops the gymfg/* records)
    recover added the deleted episode back and said both that the logs gave the same episodes
    as the dataset's and that no log held the dataset's episodes. Now the edited episodes are
    known by their frames, and the episode it adds back is said to be added back."""
    from lerobot.datasets.dataset_tools import delete_episodes
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    edited = copy / "edited"
    delete_episodes(LeRobotDataset("gymfg/s", root=copy / "dataset"), [0], output_dir=edited)
    shutil.rmtree(copy / "dataset")
    edited.rename(copy / "dataset")
    capsys.readouterr()
    assert collect.main(["recover", str(copy)]) == 0
    said = capsys.readouterr()
    assert f"{EPISODES} episodes (+1" in said.out
    assert f"{EPISODES - 1} dataset episode(s) record no log" in said.out
    assert "added back" in said.out and "collect repair" in said.out
    assert "no log" not in said.err


def test_what_each_log_gave_names_its_episodes_and_their_seeds(copy, capsys):
    """#53: "took 4 episode(s) (0-3; ...)" read as eval's seeds 0..15; the numbers are the
    log's own episodes, and their seeds are said beside them."""
    assert collect.main(["recover", str(copy)]) == 0
    assert f"(log episodes 0-{EPISODES - 1}, seeds 3-{3 + EPISODES - 1}; 0 new)" in (
        capsys.readouterr().out
    )


@pytest.mark.timeout(60)
@pytest.mark.parametrize(
    "make",
    [
        pytest.param(os.mkfifo, id="fifo"),
        pytest.param(lambda p: p.symlink_to("/dev/zero"), id="dev-zero"),
    ],
)
@pytest.mark.parametrize("which", ["data", "meta/episodes", "meta/info.json", "meta/stats.json"])
def test_recover_refuses_a_dataset_file_that_is_not_a_file(copy, capsys, which, make):
    """#52.7: a FIFO in the place of a dataset file hung recover (its open waits for a
    writer), a link to /dev/zero read until memory ran out; now one line names the file, and
    the dataset is left as it is."""
    root = copy / "dataset"
    if which in ("data", "meta/episodes"):
        path = next((root / which).rglob("*.parquet"))
    else:
        path = root / which
    path.unlink()
    make(path)
    before = sorted(p.name for p in copy.iterdir())
    assert collect.main(["recover", str(copy)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and "Traceback" not in err, err
    assert str(path.relative_to(root)) in err and "not a regular file" in err, err
    assert sorted(p.name for p in copy.iterdir()) == before
    assert os.path.lexists(path)


def test_statistics_that_are_not_numbers_are_rebuilt(copy, capsys):
    """#52.11: a NaN in meta/stats.json survived recover, while train bc refused the dataset
    and advised running recover: the advice looped."""
    from gymfg_il import train

    stats = copy / "dataset" / "meta" / "stats.json"
    record = json.loads(stats.read_text())
    record["observation.state"]["std"][2] = float("nan")
    stats.write_text(json.dumps(record))
    assert collect.main(["recover", str(copy)]) == 0
    out = capsys.readouterr().out
    assert "rebuilt from the logs" in out and "std of" in out
    argv = ["bc", "--dataset", str(copy), "--epochs", "1", "--hidden", "16", "--no-progress"]
    assert train.main([*argv, "--out", str(copy / "policy")]) == 0
