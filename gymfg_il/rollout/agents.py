"""What builds an agent for an env, picklable so a worker process can build it too: the
task's physics-based controller, or a trained policy checkpoint."""

from __future__ import annotations

from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import Any

from gymfg_il.agent import Agent
from gymfg_il.envs.single import AircraftEnv


@dataclass(frozen=True)
class AgentSpec:
    """``AgentSpec.controller()``, ``AgentSpec.policy(path)`` or
    ``AgentSpec.synthetic(device, skill)`` (the synthetic pilot at a ManualController)."""

    kind: str
    path: Path | None = None
    device: str = "keyboard"
    skill: float = 0.7

    @classmethod
    def controller(cls) -> AgentSpec:
        return cls("controller")

    @classmethod
    def policy(cls, path: Path) -> AgentSpec:
        return cls("policy", Path(path))

    @classmethod
    def synthetic(cls, device: str = "keyboard", skill: float = 0.7) -> AgentSpec:
        return cls("synthetic", None, device, skill)

    def key(self) -> str:
        """What a worker's cache knows this agent by: its spec, and for a checkpoint the
        time and size of its config and weights (one retrained in place is loaded afresh)."""
        if self.path is None:
            return repr(self)
        from gymfg_il.policies.checkpoint import CONFIG_FILE, WEIGHTS_FILE
        from gymfg_il.policies.lerobot_checkpoint import find_pretrained

        folder = find_pretrained(self.path) or self.path
        stamps: list[tuple[int, int] | None] = []
        for name in (CONFIG_FILE, WEIGHTS_FILE):
            try:
                st = (folder / name).stat()
                stamps.append((st.st_mtime_ns, st.st_size))
            except OSError:
                stamps.append(None)  # loading it will say what is missing
        return repr((self, stamps))

    def meta(self) -> dict[str, Any]:
        """A policy's ``config.json`` (for a LeRobot checkpoint, what its config says of it:
        ``policies.lerobot_checkpoint.lerobot_meta``)."""
        from gymfg_il.policies.checkpoint import read_config
        from gymfg_il.policies.lerobot_checkpoint import find_pretrained, lerobot_meta

        assert self.path is not None
        folder = find_pretrained(self.path)
        if folder is not None:
            return lerobot_meta(folder)
        return read_config(self.path)

    def make(self, env: AircraftEnv) -> Agent:
        if self.kind in ("controller", "synthetic"):
            from gymfg_il.controllers.autopilot import controller_for

            model, throttle = env.aircraft.model, env.aircraft.profile.cruise_throttle
            if self.kind == "controller":
                return controller_for(env.task, model, env.dt, throttle)
            from gymfg_il.display.readings import display_of
            from gymfg_il.manual.controller import ManualController
            from gymfg_il.manual.perception import DisplayIntent
            from gymfg_il.manual.synthetic import PilotAgent, SyntheticPilot

            intent = DisplayIntent(env.task, model, env.dt, throttle)
            pilot = SyntheticPilot(self.device, intent, env.dt, self.skill)
            human = ManualController(self.device, throttle=throttle)
            world = env.world
            return PilotAgent(
                pilot, human, lambda: display_of(env.task, world.slots[0].state, world.steps)
            )
        from gymfg_il.policies.agent import PolicyAgent
        from gymfg_il.policies.lerobot_checkpoint import LeRobotAgent, find_pretrained

        assert self.path is not None
        folder = find_pretrained(self.path)
        if folder is not None:
            checkpoint = LeRobotAgent(folder)
            checkpoint.check_observation(env.observation_names)
            for view, size in checkpoint.camera_sizes.items():
                checkpoint.see[view] = partial(env.camera_frame, view, size)
            return checkpoint
        agent = PolicyAgent.load(self.path)
        agent.check_observation(env.observation_names)
        if agent.camera is not None:
            view, size = agent.camera["view"], int(agent.camera["size"])
            agent.see = lambda: env.camera_frame(view, size)
        return agent
