"""The dataset's features, derived from the task's observation names and the action contract.

| feature | dtype | shape | meaning |
| --- | --- | --- | --- |
| observation.state | float32 | (n,) | the task's observation, ``names`` = its variable names |
| observation.environment_state | float32 | (k,) | the task's own columns of it (targets, errors, |
| | | | integrals, gates: every name that is not aircraft state), for LeRobot's ACT and diffusion |
| action | float32 | (4,) | the demonstrator's [aileron, elevator, rudder, throttle] |
| next.reward | float32 | (1,) | reward of the step |
| next.done | bool | (1,) | the episode ended with this step |
| intervention | bool | (1,) | a human flew this step (human takeover / DAgger) |
| wall_time | float32 | (1,) | wall-clock s from the episode's first frame to this frame's input |
| | | | (beside ``timestamp``, the simulation's): only in a dataset made from logs with frames |
| | | | flown in real time (``cockpit.timing``); -1 in frames flown faster. The episode's |
| | | | ``gymfg/wall_start`` is its first frame's wall clock (Unix s) |
| observation.images.<view> | video | (H, W, 3) | camera frames, only with ``images`` |

``observation.environment_state`` repeats what ``observation.state`` already holds: LeRobot's
ACT and diffusion policies need an image or an environment state among their inputs, and with
the task's columns there (normalised: ``ENV`` in their ``normalization_mapping``) they train on
our datasets unchanged. A task with no columns of its own has no environment state. Our own
policies read ``observation.state`` only.

Plus LeRobot's own ``timestamp``, ``frame_index``, ``episode_index``, ``index``, ``task_index``
and a ``task`` string per frame.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from gymfg_il.errors import ConfigError
from gymfg_il.sim.properties import ACTION_NAMES, task_columns

OUR_KEYS = ("observation.state", "action", "next.reward", "next.done", "intervention")
ENVIRONMENT_STATE = "observation.environment_state"
WALL_TIME = "wall_time"
NO_WALL_TIME = -1.0  # a frame flown faster than real time, in a dataset with the column


def dataset_features(
    observation_names: Sequence[str],
    images: Sequence[str] = (),
    image_size: int = 128,
    wall_clock: bool = False,
) -> dict[str, dict[str, Any]]:
    """Our features for a task observing ``observation_names``, with the camera ``images``
    (views) as square video features of ``image_size`` pixels, and with ``wall_clock`` the
    ``wall_time`` of each frame (a dataset made from frames flown in real time)."""
    clock = {WALL_TIME: {"dtype": "float32", "shape": (1,), "names": None}}
    videos = {
        f"observation.images.{view}": {
            "dtype": "video",
            "shape": (image_size, image_size, 3),
            "names": ["height", "width", "channels"],
        }
        for view in images
    }
    own = [observation_names[i] for i in task_columns(observation_names)]
    environment = {
        ENVIRONMENT_STATE: {
            "dtype": "float32",
            "shape": (len(own),),
            "names": own,
        }
    }
    return {
        **videos,
        "observation.state": {
            "dtype": "float32",
            "shape": (len(observation_names),),
            "names": list(observation_names),
        },
        **(environment if own else {}),
        "action": {"dtype": "float32", "shape": (4,), "names": list(ACTION_NAMES)},
        "next.reward": {"dtype": "float32", "shape": (1,), "names": None},
        "next.done": {"dtype": "bool", "shape": (1,), "names": None},
        "intervention": {"dtype": "bool", "shape": (1,), "names": None},
        **(clock if wall_clock else {}),
    }


def check_compatible(
    existing: dict[str, dict[str, Any]], wanted: dict[str, dict[str, Any]], where: str
) -> None:
    """Appending needs identical features; say exactly what differs."""
    problems = []
    cameras = [
        sorted(k for k, v in f.items() if v.get("dtype") == "video") for f in (existing, wanted)
    ]
    if cameras[0] != cameras[1]:
        problems.append(f"camera features: existing {cameras[0]}, new {cameras[1]}")
    # datasets made before the environment state existed are appended to without it
    both = [ENVIRONMENT_STATE] if ENVIRONMENT_STATE in existing else []
    for key in (*OUR_KEYS, *both, *cameras[1]):
        have, want = existing.get(key), wanted.get(key)
        if have is None or want is None:
            where_missing = "the existing dataset" if have is None else "the new data"
            problems.append(f"{key} is missing from {where_missing}")
            continue
        for attr in ("dtype", "shape", "names"):
            a, b = have.get(attr), want.get(attr)
            if attr == "shape":
                a, b = tuple(a or ()), tuple(b or ())
            if a != b:
                problems.append(f"{key}.{attr}: existing {a!r}, new {b!r}")
    if problems:
        raise ConfigError(
            f"cannot append to the dataset at {where}: its features differ ("
            + "; ".join(problems)
            + "). Collect into another --out folder, or use the task and aircraft it was "
            "made with"
        )
