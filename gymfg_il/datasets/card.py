"""The dataset card: ``README.md`` in the dataset folder, written through LeRobot's own card
template (``datasets.lerobot_api.dataset_card``) whenever a dataset is finalised.

LeRobot writes its card only when it pushes a dataset to the Hub; a folder shared any other
way would say nothing of what it holds. The card's YAML front matter is LeRobot's (tags,
``task_categories``, the parquet ``configs``); its description says what a user of the data
needs first: that the data are simulated (JSBSim and its version), the aircraft, tasks and
sources, the DART noise, the weather, the rates, the episode and frame counts, every
observation with its unit, the actions, how to load the folder with stock LeRobot, and its
limitations (what the data is not: simulated flight of JSBSim's models, who or what flew, what
was not recorded). The template's homepage, paper, license and citation say what is true of a
local dataset: no homepage, GymFG-IL's license (the package's own), the paper whose design
GymFG-IL builds on, and no BibTeX (no publication describes the dataset). Everything is read
back from the dataset's own metadata (``info.json``, the task table and
the per-episode ``gymfg/*`` columns), so the card always describes what the folder holds.
"""

from __future__ import annotations

import json
from importlib.metadata import PackageNotFoundError, metadata
from pathlib import Path
from typing import Any

from gymfg_il.datasets import lerobot_api as lr
from gymfg_il.datasets.card_facts import (
    PACKAGE,
    aircraft,
    as_float,
    cell,
    code,
    facts,
    installed,
    jsbsim,
)
from gymfg_il.datasets.provenance import PREFIX
from gymfg_il.sim.properties import ACTION_NAMES, BY_NAME, NAMES

CARD = "README.md"
PAPER = (
    'none describes this dataset; GymFG-IL builds on the design of "GymFG: A Framework with '
    'a Gym Interface for FlightGear" (A. Wood, A. Sydney, P. Chin, B. Thapa, R. Ross)'
)
HOMEPAGE = "none: a local dataset folder, not published"
# who or what each recorded source is (``gymfg/source``; a person taking over from an
# assistant is ``ASSIST+human``)
SOURCES = {
    "autopilot": "GymFG-IL's PID autopilot (`gymfg_il.controllers.autopilot`); no person flew",
    "human": "a person flying through GymFG-IL's manual controls (keyboard, mouse, joystick or "
    "a FlightGear cockpit); who they are and how much they have flown is not recorded",
    "synthetic": "a model of a person flying through the manual controls' keyboard, mouse or "
    "joystick events (`gymfg_il.manual.synthetic`), not a person",
    "dagger": "states a learned policy flew into, labelled by the task's autopilot: `action` is "
    "the autopilot's label, not what was flown",
}
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


def _license() -> str | None:
    """GymFG-IL's license as a Hub license id (``mit``), from the installed package's
    metadata (pyproject's ``project.license``); None when the package is not installed."""
    try:
        meta = metadata(PACKAGE)
    except PackageNotFoundError:
        return None
    found = meta.get("License-Expression") or meta.get("License")
    return str(found).lower() if found else None


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


def _literal(text: str) -> str:
    """``text`` as a Python string literal that cannot close the card's code block."""
    return json.dumps(text).replace("`", "\\u0060")


def _source(name: str) -> str:
    assist, _, person = name.rpartition("+")
    if assist and person in SOURCES:
        return (
            f"{SOURCES[person]}; they took over from {code(assist)} when they chose (the "
            "`intervention` column marks the frames they flew)"
        )
    return SOURCES.get(name, "not described here (a source GymFG-IL does not know)")


