"""The dataset card: ``README.md`` in the dataset folder, written through LeRobot's own card
template (``datasets.lerobot_api.dataset_card``) whenever a dataset is finalised.

LeRobot writes its card only when it pushes a dataset to the Hub; a folder shared any other
way would say nothing of what it holds. The card's YAML front matter is LeRobot's (tags,
``task_categories``, the parquet ``configs``); its description says what a user of the data
needs first: that the data are simulated (JSBSim and its version), the aircraft, tasks and
sources, the DART noise, the weather, the rates, the episode and frame counts, every
observation with its unit, the actions, and how to load the folder with stock LeRobot.
Everything is read back from the dataset's own metadata (``info.json``, the task table and
the per-episode ``gymfg/*`` columns), so the card always describes what the folder holds.
"""

from __future__ import annotations

import json
from collections import Counter
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path
from typing import Any

from gymfg_il.datasets import lerobot_api as lr
from gymfg_il.datasets.provenance import PREFIX
from gymfg_il.sim.properties import ACTION_NAMES, BY_NAME

CARD = "README.md"
# units of task columns whose name carries no catalogue variable, by the name's ending
_SUFFIX_UNITS = (
    ("_rad_s", "rad/s"),
    ("_fps", "ft/s"),
    ("_kts", "kt"),
    ("_ft", "ft"),
    ("_deg", "deg"),
)
_ACTION_RANGES = {"throttle": "[0, 1]"}


def unit_of(name: str) -> str:
    """The unit of an observation entry: a catalogue variable's own; a task's target or
    error of a variable in that variable's unit, its error integral in unit x s; other task
    columns by their name's ending (``_ft``, ``_deg``, ...); "1" for counts and ratios."""
    if name in BY_NAME:
        return BY_NAME[name].unit
    for ending, scale in (("_error_integral", " s"), ("_target", ""), ("_error", "")):
        base = name.removesuffix(ending)
        if base != name and base in BY_NAME:
            unit = BY_NAME[base].unit
            return f"{unit}{scale}" if unit != "1" else (scale.strip() or "1")
    for ending, unit in _SUFFIX_UNITS:
        if name.endswith(ending):
            return unit
    return "1"


def _installed(package: str) -> str:
    try:
        return version(package)
    except PackageNotFoundError:
        return "unknown"


def _counted(values: list[Any]) -> str:
    counts = Counter(str(v) for v in values)
    return (
        ", ".join(f"{k} ({n} episode{'s' * (n != 1)})" for k, n in sorted(counts.items()))
        or "unknown"
    )


def episode_columns(root: Path) -> dict[str, list[Any]]:
    """The ``gymfg/*`` columns of every episode, in file order, read with pyarrow alone
    (LeRobot's loader of the episode table costs ~1 s on a 20-episode dataset)."""
    import pyarrow.parquet as pq

    out: dict[str, list[Any]] = {}
    for path in sorted((Path(root) / "meta" / "episodes").rglob("*.parquet")):
        names = [n for n in pq.read_schema(path).names if n.startswith(PREFIX)]
        for name, column in pq.read_table(path, columns=names).to_pydict().items():
            out.setdefault(name, []).extend(column)
    return out


