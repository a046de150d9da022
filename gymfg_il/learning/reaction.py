"""A pilot's reaction time, from their own demonstrations, and BC that answers for it.

A pilot closes its attitude loops on the stick: the elevator answers the pitch it sees, the
ailerons the bank. Over a pilot's episodes, the correlation of each attitude's change with the
stick's change k steps later peaks where the stick answers it: at the pilot's delay, its
reaction time and what its input device adds. The estimate (``reaction_steps``) is the lag at
which the two correlations, summed (pitch with the elevator; the bank against the ailerons,
since a bank to the right is answered with left aileron), peak, within ``MAX_S``. Changes, not
values, are correlated: a value's slow drift would correlate at every lag.

On the synthetic pilot (docs/results/capture.md) it lands on the pilot's true delay; the
demonstrations of an autopilot, which answers at once, give 0 or 1.

``train bc --shift N`` pairs each observation with the action taken N steps later (the last N
frames of an episode have no such action and are left out), so the policy answers at once
what the pilot answered late; ``--shift auto`` uses each pilot's own estimate
(``gymfg/pilot``, else the episode's source) on the episodes a person or the synthetic pilot
flew.
"""

from __future__ import annotations

import logging
from typing import TYPE_CHECKING, Any

import numpy as np

from gymfg_il.errors import ConfigError

if TYPE_CHECKING:
    from gymfg_il.learning.frames import Frames

log = logging.getLogger(__name__)

MAX_S = 1.0  # the longest reaction time looked for
# (attitude entry, the action that answers it, the sign of its answer)
ATTITUDE_LOOPS = (("pitch_deg", 1, 1.0), ("roll_deg", 0, -1.0))
PERSONS = ("human", "synthetic")  # the sources whose episodes --shift auto shifts


def _standard(x: np.ndarray) -> np.ndarray:
    return (x - x.mean()) / (x.std() + 1e-12)


def reaction_steps(frames: Frames, episodes: list[int] | None = None) -> int | None:
    """The lag (agent steps) at which the stick answers the attitude over ``episodes`` (all
    of ``frames`` by default; module docstring); None where the observation holds no attitude
    or the episodes are too short to tell."""
    names = list(frames.observation_names)
    loops = [(names.index(n), a, sign) for n, a, sign in ATTITUDE_LOOPS if n in names]
    lags = max(1, round(MAX_S * frames.fps))
    chosen = np.unique(frames.episode) if episodes is None else np.asarray(episodes)
    total, counted = np.zeros(lags + 1), 0
    for e in chosen:
        at = np.flatnonzero(frames.episode == e)
        if len(at) < 4 * (lags + 1):
            continue
        obs, action = frames.obs[at].astype(np.float64), frames.action[at].astype(np.float64)
        for j, a, sign in loops:
            seen, moved = np.diff(obs[:, j]), np.diff(action[:, a])
            if seen.std() == 0 or moved.std() == 0:
                continue  # a still attitude, or hands off: nothing answered
            seen, moved = _standard(seen), _standard(moved)
            n = len(seen)
            total += sign * np.array([seen[: n - k] @ moved[k:] / (n - k) for k in range(lags + 1)])
            counted += 1
    if not counted:
        return None
    return int(np.argmax(total))


def pilot_of(frames: Frames) -> dict[int, str]:
    """Each episode's pilot: its ``gymfg/pilot``, else its source."""
    eps = frames.episodes
    sources = [str(s) for s in eps.get("gymfg/source", [])]
    ids = eps.get("episode_index", list(range(len(sources))))
    pilots = eps.get("gymfg/pilot") or [""] * len(ids)
    return {int(i): str(p) or s for i, p, s in zip(ids, pilots, sources, strict=True)}


def reactions(frames: Frames) -> dict[str, int | None]:
    """Each pilot's reaction (``reaction_steps`` over their episodes) among the episodes a
    person or the synthetic pilot flew."""
    eps = frames.episodes
    ids = eps.get("episode_index", list(range(len(eps.get("gymfg/source", [])))))
    source = dict(zip(ids, [str(s) for s in eps.get("gymfg/source", [])], strict=True))
    by_pilot: dict[str, list[int]] = {}
    present = set(np.unique(frames.episode).tolist())  # a selection keeps every episode's row
    for e, pilot in pilot_of(frames).items():
        if source.get(e) in PERSONS and e in present:
            by_pilot.setdefault(pilot, []).append(e)
    return {pilot: reaction_steps(frames, found) for pilot, found in sorted(by_pilot.items())}


def shifted(frames: Frames, shift: str) -> tuple[Frames, dict[str, Any]]:
    """``frames`` with each observation paired with the action ``shift`` steps later (a
    number, for every episode; ``auto``: each pilot's estimate, on the episodes a person or
    the synthetic pilot flew), and what was shifted by how much, for the run's record."""
    if shift == "auto":
        sources = frames.episodes.get("gymfg/source")
        if not sources or len(sources) != len(frames.episodes.get("episode_index", sources)):
            raise ConfigError(
                "--shift auto estimates each pilot's reaction from the episodes' records "
                "(gymfg/source, gymfg/pilot), which this dataset lacks (LeRobot's dataset "
                "editing drops them): restore them with python -m gymfg_il.collect repair "
                "EDITED --source ORIGINAL, or give the steps (--shift N)"
            )
        found = reactions(frames)
        pilots = pilot_of(frames)
        steps = {e: found.get(pilots[e]) or 0 for e in pilots}
        for pilot, lag in found.items():
            said = "cannot tell" if lag is None else f"{lag} steps ({lag / frames.fps:.2f} s)"
            log.info("reaction time of %s: %s", pilot, said)
        record: dict[str, Any] = {"shift": "auto", "reaction_steps": found}
    else:
        steps = {int(e): int(shift) for e in np.unique(frames.episode)}
        record = {"shift": int(shift)}
    if not any(steps.values()):
        return frames, record
    by = np.array([steps.get(int(e), 0) for e in frames.episode])
    return frames.later_actions(by), record
