"""Shared fixtures: small factories for teams and envs."""

from __future__ import annotations

import os

import pytest

os.environ.setdefault("HF_HUB_OFFLINE", "1")
os.environ.setdefault("SDL_VIDEODRIVER", "dummy")


@pytest.fixture
def make_env():
    """Factory for single-aircraft envs that are closed after the test."""
    from gymfg_il.envs.single import AircraftEnv

    made = []

    def make(task="altitude", aircraft="c172p", **kwargs):
        env = AircraftEnv(task, aircraft, **kwargs)
        made.append(env)
        return env

    yield make
    for env in made:
        env.close()
