"""A policy's memory as columns of the frames it learns from (``remembered``): the loop
integrals of ``policies.memory`` computed over each recorded episode from its first frame, as
the policy computes them in flight step by step."""

from __future__ import annotations

import logging
from dataclasses import replace
from typing import Any

import numpy as np

from gymfg_il.errors import ConfigError
from gymfg_il.learning.frames import Frames, episode_runs

log = logging.getLogger(__name__)


def remembered(frames: Frames, policy: Any) -> Frames:
    """``frames`` with the memory ``policy`` (a configuration) declares appended to each
    observation (names ``memory.*``, statistics from these frames); as they are where it
    declares none, or (``auto``) where the dataset is not of one solo flight with an expert.
    Computed before any frame is left out, so each episode runs whole."""
    asked = getattr(policy, "memory", "none")
    if asked == "none":
        return frames
    from gymfg_il.policies.memory import NAMES, LoopMemoryRecipe, names_of

    if any(n in NAMES for n in frames.observation_names):
        return frames  # already remembered (DAgger's rounds hand the frames on)
    flight, why = frames.flight()
    try:
        if flight is None or not flight.is_solo:
            raise ConfigError(
                f"--memory {asked} runs the task's expert loops, so it needs a dataset of one "
                f"solo flight spec: {why or 'a team flight'}; train with --memory none"
            )
        recipe = LoopMemoryRecipe.for_flight(flight.to_dict(), frames.observation_names)
        expert = by_expert(frames)
        kind = (recipe.by_expert if expert else recipe.default) if asked == "auto" else asked
        if kind == "none":
            log.info("the policy remembers nothing: the %s task asks for no memory", flight.task)
            return frames
        fresh = recipe.new(kind)
        memory = _columns(frames, fresh)
    except ConfigError as err:
        if asked != "auto":
            raise
        log.warning("the policy remembers nothing (--memory none): %s", err)
        return frames
    if expert:  # each integral in its loop's range (``LoopMemory.scales``), from zero
        mean, std = np.zeros(len(fresh.names), np.float32), fresh.scales
    else:
        mean, std = memory.mean(0), memory.std(0)
    stats = {
        "mean": np.r_[frames.obs_stats["mean"], mean],
        "std": np.r_[frames.obs_stats["std"], std],
    }
    obs = np.concatenate([frames.obs, memory], axis=1)
    names = [*frames.observation_names, *names_of(kind)]
    return replace(frames, obs=obs, observation_names=names, obs_stats=stats)


# sources whose every action is the task's own autopilot's: its demonstrations, and the states
# a policy flew into, labelled by it (``collect dagger``)
BY_EXPERT = ("autopilot", "dagger")


def by_expert(frames: Frames) -> bool:
    """Whether the task's own expert gave every action of ``frames`` (``collect autopilot``,
    ``collect dagger``): then the memory's loops are the demonstrator's, whose integral terms are
    known, and a policy starts from them and is held near them (``MLPPolicy.anchor_memory``),
    each integral measured in its loop's range. Anyone else's integrals (a person's trim)
    are learned from the data, measured in their spread there: held at the expert's terms,
    a clone of the synthetic pilot's turns flew 19 % against 100 % (docs/results/memory.md)."""
    sources = frames.episodes.get("gymfg/source") or []
    return bool(sources) and all(source in BY_EXPERT for source in sources)


def _columns(frames: Frames, fresh: Any) -> np.ndarray:
    """The memory ``fresh`` (a ``LoopMemory``) at every frame, run over each episode from
    its first frame."""
    memory = np.zeros((len(frames), len(fresh.names)), np.float32)
    first, end = episode_runs(frames.episode)
    gaps = []
    for start in np.unique(first):
        stop, numbers = int(end[start]), frames.frame[first[start] : end[start]]
        if numbers[0] != 0 or np.any(np.diff(numbers) <= 0):
            raise ConfigError(
                f"episode {int(frames.episode[start])} does not start at frame 0 with its "
                "frames in order, so its memory cannot be run from its start; repair the "
                "dataset (python -m gymfg_il.collect recover) or train with --memory none"
            )
        if numbers[-1] != len(numbers) - 1:
            gaps.append(int(frames.episode[start]))
        memory[start:stop] = fresh.over(frames.obs[start:stop])
    if gaps:
        log.warning(
            "episodes %s lack frames (edited datasets): their memory runs over the frames "
            "they hold, as if consecutive",
            gaps,
        )
    return memory