def limitations(
    meta: Any, episodes: dict[str, list[Any]], specs: list[Any], names: list[str]
) -> list[str]:
    """The card's Limitations section (Markdown lines): what the data is not, read from the
    dataset (``names``: the observation's)."""
    flown = aircraft(meta, episodes)
    sources = sorted({str(s) for s in episodes.get("gymfg/source", []) if s})
    noisy = any(as_float(n, 0.0) > 0 for n in episodes.get("gymfg/noise", []))
    longest = max((s.episode_time_s for s in specs), default=None)
    # the catalogue's commands are the flown actions, its clock the frame's timestamp
    unobserved = [n for n in NAMES if n not in names and not n.endswith(("_cmd", "_time_s"))]
    cameras = [k for k, f in meta.features.items() if f.get("dtype") == "video"]
    who = [f"  - {code(s)}: {_source(s)}." for s in sources] or ["  - not recorded."]
    lines = [
        "### Limitations",
        "",
        f"- **Simulated flight only.** Every frame was computed by JSBSim "
        f"({jsbsim(episodes)}); no real aircraft or sensor is behind it. Observations "
        "are the simulator's exact values: no sensor noise, bias, latency or failure.",
        f"- **Aircraft models.** {', '.join(map(code, flown))}: JSBSim's own "
        + (
            "model of that name as the `jsbsim` package ships it: what it computes"
            if len(flown) == 1
            else "models of those names as the `jsbsim` package ships them: what they compute"
        )
        + ", not flight-test data of the aircraft. No other aircraft is in the data.",
        "- **Who flew.**",
        *who,
    ]
    if noisy:
        lines.append(
            "- **Actions are labels.** `action` is the demonstrator's command without the DART "
            "noise that was added to what was flown; the flown commands are only in the "
            "session's MCAP logs."
        )
    lines += [
        "- **Weather.** JSBSim's standard atmosphere with the turbulence and steady wind of "
        "the table; no precipitation, icing, cloud or change of temperature and pressure.",
        "- **Flight regime.** Every episode starts in the air (the table's starts)"
        + (f" and lasts at most {longest:g} s" if longest is not None else "")
        + ": no takeoff, taxiing or landing; flying below the task's floor above the ground "
        "counts as a crash and ends it.",
        "- **Not recorded.** "
        + (
            f"The aircraft state the observation leaves out ({', '.join(unobserved)}) is not "
            "in the dataset (the session's MCAP logs, where kept, hold it per step). "
            if unobserved
            else ""
        )
        + "Nothing of JSBSim's model beyond GymFG-IL's state catalogue (engine, fuel, "
        "surface positions, loads) is recorded anywhere. "
        + (
            f"Camera features ({', '.join(f'`{c}`' for c in cameras)}) are drawn by "
            "GymFG-IL's headless renderer from the simulated state, not filmed."
            if cameras
            else "No images."
        ),
    ]
    return lines


def description(meta: Any, episodes: dict[str, list[Any]], repo_id: str, root: Path) -> str:
    """The card's description (Markdown) of the dataset whose metadata is ``meta`` and whose
    episodes' ``gymfg/*`` columns are ``episodes``."""
    from gymfg_il.envs.flight import FlightSpec

    names = list(meta.features["observation.state"]["names"] or [])
    specs = [FlightSpec.from_json(s) for s in sorted(set(episodes.get("gymfg/spec", [])))]
    tasks = list(meta.tasks.index) if meta.tasks is not None else []
    lines = [
        "Fixed-wing flight demonstrations recorded with GymFG-IL: one frame per agent step, "
        "`observation.state` the task's observation, `action` the demonstrator's controls.",
        "",
        "| | |",
        "| --- | --- |",
        *(f"| {k} | {v} |" for k, v in facts(meta, episodes, specs)),
        "",
        "Per-frame task strings: " + ("; ".join(cell(t, 200) for t in tasks) or "none") + ".",
        "Per-episode metadata (seed, source, target, flight spec, log) is in the `gymfg/*` "
        "columns of `meta/episodes`.",
        "",
        "### Observation (`observation.state`)",
        "",
        "| index | name | unit |",
        "| --- | --- | --- |",
        *(f"| {i} | {cell(n)} | {cell(unit_of(n))} |" for i, n in enumerate(names)),
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
        *limitations(meta, episodes, specs, names),
        "",
        "### Loading",
        "",
        "```python",
        "import os",
        'os.environ["HF_HUB_OFFLINE"] = "1"  # a local folder: never ask the Hub',
        "from lerobot.datasets.lerobot_dataset import LeRobotDataset",
        "",
        f"ds = LeRobotDataset({_literal(repo_id)}, root={_literal(str(root))})",
        "```",
    ]
    return "\n".join(lines)


def card_text(
    root: Path, repo_id: str = "gymfg/local", shown_root: Path | None = None, meta: Any = None
) -> str:
    """The card of the dataset at ``root`` (``meta``: its finalised metadata, else read;
    ``shown_root``: the folder the loading example names, when the dataset is moved there)."""
    root = Path(root)
    meta = meta if meta is not None else lr.open_metadata(root, repo_id)
    episodes = episode_columns(root)
    tags = ["gymfg", "jsbsim", "simulation", "fixed-wing", "imitation-learning"]
    return lr.dataset_card(
        meta,
        description(meta, episodes, repo_id, shown_root or root),
        tags,
        license=_license(),
        homepage=HOMEPAGE,
        paper=PAPER,
        citation=(
            "No BibTeX: no publication describes this dataset. To say how it was made, name "
            f"GymFG-IL {installed(PACKAGE)} and the JSBSim version above."
        ),
    )


def write_card(
    root: Path, repo_id: str = "gymfg/local", shown_root: Path | None = None, meta: Any = None
) -> Path:
    """Write (or rewrite) ``README.md`` of the dataset at ``root`` (``card_text``); its
    path."""
    text = card_text(root, repo_id, shown_root, meta)
    path = Path(root) / CARD
    tmp = path.with_name(f".{CARD}.tmp")
    tmp.write_text(text, encoding="utf-8")
    tmp.replace(path)
    return path
