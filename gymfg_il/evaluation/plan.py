"""What an evaluation flies: the flight and the agents (``plan``).

A policy is flown with its own flight spec (its aircraft, task and options, rate and episode
time, from its ``config.json``) unless a flight option asks otherwise; ``flight_for`` settles
what is flown and refuses what cannot be meant (a 30 Hz policy flown at 10 Hz). Every agent
flies the same seeded cases of that one flight (``evaluation.runner``).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from gymfg_il.collectors.config import MANUAL_HZ
from gymfg_il.envs.flight import STILL_AIR, FlightSpec
from gymfg_il.envs.options import FlightOptions
from gymfg_il.errors import ConfigError
from gymfg_il.evaluation.config import EvalConfig
from gymfg_il.rollout.agents import AgentSpec


def flight_for(
    policies: Mapping[Path, Mapping[str, Any]], options: FlightOptions | None = None
) -> tuple[FlightSpec, list[str]]:
    """What to fly: the policies' own flight, changed where an option is set (each change is
    returned as a note to print), or, without policies, the options over the defaults.

    A rate other than the policy's is refused: its actions were learnt at its own rate."""
    options = options or FlightOptions()
    specs = {path: meta.get("spec") for path, meta in policies.items()}
    known = {p: FlightSpec.from_dict(s) for p, s in specs.items() if s}
    calm = {p: s.replace(**STILL_AIR) for p, s in known.items()}
    distinct = {s.to_json(): p for p, s in calm.items()}
    if len(distinct) > 1:
        a, b = list(distinct.values())[:2]
        raise ConfigError(
            f"{a} and {b} were trained on different flights; every agent of one evaluation "
            "flies the same cases: evaluate them separately"
        )
    weather_notes = _weather_notes(known, options)
    agent_hz = options.agent_hz
    if not known:
        missing = ", ".join(str(p) for p in policies)
        if policies and (options.task is None or options.aircraft is None):
            why = "; ".join(str(m.get("spec_note") or "") for m in policies.values()).strip("; ")
            raise ConfigError(
                f"{missing} records no flight of its own ({why or 'its dataset predates them'})"
                ": give --task and --aircraft"
            )
        rates = {int(m["fps"]) for m in policies.values() if m.get("fps")}
        if len(rates) > 1 or (rates and agent_hz is not None and {agent_hz} != rates):
            raise ConfigError(
                f"{missing} {'were' if len(policies) > 1 else 'was'} trained at {sorted(rates)} "
                f"Hz (the dataset's fps) and fly at that rate; drop --agent-hz or evaluate "
                "them separately"
            )
        rate = agent_hz or (rates.pop() if rates else None)
        return FlightOptions(**{**options.given(), "agent_hz": rate}).flight(), []
    path, base = next(iter(known.items()))
    if agent_hz is not None and agent_hz != base.agent_hz:
        raise ConfigError(
            f"{path} was trained at {base.agent_hz} Hz (its dataset's fps) and flies at that "
            f"rate; --agent-hz {agent_hz} would change what each of its actions means. Drop "
            "--agent-hz, or train on data recorded at that rate"
        )
    asked = options.given()
    changes: dict[str, Any] = {}
    notes: list[str] = []
    for name, value in asked.items():
        old = getattr(base, name)
        if value == old:
            continue
        changes[name] = value
        notes.append(
            f"note: {path} was trained with {name}={old!r}; flying it with {name}={value!r} "
            "as asked"
        )
    if "task" in changes and "task_kwargs" not in asked:
        changes["task_kwargs"] = {}  # another task's options would not fit
    return base.replace(**changes), weather_notes + notes


def _weather_notes(known: Mapping[Path, FlightSpec], options: FlightOptions) -> list[str]:
    """Policies whose flights differ only in the weather (a policy fine-tuned in turbulence
    beside the one it started from) fly together in the weather the options give, else the
    first policy's: a note says which, and what each was trained in."""
    weathers = {p: {k: getattr(s, k) for k in STILL_AIR} for p, s in known.items()}
    if len({repr(w) for w in weathers.values()}) < 2:
        return []
    first = next(iter(weathers))
    flown = {**weathers[first], **{k: v for k, v in options.given().items() if k in STILL_AIR}}
    whose = "as asked" if any(k in options.given() for k in STILL_AIR) else f"{first}'s"
    said = ", ".join(
        f"{k}={flown[k]!r}"
        for k in STILL_AIR
        if k != "wind_from_deg" and (k != "gusts" or flown[k] != "none")
    )
    trained = "; ".join(
        f"{p}: {'no' if w['turbulence'] == 'none' else w['turbulence']} turbulence, "
        f"{w['wind_kt']:g} kt wind" + (f", {w['gusts']} gusts" if w["gusts"] != "none" else "")
        for p, w in weathers.items()
    )
    return [
        f"note: these policies were trained in different weather ({trained}); all fly in "
        f"{said} ({whose})"
    ]


def policy_meta(path: Path) -> dict[str, Any]:
    """A policy's config; a LeRobot checkpoint's completed with the flight, rate and
    observation of the dataset it was trained on, when that dataset is here."""
    meta = AgentSpec.policy(path).meta()
    if not meta.get("lerobot"):
        return meta
    root = meta.get("dataset")
    if not root or not (Path(root) / "meta" / "info.json").is_file():
        meta["spec_note"] = f"its training dataset ({root}) is not here to say what it flew"
        return meta
    from gymfg_il.learning.data import dataset_flight

    spec, why, found = dataset_flight(Path(root))
    meta.update(found, spec=spec.to_dict() if spec else None, spec_note=why)
    return meta


def plan(cfg: EvalConfig) -> tuple[FlightSpec, dict[str, AgentSpec], list[str]]:
    """What flies (the flight, the agents by row name) and the notes on options that changed
    a policy's own flight; a clear error for a policy that cannot fly it."""
    metas = {path: policy_meta(path) for path in cfg.policy}
    if cfg.pilot == "synthetic" and not cfg.policy and cfg.agent_hz is None:
        cfg = dataclasses.replace(cfg, agent_hz=MANUAL_HZ)  # the pilot flies as a person does
    flight, notes = flight_for(metas, cfg)
    env = flight.make_env()
    try:
        for path in metas:  # loaded whole now: a damaged policy fails before anything flies
            AgentSpec.policy(path).make(env)
    finally:
        env.close()
    agents = {"controller": AgentSpec.controller()}
    if cfg.pilot == "synthetic":
        agents[f"pilot:synthetic-{cfg.device}"] = AgentSpec.synthetic(cfg.device, cfg.skill)
    names = [p.name for p in cfg.policy]
    for path in cfg.policy:  # a folder name twice (run1/policy, run2/policy): the whole path
        agents[f"policy:{path.name if names.count(path.name) == 1 else path}"] = AgentSpec.policy(
            path
        )
    return flight, agents, notes