def description(meta: Any, episodes: dict[str, list[Any]], repo_id: str, root: Path) -> str:
    """The card's description (Markdown) of the dataset whose metadata is ``meta`` and whose
    episodes' ``gymfg/*`` columns are ``episodes``."""
    from gymfg_il.envs.flight import FlightSpec

    features = meta.features
    names = list(features["observation.state"]["names"] or [])
    specs = [FlightSpec.from_json(s) for s in sorted(set(episodes.get("gymfg/spec", [])))]
    recorded = sorted({str(v) for v in episodes.get("gymfg/jsbsim", []) if v})
    jsbsim = ", ".join(recorded) or (
        f"version not recorded; {_installed('jsbsim')} where this card was written"
    )
    sim_hz = sorted({s.sim_hz for s in specs})
    weather = sorted(
        {
            f"turbulence {s.turbulence}, wind {s.wind_kt:g} kt"
            + (f" from {s.wind_from_deg:g} deg" if s.wind_from_deg is not None else "")
            for s in specs
        }
    )
    tasks = list(meta.tasks.index) if meta.tasks is not None else []
    kinds = episodes.get("gymfg/target_kind", [])
    aircraft = sorted(set(episodes.get("gymfg/aircraft", []))) or [str(meta.robot_type)]
    rows = [
        ("data", f"simulated: the JSBSim flight dynamics model (JSBSim {jsbsim}); "
         "no real aircraft flew"),
        ("aircraft", ", ".join(aircraft)),
        ("tasks", _counted(episodes.get("gymfg/task", [])) if episodes else "unknown"),
        ("targets", _counted(kinds) if kinds else "not recorded"),
        ("sources", _counted(episodes.get("gymfg/source", [])) if episodes else "unknown"),
        ("DART noise (action std)", _counted(episodes.get("gymfg/noise", []))
         if episodes else "unknown"),
        ("weather", "; ".join(weather) or "unknown"),
        ("starts", ", ".join(sorted(
            {"trimmed straight, level flight" if s.trimmed_starts else "untrimmed"
             for s in specs}
        )) or "unknown"),
        ("rates", f"{meta.fps} fps (agent steps); JSBSim at "
         f"{', '.join(str(h) for h in sim_hz) or 'unknown'} Hz"),
        ("episodes", f"{meta.total_episodes} ({meta.total_frames} frames)"),
        ("cameras", ", ".join(
            f"`{k}` ({f['shape'][1]}x{f['shape'][0]} video)"
            for k, f in features.items() if f.get("dtype") == "video"
        ) or "none"),
        ("card written by", f"GymFG-IL {_installed('gymfg-il')}"),
    ]  # fmt: skip
    lines = [
        "Fixed-wing flight demonstrations recorded with GymFG-IL: one frame per agent step, "
        "`observation.state` the task's observation, `action` the demonstrator's controls.",
        "",
        "| | |",
        "| --- | --- |",
        *(f"| {k} | {v} |" for k, v in rows),
        "",
        "Per-frame task strings: " + ("; ".join(f"`{t}`" for t in tasks) or "none") + ".",
        "Per-episode metadata (seed, source, target, flight spec, log) is in the `gymfg/*` "
        "columns of `meta/episodes`.",
        "",
        "### Observation (`observation.state`)",
        "",
        "| index | name | unit |",
        "| --- | --- | --- |",
        *(f"| {i} | {n} | {unit_of(n)} |" for i, n in enumerate(names)),
        "",
        "### Action (`action`)",
        "",
        "| index | name | range |",
        "| --- | --- | --- |",
        *(
            f"| {i} | {n} | {_ACTION_RANGES.get(n, '[-1, 1]')} (normalised command) |"
            for i, n in enumerate(ACTION_NAMES)
        ),
        "",
        "### Loading",
        "",
        "```python",
        "import os",
        'os.environ["HF_HUB_OFFLINE"] = "1"  # a local folder: never ask the Hub',
        "from lerobot.datasets.lerobot_dataset import LeRobotDataset",
        "",
        f"ds = LeRobotDataset({json.dumps(repo_id)}, root={json.dumps(str(root))})",
        "```",
    ]
    return "\n".join(lines)


def write_card(
    root: Path, repo_id: str = "gymfg/local", shown_root: Path | None = None, meta: Any = None
) -> Path:
    """Write (or rewrite) ``README.md`` of the dataset at ``root`` (``meta``: its finalised
    metadata, else read; ``shown_root``: the folder the loading example names, when the
    dataset is moved there); its path."""
    root = Path(root)
    meta = meta if meta is not None else lr.open_metadata(root, repo_id)
    episodes = episode_columns(root)
    tags = ["gymfg", "jsbsim", "simulation", "fixed-wing", "imitation-learning"]
    text = lr.dataset_card(meta, description(meta, episodes, repo_id, shown_root or root), tags)
    path = root / CARD
    tmp = path.with_name(f".{CARD}.tmp")
    tmp.write_text(text, encoding="utf-8")
    tmp.replace(path)
    return path
