"""Every frame of a dataset in memory (``Frames``): observations, actions and where each frame
sits, the per-episode records beside them; what ``learning.data`` loads and the batches, the
checks and the selections read."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from gymfg_il.envs.flight import STILL_AIR, FlightSpec
from gymfg_il.errors import ConfigError


@dataclass
class Frames:
    """Every frame of a dataset: observations, actions, and where each frame sits."""

    obs: np.ndarray  # (N, n_obs) float32
    action: np.ndarray  # (N, 4) float32
    episode: np.ndarray  # (N,) int64
    frame: np.ndarray  # (N,) int64
    observation_names: list[str]
    action_names: list[str]
    fps: int
    obs_stats: dict[str, np.ndarray]
    action_stats: dict[str, np.ndarray]
    episodes: dict[str, list[Any]] = field(default_factory=dict)  # per-episode metadata
    intervention: np.ndarray | None = None  # (N,) bool: a person took over from a policy
    images: np.ndarray | None = None  # (N, H, W, 3) uint8: one camera, when asked for
    camera: str | None = None  # which (``front``, ``chase``)

    def __len__(self) -> int:
        return len(self.action)

    def flight(self) -> tuple[FlightSpec | None, str]:
        """The solo flight every episode was flown as (``flight_of``)."""
        return flight_of(self.episodes)

    def demonstrated(self) -> Frames:
        """The frames a demonstrator flew: every frame of a demonstration, and of an episode a
        policy flew with a person (or the synthetic pilot) watching (source ``policy+...``),
        only the frames they took over (human-gated DAgger learns from the takeovers alone;
        the policy's own frames would teach it what it already does)."""
        sources = self.episodes.get("gymfg/source")
        if self.intervention is None or not sources:
            return self
        ids = self.episodes.get("episode_index", list(range(len(sources))))
        assisted = [i for i, src in zip(ids, sources, strict=True) if src.startswith("policy+")]
        keep = ~np.isin(self.episode, assisted) | self.intervention
        return self if keep.all() else self._take(keep)

    def from_first_input(self) -> Frames:
        """Each episode a person or the synthetic pilot flew (source ``human`` or
        ``synthetic``) from its first input on: the frame whose action first differs from the
        episode's first. The frames before it show hands at rest whatever the state (a person
        reading the briefing, or not yet reacting). An episode never touched is kept whole."""
        sources = self.episodes.get("gymfg/source")
        if not sources or not len(self):
            return self
        ids = self.episodes.get("episode_index", list(range(len(sources))))
        person = [i for i, src in zip(ids, sources, strict=True) if src in ("human", "synthetic")]
        first, end = episode_runs(self.episode)
        moved = np.any(self.action != self.action[first], axis=1)
        count = np.cumsum(moved)
        before = count[first] - moved[first]  # inputs before each frame's episode
        touched = count[end - 1] > before
        keep = (count > before) | ~touched | ~np.isin(self.episode, person)
        return self if keep.all() else self._take(keep)

    def later_actions(self, steps: np.ndarray) -> Frames:
        """Each observation paired with the action taken ``steps`` (one per frame) steps later
        in its episode; the frames with no such action are left out."""
        _, end = episode_runs(self.episode)
        keep = np.arange(len(self)) + steps < end
        out = self._take(keep)
        out.action = self.action[np.flatnonzero(keep) + steps[keep]]
        return out

    def select(self, episodes: np.ndarray) -> Frames:
        return self._take(np.isin(self.episode, episodes))

    def _take(self, keep: np.ndarray) -> Frames:
        return Frames(
            self.obs[keep],
            self.action[keep],
            self.episode[keep],
            self.frame[keep],
            self.observation_names,
            self.action_names,
            self.fps,
            self.obs_stats,
            self.action_stats,
            self.episodes,
            None if self.intervention is None else self.intervention[keep],
            None if self.images is None else self.images[keep],
            self.camera,
        )


def episode_runs(episode: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For each frame of frames that run episode by episode: the index of its episode's first
    frame, and one past its last."""
    n = len(episode)
    starts = np.r_[True, episode[1:] != episode[:-1]] if n else np.zeros(0, dtype=bool)
    first = np.maximum.accumulate(np.where(starts, np.arange(n), 0))
    end = np.r_[np.flatnonzero(starts)[1:], n][np.cumsum(starts) - 1]
    return first, end


def flight_of(episodes: dict[str, list[Any]]) -> tuple[FlightSpec | None, str]:
    """The solo flight every episode (``gymfg/*`` columns) was flown as (a team run's
    aircraft on its own; the longest episode time where only that differs; the first
    episode's weather where only the weather differs, as when `collect manual --gusts`
    episodes join calm ones, said in the note), and why there is none when
    the episodes disagree on more or predate flight specs."""
    specs = episodes.get("gymfg/spec")
    if not specs:
        return None, (
            "its episodes record no flight spec (its dataset predates them, or LeRobot's "
            "editing dropped them: `python -m gymfg_il.collect repair DIR --source ORIGINAL`)"
        )
    callsigns = episodes.get("gymfg/callsign") or ["ego"] * len(specs)
    found = [  # in episode order
        FlightSpec.from_json(text).for_callsign(c)
        for text, c in dict.fromkeys(zip(specs, callsigns, strict=True))
    ]
    longest = max(s.episode_time_s for s in found)
    alike = list(dict.fromkeys(s.replace(episode_time_s=longest) for s in found))
    calm = {s.replace(**STILL_AIR) for s in alike}
    if len(calm) > 1:
        return None, (
            f"its episodes were flown in {len(calm)} different flights (aircraft, task, "
            "options or rate)"
        )
    own = alike[0]
    if len(alike) == 1:
        return own, ""
    weathers = "; ".join(_weather_text(s) for s in alike)
    return own, (
        f"its episodes were flown in {len(alike)} weathers ({weathers}); its own flight is "
        "its first episode's"
    )


def _weather_text(spec: FlightSpec) -> str:
    turbulence = "no" if spec.turbulence == "none" else spec.turbulence
    parts = [f"{turbulence} turbulence", f"{spec.wind_kt:g} kt wind"]
    return ", ".join(parts + ([f"{spec.gusts} gusts"] if spec.gusts != "none" else []))


def observed_names(spec: str, callsign: str) -> tuple[str, ...] | None:
    """The observation names of ``callsign``'s task in the flight ``spec`` (JSON)."""
    try:
        aircraft = FlightSpec.from_json(spec).for_callsign(callsign).solo_aircraft
        return tuple(aircraft.task_factory()().observation_names)
    except (ConfigError, ValueError, KeyError, TypeError):
        return None  # a spec this version cannot build: its names are unknown
