"""The cockpit session's stages alone, each given its data: what the session commands do to
the episodes (``phases``), the synthetic pilot as an input that returns its keys, and its
human-gated DAgger gate."""

import os
from types import SimpleNamespace

import numpy as np
import pytest

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
import pygame

from gymfg_il.cockpit.inputs.devices import DeviceInput
from gymfg_il.cockpit.inputs.source import Seen
from gymfg_il.cockpit.inputs.synthetic_pilot import SyntheticInput
from gymfg_il.cockpit.phases import Phases, SessionStats
from gymfg_il.display.readings import Display
from gymfg_il.manual.controller import ManualController
from gymfg_il.tasks.verdicts import TrackedError


class FakeLog:
    """A flight log that remembers what it was told."""

    def __init__(self):
        self.calls, self.last_action, self.episode = [], np.zeros(4), -1

    def start(self, seed, starts):
        self.calls.append(("start", seed))

    def finish(self, outcome):
        self.episode += 1
        self.calls.append(("finish", outcome))
        return self.episode

    def discard(self, reason):
        self.calls.append(("discard",))

    def mark(self, episode, mark):
        self.calls.append(("mark", episode, mark))


def phases(build_each=True):
    log = FakeLog()
    rollout = SimpleNamespace(reset=lambda seed: [])
    takeover = SimpleNamespace(toggles=[], toggle=lambda action: takeover.toggles.append(action))
    updater = SimpleNamespace(asked=0, warm=lambda: None)
    updater.request = lambda: setattr(updater, "asked", updater.asked + 1)
    made = Phases(rollout, log, takeover, updater, SessionStats(), seed=7, build_each=build_each)
    return made, log, takeover, updater


def test_the_commands_start_end_discard_and_mark_episodes():
    p, log, takeover, updater = phases()
    assert p.apply(["mark success", "end", "pause"]) and p.state == "idle"  # nothing to do
    assert p.apply(["start", "start"]) and p.state == "recording" and p.started == 1
    p.apply(["pause"])
    assert p.state == "paused"
    p.apply(["discard", "start"])  # the same case again, with its seed
    p.apply(["takeover", "end", "mark failure", "mark success"])  # the last mark counts
    assert log.calls == [
        ("start", 7),
        ("discard",),
        ("start", 7),
        ("finish", "ended by the pilot"),
        ("mark", 0, "failure"),
        ("mark", 0, "success"),
    ]
    assert (p.stats.saved, p.stats.discarded, p.episode, p.next_seed) == (1, 1, 1, 8)
    assert len(takeover.toggles) == 1 and updater.asked == 3  # the saved episode, two marks
    assert not p.apply(["start", "quit"]) and log.calls[-1] == ("discard",)  # quit discards
    assert p.stats.discarded == 2 and p.next_seed == 8


def test_the_synthetic_pilots_dataset_waits_for_the_end():
    p, _, _, updater = phases(build_each=False)
    p.apply(["start", "end", "mark success"])
    assert p.stats.saved == 1 and updater.asked == 0


def seen(phase="recording", human_flies=True, error=0.0, started=1):
    observation = np.array([0.0, error])
    return Seen(phase, started, 3, Display(()), human_flies, observation)


def keys(events):
    return [(pygame.key.name(e.key), e.type == pygame.KEYDOWN) for e in events]


def test_the_synthetic_pilot_returns_its_keys_and_posts_none(monkeypatch):
    monkeypatch.setattr(pygame.event, "post", lambda event: pytest.fail(f"posted {event}"))
    human = ManualController("keyboard")
    pilot = SimpleNamespace(dt=1 / 30)
    source = SyntheticInput(DeviceInput(human, 1 / 30), pilot, assisted=False, tracked=None)
    polled = source.poll(seen(phase="idle"))
    assert polled.commands == ["start"]  # Space, as a person presses it, never posted
    assert source.poll(seen(phase="paused")).commands == [] and source.sent == []


@pytest.mark.parametrize("tolerance", [50.0, 10.0])
def test_the_dagger_gate_takes_over_past_three_tolerances_and_hands_back_once_settled(tolerance):
    pilot = SimpleNamespace(dt=0.1)
    tracked = TrackedError("altitude_ft", "altitude_ft_error", 1, tolerance, False)
    gate = SyntheticInput(None, pilot, assisted=True, tracked=tracked)
    assert gate._gated(seen(human_flies=False, error=3 * tolerance)) == []
    assert keys(gate._gated(seen(human_flies=False, error=-3.01 * tolerance))) == [
        ("t", True),
        ("t", False),
    ]
    # the person flies: within the tolerance for 3 s (30 frames of 0.1 s), then T again
    frames = [gate._gated(seen(error=tolerance)) for _ in range(29)]
    assert not any(frames)
    assert gate._gated(seen(error=1.01 * tolerance)) == []  # out of it: the count restarts
    frames = [gate._gated(seen(error=0.0)) for _ in range(30)]
    assert [i for i, f in enumerate(frames) if f] == [29] and keys(frames[29])[0] == ("t", True)
