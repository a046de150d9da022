"""A person and an assistant sharing the controls: the assistant (the task's controller or a
policy) flies until the person takes over, and again after they hand back."""

from __future__ import annotations

import numpy as np

from gymfg_il.agent import Agent
from gymfg_il.manual.controller import ManualController


class Takeover:
    """An Agent: the person (``human``) flies, or ``assistant`` while the person lets it.

    While the person flies, the assistant is still called at every step where it keeps
    something from step to step, its action discarded: a ``stateful`` one (a recurrent
    policy) so its state follows the flight, one with ``track`` (the controller) so its
    integrators follow the person's inputs; handing back is then bumpless.
    ``intervening`` tells the rollout loop to flag those steps.
    """

    def __init__(self, human: ManualController, assistant: Agent | None = None) -> None:
        self.human, self.assistant = human, assistant
        self.human_flies = assistant is None

    @property
    def intervening(self) -> bool:
        """A person flies while an assistant was ready to."""
        return self.assistant is not None and self.human_flies

    def toggle(self, last_action: np.ndarray) -> None:
        """Take over (the stick starts where the assistant had it) or hand back."""
        if self.assistant is None:
            return
        self.human_flies = not self.human_flies
        if self.human_flies:
            self.human.values[:] = last_action

    def reset(self, seed: int | None = None) -> None:
        self.human.reset(seed)
        if self.assistant is not None:
            self.assistant.reset(seed)

    def start_from(self, action: np.ndarray) -> None:
        """The person's stick and the assistant start from the aircraft's start controls."""
        self.human.start_from(action)
        start = getattr(self.assistant, "start_from", None)
        if start is not None:
            start(action)

    def act(self, observation: np.ndarray, opponent_states: np.ndarray | None = None) -> np.ndarray:
        if self.human_flies:
            action = self.human.act(observation)
            assistant = self.assistant
            track = getattr(assistant, "track", None)
            keeps = track is not None or getattr(assistant, "stateful", False)
            if assistant is not None and keeps:  # something of it outlives the step
                assistant.act(observation, opponent_states)  # its action is not flown
            if track is not None:
                track(action)  # its integrators follow the person: a bumpless hand-back
            return action
        assert self.assistant is not None
        return self.assistant.act(observation, opponent_states)
