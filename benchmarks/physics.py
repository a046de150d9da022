"""The simulation's own speed: ``AircraftEnv.step`` against a bare JSBSim loop doing the same
property I/O, a team of 8 aircraft against a team of 1, and trimmed resets against untrimmed
ones."""

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

    env = AircraftEnv("altitude", "c172p")
    ic = InitialConditions(altitude_ft=5000, airspeed_kts=110)
    action = np.array([0.0, 0.0, 0.0, 0.75], np.float32)

    def run_env(n: int) -> None:
        env.reset(seed=0, options={"initial_conditions": ic})
        step = env.step
        for _ in range(n):
            step(action)

    run_raw = raw_loop()
    r = paired(run_env, run_raw, steps, rounds)
    env.close()
    return Row(
        "env_step_vs_raw_jsbsim",
        r["ratio"],
        "ratio",
        0.95,
        detail=[
            f"env.step (c172p, 10 Hz)     {r['candidate']:9,.0f} steps/s (median)",
            f"raw FGFDMExec, same I/O     {r['reference']:9,.0f} steps/s (median)",
            f"per-round ratios {', '.join(f'{x:.3f}' for x in r['ratios'])}",
        ],
        extra={"rounds": r["ratios"]},
    )


def raw_loop() -> Callable[[int], None]:
    """A bare JSBSim loop doing an agent step's property I/O (c172p, 10 Hz): the four
    controls set through cached nodes, 12 ``FGFDMExec.run()``, the catalogue read into an
    array; ``loop(n)`` resets and takes ``n`` steps."""
    from gymfg_il.sim.initial import InitialConditions
    from gymfg_il.sim.simulation import Simulation

    ic = InitialConditions(altitude_ft=5000, airspeed_kts=110)
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

    return run_raw


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


def trimmed_vs_untrimmed(n_resets: int, rounds: int) -> Row:
    """Resets/s of a c172p with trimmed starts over resets/s with untrimmed ones, at the
    starts the tasks draw (cruise altitude +/- 500 ft, cruise speed +/- 5 %); the trim grid
    around them is trimmed before the first round, as after an episode or two."""
    import dataclasses

    from gymfg_il.aircraft import PROFILES
    from gymfg_il.sim.initial import InitialConditions
    from gymfg_il.sim.simulation import Simulation

    profile, rng = PROFILES["c172p"], np.random.default_rng(0)
    starts = [
        InitialConditions(
            altitude_ft=profile.cruise_altitude_ft + float(rng.uniform(-500, 500)),
            airspeed_kts=profile.cruise_kts * float(rng.uniform(0.95, 1.05)),
            heading_deg=float(rng.uniform(0, 360)),
            trimmed=True,
        )
        for _ in range(64)
    ]
    untrimmed = [dataclasses.replace(ic, trimmed=False) for ic in starts]
    sim = Simulation("c172p")
    for ic in starts:
        sim.reset(ic)

    def resets(ics: list[InitialConditions]) -> Callable[[int], None]:
        def run(n: int) -> None:
            for i in range(n):
                sim.reset(ics[i % len(ics)], 0.75)

        return run

    r = paired(resets(starts), resets(untrimmed), n_resets, rounds)
    return Row(
        "reset_trimmed_vs_untrimmed",
        r["ratio"],
        "ratio",
        0.5,
        detail=[
            f"trimmed starts     {r['candidate']:9,.0f} resets/s (median)",
            f"untrimmed starts   {r['reference']:9,.0f} resets/s (median)",
        ],
    )


def rows(quick: bool) -> list[Row]:
    steps, rounds = (200, 2) if quick else (900, 9)
    return [
        env_vs_raw(steps, rounds),
        eight_vs_one(steps // 2, rounds),
        trimmed_vs_untrimmed(steps, rounds),
    ]
