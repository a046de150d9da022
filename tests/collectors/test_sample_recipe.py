"""The bundled sample is what its recipe makes: `collect collectors/sample.toml` flies its
episodes again into a fresh folder, frame for frame the bundled ones."""

import json
from pathlib import Path

import pyarrow.parquet as pq
import pytest

from gymfg_il import collect
from gymfg_il.collectors.config import CollectConfig

ROOT = Path(__file__).resolve().parents[2]
SAMPLE = ROOT / "datasets/sample-altitude-c172p"
RECIPE = ROOT / "collectors/sample.toml"


def frames(root: Path, episodes: int) -> dict[str, list]:
    """Every data column of the first ``episodes`` episodes."""
    tables = [pq.read_table(f) for f in sorted((root / "data").rglob("*.parquet"))]
    rows = {name: [] for name in tables[0].column_names}
    for table in tables:
        for name, column in table.to_pydict().items():
            rows[name] += column
    keep = [i for i, e in enumerate(rows["episode_index"]) if e < episodes]
    return {name: [column[i] for i in keep] for name, column in rows.items()}


def episode_metadata(root: Path, episodes: int) -> dict[str, list]:
    """The gymfg/* columns of the first ``episodes`` episodes, but the log's file name (which
    carries the time the session ran)."""
    table = pq.read_table(root / "meta/episodes/chunk-000/file-000.parquet").to_pydict()
    return {
        name: column[:episodes]
        for name, column in table.items()
        if name.startswith("gymfg/") and name != "gymfg/log"
    }


def remade(out: Path) -> Path:
    assert collect.main([str(RECIPE), "--out", str(out), "--no-progress"]) == 0
    return out / "dataset"


def assert_same(remade: Path, episodes: int) -> None:
    bundled = SAMPLE / "dataset"
    assert frames(remade, episodes) == frames(bundled, episodes)
    assert episode_metadata(remade, episodes) == episode_metadata(bundled, episodes)
    info, ours = (json.loads((r / "meta/info.json").read_text()) for r in (remade, bundled))
    assert info["features"] == ours["features"] and info["fps"] == ours["fps"]


def test_the_recipe_writes_a_fresh_folder_beside_the_bundled_one():
    out = CollectConfig.from_recipe(RECIPE).out
    assert out.parent == Path("datasets") and out.name != SAMPLE.name


@pytest.mark.slow
def test_the_recipe_remakes_the_bundled_sample_exactly(tmp_path):
    root = remade(tmp_path / "sample")
    assert json.loads((root / "meta/info.json").read_text())["total_episodes"] == 20
    assert_same(root, 20)
