"""The simulation's own speed: ``AircraftEnv.step`` against a bare JSBSim loop doing the same
property I/O, and a team of 8 aircraft against a team of 1."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from benchmarks.common import Row, paired


def env_vs_raw(steps: int, rounds: int) -> Row:
    """steps/s of ``AircraftEnv.step`` (c172p, altitude task, 10 Hz = 12 JSBSim frames) over
    steps/s of a bare loop with the same property I/O (the four controls set through cached
    nodes, 12 ``FGFDMExec.run()``, the catalogue read into an array)."""
    from gymfg_il.envs.single import AircraftEnv
    from gymfg_il.sim.initial import InitialConditions
    from gymfg_il.sim.simulation import Simulation

    env = AircraftEnv("altitude", "c172p")
    ic = InitialConditions(altitude_ft=5000, airspeed_kts=110)
    action = np.array([0.0, 0.0, 0.0, 0.75], np.float32)

    def run_env(n: int) -> None:
        env.reset(seed=0, options={"initial_conditions": ic})
        step = env.step
        for _ in range(n):
            step(action)

    sim = Simulation("c172p")
    fdm = sim.fdm
    pm = fdm.get_property_manager()
    setters = [
        pm.get_node(p).set_double_value
        for p in (
            "fcs/aileron-cmd-norm",
            "fcs/elevator-cmd-norm",
            "fcs/rudder-cmd-norm",
            "fcs/throttle-cmd-norm",
        )
    ]
    getters = list(sim._getters)
    run = fdm.run
    values = (0.0, 0.0, 0.0, 0.75)

    def run_raw(n: int) -> None:
        sim.reset(ic, 0.75)
        for _ in range(n):
            for setter, v in zip(setters, values, strict=True):
                setter(v)
            for _ in range(12):
                run()
            np.array([g() for g in getters])

    r = paired(run_env, run_raw, steps, rounds)
    env.close()
    return Row(
        "env_step_vs_raw_jsbsim",
        r["ratio"],
        "ratio",
        0.90,
        detail=[
            f"env.step (c172p, 10 Hz)     {r['candidate']:9,.0f} steps/s (median)",
            f"raw FGFDMExec, same I/O     {r['reference']:9,.0f} steps/s (median)",
            f"per-round ratios {', '.join(f'{x:.3f}' for x in r['ratios'])}",
        ],
        extra={"rounds": r["ratios"]},
    )


def eight_vs_one(steps: int, rounds: int) -> Row:
    """aircraft-steps/s of an OfflineEnv team of 8 c172p over that of a team of 1."""
    from gymfg_il import Team
    from gymfg_il.aircraft import c172p
    from gymfg_il.envs import OfflineEnv
    from gymfg_il.tasks import ReachStaticTargetAltitudeTask

    def runner(n_aircraft: int) -> Callable[[int], None]:
        team = Team(
            "red",
            [(c172p(f"red-{i}"), ReachStaticTargetAltitudeTask) for i in range(n_aircraft)],
        )
        env = OfflineEnv()
        env.reset(team, seed=0)
        action = np.tile([0.0, 0.0, 0.0, 0.75], n_aircraft)

        def run(n: int) -> None:
            env.reset(team, seed=0)
            for _ in range(n):
                info = env.step(action)[-1]
            # a terminated aircraft is no longer simulated and would flatter the figure
            assert not any(info["terminated"]), info["reasons"]

        return run

    one, eight = runner(1), runner(8)
    r = paired(eight, one, steps, rounds)  # steps/s; a step of 8 aircraft is 8 aircraft-steps
    return Row(
        "per_aircraft_8_vs_1",
        8 * r["ratio"],
        "ratio",
        0.85,
        detail=[
            f"1 aircraft                  {r['reference']:9,.0f} aircraft-steps/s",
            f"8 aircraft                  {8 * r['candidate']:9,.0f} aircraft-steps/s",
        ],
    )


def rows(quick: bool) -> list[Row]:
    steps, rounds = (200, 2) if quick else (900, 9)
    return [env_vs_raw(steps, rounds), eight_vs_one(steps // 2, rounds)]
