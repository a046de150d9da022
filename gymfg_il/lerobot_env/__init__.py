"""GymFG as a LeRobot env plugin: ``lerobot-eval --env.type=gymfg``.

    lerobot-eval --policy.path=OUT/checkpoints/last/pretrained_model \\
        --env.type=gymfg --env.discover_packages_path=gymfg_il.lerobot_env \\
        --env.task=roll --env.aircraft=c172p --eval.n_episodes=10 --eval.batch_size=1

Importing this package registers the ``gymfg`` choice of LeRobot's ``EnvConfig`` registry
(``GymFGEnv``; its fields are the ``--env.*`` flags) and a gymnasium id per task,
``gym_gymfg/<task>`` (``env.LeRobotFlightEnv``). The policy sees ``observation.state`` (the
task's observation), ``observation.environment_state`` (its task columns) and, with
``--env.images='[front]'``, ``observation.images.front``: the features our datasets hold, so a
policy trained with ``lerobot-train`` on them flies here unchanged.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import gymnasium as gym
from lerobot.configs import FeatureType, PolicyFeature
from lerobot.envs.configs import EnvConfig
from lerobot.utils.constants import ACTION, OBS_ENV_STATE, OBS_IMAGES, OBS_STATE

from gymfg_il.envs.options import FlightOptions
from gymfg_il.errors import ConfigError, join_problems
from gymfg_il.sim.timing import DEFAULT_AGENT_HZ
from gymfg_il.sim.weather import TURBULENCE, Turbulence
from gymfg_il.tasks.library import TRACKED_TASKS

NAMESPACE = "gym_gymfg"
ENTRY_POINT = "gymfg_il.lerobot_env.env:LeRobotFlightEnv"

for _task in TRACKED_TASKS:
    if f"{NAMESPACE}/{_task}" not in gym.registry:
        gym.register(f"{NAMESPACE}/{_task}", entry_point=ENTRY_POINT, kwargs={"task": _task})


@EnvConfig.register_subclass("gymfg")
@dataclass
class GymFGEnv(EnvConfig):
    """A GymFG solo flight for LeRobot's tools: the flight options
    (``envs.options.FlightOptions``) under LeRobot's names (its ``fps`` is our ``agent_hz``),
    and the camera views the policy is given.

    Attributes:
        task: our task name: altitude, roll, pitch, heading, airspeed, sideslip, level, or a
            maneuver (turn, climb-turn, waypoints, formation, approach).
        aircraft: JSBSim model (c172p, f15, A320, ...).
        dynamic: moving targets instead of fixed ones.
        episode_time_s: episode length in seconds (None: the task's own, 90 s for most).
        fps: agent rate in Hz, a divisor of 120: the dataset's fps.
        images: camera views given to the policy (front, chase), as in ``collect --images``.
        image_size: the camera frames' size in pixels (square).
        turbulence: none, light, moderate or severe.
    """

    task: str | None = "roll"
    aircraft: str = "c172p"
    dynamic: bool = False
    episode_time_s: float | None = None
    fps: int = DEFAULT_AGENT_HZ
    images: list[str] = field(default_factory=list)
    image_size: int = 128
    turbulence: Turbulence = "none"
    features: dict[str, PolicyFeature] = field(default_factory=dict)
    features_map: dict[str, str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        problems = []
        if self.task not in TRACKED_TASKS:
            problems.append(f"task={self.task!r}: choose one of {', '.join(TRACKED_TASKS)}")
        if self.turbulence not in TURBULENCE:
            problems.append(f"turbulence={self.turbulence!r}: {', '.join(TURBULENCE)}")
        if problems:
            raise ConfigError(join_problems("--env (gymfg)", problems))
        env = self.make_one()
        try:
            spaces = env.observation_space.spaces
            self.features = {ACTION: PolicyFeature(type=FeatureType.ACTION, shape=(4,))}
            self.features_map = {ACTION: ACTION, "agent_pos": OBS_STATE}
            self.features["agent_pos"] = PolicyFeature(
                type=FeatureType.STATE, shape=spaces["agent_pos"].shape
            )
            if "environment_state" in spaces:
                self.features["environment_state"] = PolicyFeature(
                    type=FeatureType.ENV, shape=spaces["environment_state"].shape
                )
                self.features_map["environment_state"] = OBS_ENV_STATE
            for view in env.images:
                key = f"pixels/{view}"
                shape = (self.image_size, self.image_size, 3)
                self.features[key] = PolicyFeature(type=FeatureType.VISUAL, shape=shape)
                self.features_map[key] = f"{OBS_IMAGES}.{view}"
        finally:
            env.close()

    @property
    def package_name(self) -> str:
        return "gymfg_il.lerobot_env"

    @property
    def gym_id(self) -> str:
        return f"{NAMESPACE}/{self.task}"

    def flight_options(self) -> FlightOptions:
        """The flight these fields describe."""
        return FlightOptions(
            aircraft=self.aircraft,
            task=self.task,
            dynamic=self.dynamic,
            episode_time_s=self.episode_time_s,
            agent_hz=self.fps,
            turbulence=self.turbulence,
        )

    @property
    def gym_kwargs(self) -> dict[str, Any]:
        options = self.flight_options().given()
        del options["task"]  # the gym id names it
        return {**options, "images": list(self.images), "image_size": self.image_size}

    def make_one(self) -> Any:
        """One env of this config (what ``create_envs`` vectorises)."""
        from gymfg_il.lerobot_env.env import LeRobotFlightEnv

        return LeRobotFlightEnv(str(self.task), **self.gym_kwargs)
