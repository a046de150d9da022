"""Flying a dataset's episodes again, for the Minari export (``export.minari``): Minari keeps
each step's executed action and the states an env gives, so every episode is re-flown in its
env from its seed, with the actions that were flown (from the session's logs where they are at
hand: bit for bit; else the dataset's float32 labels, within ``NEAR`` of the dataset's states).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from gymfg_il.datasets.episode_logs import log_name_problem
from gymfg_il.errors import ConfigError

if TYPE_CHECKING:
    from gymfg_il.learning.frames import Frames

NEAR = 1e-3  # relative drift allowed when re-flying from float32 actions (no logs at hand)


class _FlownActions:
    """Each episode's flown actions: from its log when the session's logs are at hand."""

    def __init__(self, logs: Path | None) -> None:
        self.logs = logs
        self._read: dict[str, Any] = {}

    def __call__(self, meta: dict[str, Any], labels: np.ndarray) -> tuple[np.ndarray, bool]:
        """(the flown actions, whether they are the exact ones: from the log)."""
        name, index = meta.get("gymfg/log"), meta.get("gymfg/log_episode")
        callsign = meta.get("gymfg/callsign", "ego")
        if (
            self.logs is not None
            and isinstance(name, str)
            and log_name_problem(name) is None  # a file name in logs/, never a path
            and (self.logs / name).is_file()
        ):
            from gymfg_il.recording.reader import read_log

            if name not in self._read:
                self._read[name] = read_log(self.logs / name)
            for ep in self._read[name].complete_episodes:
                if ep.index == index and callsign in ep.steps:
                    return ep.steps[callsign].action, True
        noisy = float(meta.get("gymfg/noise", 0.0) or 0.0) > 0.0
        # the action column holds the demonstrator's label: under DAgger the policy flew and
        # the expert labelled, so what flew is only in the log
        relabelled = "dagger" in str(meta.get("gymfg/source", ""))
        if noisy or relabelled:
            why = (
                f"flown with noise {meta['gymfg/noise']}"
                if noisy
                else f"labelled by a demonstrator that did not fly it (source "
                f"{meta.get('gymfg/source')!r})"
            )
            raise ConfigError(
                f"episode {meta['episode_index']} was {why}: its flown actions are only in "
                f"its log {name}, which is not under "
                f"{self.logs or 'a logs/ folder beside the dataset'}; export the session "
                "folder that holds it"
            )
        return labels.astype(np.float64), False


def _refly(
    env: Any,
    meta: dict[str, Any],
    obs: np.ndarray,
    flown_actions: tuple[np.ndarray, bool],
    labels: np.ndarray,
) -> Any:
    """Fly one episode again in ``env``; its Minari buffer, or a clear error where it departs
    from the dataset (``flown_actions``: exact ones must give the dataset's observations bit
    for bit, float32-rounded ones within ``NEAR``)."""
    from minari.data_collector import EpisodeBuffer

    actions, exact = flown_actions
    index, seed = int(meta["episode_index"]), int(meta["gymfg/seed"])
    flown, rewards, terms, truncs = _fly(env, actions, index, seed)
    _check_departure(flown, obs, exact, index, seed)
    if not exact:
        flown[: len(obs)] = obs  # the dataset's own; only the last comes from the flight
    return EpisodeBuffer(
        id=None,
        seed=seed,
        observations=flown,
        actions=actions.astype(np.float32),  # the action space's dtype
        rewards=np.array(rewards),
        terminations=np.array(terms),
        truncations=np.array(truncs),
        infos={"label": np.concatenate([labels, labels[-1:]])},
    )


def _fly(
    env: Any, actions: np.ndarray, index: int, seed: int
) -> tuple[np.ndarray, list[float], list[bool], list[bool]]:
    """Episode ``index`` flown in ``env`` from ``seed`` with ``actions``: (its N + 1
    observations, its rewards, terminations and truncations), or an error where it ends
    before or after the dataset's episode."""
    first, _ = env.reset(seed=seed)
    observations = [np.asarray(first, np.float32)]
    rewards, terms, truncs = [], [], []
    for t, action in enumerate(actions):
        ob, reward, terminated, truncated, _ = env.step(action)
        observations.append(np.asarray(ob, np.float32))
        rewards.append(float(reward))
        terms.append(bool(terminated))
        truncs.append(bool(truncated))
        if (terminated or truncated) and t < len(actions) - 1:
            raise ConfigError(
                f"episode {index} (seed {seed}) ends after {t + 1} steps when flown again "
                f"in its env, but the dataset holds {len(actions)}"
            )
    if not (terms[-1] or truncs[-1]):
        raise ConfigError(
            f"episode {index} (seed {seed}) has not ended after its {len(actions)} steps when "
            "flown again in its env"
        )
    return np.stack(observations), rewards, terms, truncs


def _check_departure(
    flown: np.ndarray, obs: np.ndarray, exact: bool, index: int, seed: int
) -> None:
    """Raise where the re-flown observations depart from the dataset's ``obs``: at all for
    ``exact`` actions, beyond float32 rounding (``NEAR``) for the dataset's own."""
    if exact:
        apart = flown[: len(obs)] != obs
    else:  # float32-rounded actions: the flight drifts by rounding only
        apart = np.abs(flown[: len(obs)] - obs) > NEAR * (1.0 + np.abs(obs))
    differs = np.flatnonzero(np.any(apart, axis=1))
    if len(differs):
        why = (
            "a dataset edited by hand, or collected by another version"
            if exact
            else "flown again from its float32 actions it drifted; export the session folder "
            "with its logs/, which hold the exact actions"
        )
        raise ConfigError(
            f"episode {index} (seed {seed}) departs from the dataset at frame {differs[0]} "
            f"when flown again in its env ({why}); it cannot be exported with its env"
        )


def refly_all(env: Any, env_id: str, frames: Frames, logs: Path | None) -> list[Any]:
    """Every episode of ``frames`` flown again in ``env`` (the one of id ``env_id``, whose
    observations must be the dataset's), with its flown actions from ``logs`` where they are
    at hand; their Minari buffers, in the dataset's order."""
    names = list(env.get_wrapper_attr("observation_names"))
    if frames.observation_names != names:
        raise ConfigError(
            f"the dataset's observation names {frames.observation_names} are not those "
            f"of its env {env_id} ({names}); it cannot be exported with its env"
        )
    flown = _FlownActions(logs)
    columns = frames.episodes
    buffers = []
    for i, episode in enumerate(columns["episode_index"]):
        meta = {k: v[i] for k, v in columns.items()}
        rows = frames.episode == episode
        order = np.argsort(frames.frame[rows])
        obs, labels = frames.obs[rows][order], frames.action[rows][order]
        buffers.append(_refly(env, meta, obs, flown(meta, labels), labels))
    return buffers
