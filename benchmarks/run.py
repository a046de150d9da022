"""Side-by-side benchmarks, printed as ratios against their references in one run.

    python benchmarks/run.py [--quick] [--json PATH]

Rows (name, value, unit, target, higher_is_better, and for some a figure beside the value:
new_pool_ratio, median):
- env_step_vs_raw_jsbsim: steps/s of ``AircraftEnv.step`` (c172p, altitude task, 10 Hz = 12
  JSBSim frames) divided by steps/s of a bare loop doing the same property I/O (the four
  controls set through cached nodes, 12 ``FGFDMExec.run()``, the catalogue read into an array).
- per_aircraft_8_vs_1: aircraft-steps/s of an OfflineEnv team of 8 c172p divided by that of a
  team of 1.
- dataset_build_frames_per_s: building a LeRobot dataset from MCAP logs (reading included),
  beside LeRobot's own add_frame + save_episode path.
- train_pipeline_frames_per_s: frames/s our in-memory batches deliver, beside stock
  LeRobotDataset + DataLoader.
- rollout_workers_2_vs_1: speed-up of seeded evaluation episodes on 2 worker processes kept
  across calls (``Workers``, as ``eval`` keeps them for all its agents, and as vector envs
  keep theirs), beside a new pool per call.
- online_{2,8,16}_teams_steps_per_s: simulation steps/s of that many client processes (one
  c172p each, flown by its autopilot at 10 Hz) in lockstep with a real server on loopback.
  Two teams: best of alternating rounds, beside clients that sleep on every reply
  (``spin_us=0``) and clients pinned to a CPU each; the median is printed too.
- manual_loop_p99_period_error_ms: timing of the real-time manual session (30 Hz, GUI and
  recording on, injected keyboard input).

Each side is timed in alternating rounds and the best round of each is compared, so a busy
moment on the machine does not land on one side only.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))


def best_rate(fns: dict[str, Callable[[int], None]], steps: int, rounds: int) -> dict[str, float]:
    """Steps per second of each function, best of ``rounds`` alternating rounds."""
    best = dict.fromkeys(fns, 0.0)
    for _ in range(rounds):
        for name, fn in fns.items():
            t0 = time.perf_counter()
            fn(steps)
            best[name] = max(best[name], steps / (time.perf_counter() - t0))
    return best


def env_vs_raw(steps: int, rounds: int) -> dict[str, float]:
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

    # The reference: the same JSBSim model and I/O with nothing around it.
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

    rates = best_rate({"env": run_env, "raw": run_raw}, steps, rounds)
    return {"env": rates["env"], "raw": rates["raw"], "ratio": rates["env"] / rates["raw"]}


def eight_vs_one(steps: int, rounds: int) -> dict[str, float]:
    from gymfg_il import Team
    from gymfg_il.aircraft import c172p
    from gymfg_il.envs import OfflineEnv
    from gymfg_il.tasks import ReachStaticTargetAltitudeTask

    def make(n: int) -> tuple[OfflineEnv, Team, np.ndarray]:
        team = Team("red", [(c172p(f"red-{i}"), ReachStaticTargetAltitudeTask) for i in range(n)])
        env = OfflineEnv()
        env.reset(team, seed=0)
        return env, team, np.tile([0.0, 0.0, 0.0, 0.75], n)

    one, eight = make(1), make(8)

    def runner(case: tuple[OfflineEnv, Team, np.ndarray]) -> Callable[[int], None]:
        env, team, action = case

        def run(n: int) -> None:
            env.reset(team, seed=0)
            for _ in range(n):
                info = env.step(action)[-1]
            # a terminated aircraft is no longer simulated and would flatter the figure
            assert not any(info["terminated"]), info["reasons"]

        return run

    rates = best_rate({"1": runner(one), "8": runner(eight)}, steps, rounds)
    per_one, per_eight = rates["1"], rates["8"] * 8
    return {"one": per_one, "eight": per_eight, "ratio": per_eight / per_one}


def dataset_build(episodes: int) -> dict[str, float]:
    """Frames/s of ``build_from_logs`` (reading the MCAP logs included) against LeRobot's
    per-frame path (``add_frame`` + ``save_episode`` from frames already in memory)."""
    import os
    import shutil
    import tempfile

    os.environ.setdefault("HF_HUB_OFFLINE", "1")
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    from gymfg_il.collectors.autopilot import record_autopilot
    from gymfg_il.collectors.config import CollectConfig
    from gymfg_il.datasets.features import dataset_features
    from gymfg_il.datasets.from_logs import build_from_logs, episode_columns
    from gymfg_il.recording.reader import read_log

    tmp = Path(tempfile.mkdtemp(prefix="gymfg-bench-"))
    try:
        cfg = CollectConfig(episodes=episodes, out=tmp / "session")
        result = record_autopilot(cfg)
        t0 = time.perf_counter()
        report = build_from_logs([result.log], tmp / "ours")
        ours = report.frames / (time.perf_counter() - t0)

        log = read_log(result.log)
        names = log.session["observation_names"]
        task = log.session["task_description"]
        t0 = time.perf_counter()
        ds = LeRobotDataset.create(
            "gymfg/bench", 10, dataset_features(names), root=tmp / "stock", use_videos=False
        )
        frames = 0
        for ep in log.complete_episodes:
            cols = episode_columns(ep, "ego")
            for i in range(len(cols["action"])):
                ds.add_frame(
                    {
                        "observation.state": cols["observation.state"][i].astype(np.float32),
                        "action": cols["action"][i].astype(np.float32),
                        "next.reward": np.array([cols["next.reward"][i]], np.float32),
                        "next.done": np.array([cols["next.done"][i]]),
                        "intervention": np.array([cols["intervention"][i]]),
                        "task": task,
                    }
                )
                frames += 1
            ds.save_episode()
        ds.finalize()
        stock = frames / (time.perf_counter() - t0)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return {"ours": ours, "stock": stock, "ratio": ours / stock}


def train_pipeline(dataset: Path, stock_items: int) -> dict[str, float]:
    """Frames/s delivered to the model: our in-memory tensor batches against stock
    ``LeRobotDataset`` + ``torch.utils.data.DataLoader`` (per-item ``__getitem__``)."""
    import os

    os.environ.setdefault("HF_HUB_OFFLINE", "1")
    import torch
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    from gymfg_il.learning.data import TensorBatches, load_frames

    frames = load_frames(dataset)
    batches = TensorBatches(frames, 256, seed=0)
    t0 = time.perf_counter()
    delivered = 0
    for _ in range(20):
        for obs, _act in batches:
            delivered += len(obs)
    ours = delivered / (time.perf_counter() - t0)

    ds = LeRobotDataset("gymfg/bench", root=dataset, video_backend="pyav")
    subset = torch.utils.data.Subset(ds, range(stock_items))
    loader = torch.utils.data.DataLoader(subset, batch_size=256, shuffle=True, num_workers=0)
    t0 = time.perf_counter()
    delivered = 0
    for batch in loader:
        delivered += len(batch["action"])
    stock = delivered / (time.perf_counter() - t0)
    return {"ours": ours, "stock": stock, "ratio": ours / stock}


def _burn(n: int) -> int:
    x = 0
    for i in range(n):
        x += i * i
    return x


def cpu_ceiling(rounds: int) -> float:
    """What two processes of pure Python get over one on this machine right now (the
    ceiling of any 2-worker speed-up; on a shared VM it moves from run to run)."""
    import multiprocessing as mp

    n = 3_000_000
    best = 0.0
    for _ in range(rounds):
        t0 = time.perf_counter()
        _burn(n)
        _burn(n)
        one = time.perf_counter() - t0
        with mp.get_context("fork").Pool(2) as pool:
            t0 = time.perf_counter()
            pool.map(_burn, [n, n])
            two = time.perf_counter() - t0
        best = max(best, one / two)
    return best


def rollout_workers(episodes: int, rounds: int) -> dict[str, float]:
    """Wall time of evaluation episodes (controller, altitude, c172p, 90 s) in this process,
    on 2 workers that have flown another task before (kept, as ``eval`` keeps them for its
    next agent),
    and on a new 2-worker pool (its start and warm-up included); best of alternating
    rounds. Each round's kept pool lives for that round only: a pool's threads, left
    running, would make the new pool start by forkserver instead of fork."""
    from gymfg_il.evaluation.parallel import fly_many
    from gymfg_il.parallel import AgentSpec, EnvSpec, Workers

    spec, agent, seeds = EnvSpec(), AgentSpec.controller(), range(episodes)
    best = {"one": float("inf"), "kept": float("inf"), "new": float("inf")}
    results = {}
    for _ in range(rounds):
        for side in best:
            if side != "kept":
                t0 = time.perf_counter()
                results[side] = fly_many(spec, agent, seeds, workers={"one": 1, "new": 2}[side])
                best[side] = min(best[side], time.perf_counter() - t0)
                continue
            with Workers(2) as kept:
                # earlier work, as eval's previous agent: another task, so the timed call
                # still builds its own env and agent in every worker
                fly_many(EnvSpec("roll"), agent, range(1000, 1004), workers=kept)
                t0 = time.perf_counter()
                results[side] = fly_many(spec, agent, seeds, workers=kept)
                best[side] = min(best[side], time.perf_counter() - t0)
    for side in ("kept", "new"):
        pairs = zip(results["one"], results[side], strict=True)
        assert all((a.rewards == b.rewards).all() for a, b in pairs), "workers changed results"
    return {**best, "ratio": best["one"] / best["kept"], "ratio_new": best["one"] / best["new"]}


def manual_loop(seconds: float) -> dict[str, float]:
    """p99 |frame period - 1/30 s| of the manual session at 30 Hz with the GUI and recording
    on, flown by injected keyboard input (pygame's dummy video driver)."""
    import os
    import tempfile

    os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
    import pygame

    from gymfg_il.manual.session import ManualSession
    from gymfg_il.parallel import EnvSpec

    frames = int(seconds * 30)
    keys = [pygame.K_LEFT, pygame.K_UP, pygame.K_RIGHT, pygame.K_DOWN]

    def on_frame(frame: int, session: ManualSession) -> None:
        if frame == 1:
            kind, key = pygame.KEYDOWN, pygame.K_SPACE
        elif frame % 15 == 0:  # a key goes down or up twice a second
            kind = pygame.KEYDOWN if frame % 30 == 0 else pygame.KEYUP
            key = keys[(frame // 30) % 4]
        else:
            return
        pygame.event.post(pygame.event.Event(kind, key=key, mod=0, unicode="", scancode=0))

    with tempfile.TemporaryDirectory() as tmp:
        spec = EnvSpec("altitude", "c172p", episode_time_s=seconds + 5, agent_hz=30)
        stats = ManualSession(spec, Path(tmp), on_frame=on_frame).run(max_frames=frames)
    errors = np.abs(np.array(stats.periods[2:]) - 1 / 30) * 1000
    return {
        "p99": float(np.percentile(errors, 99)),
        "median": float(np.median(errors)),
        "frames": len(errors),
    }


def online_client(
    address: str,
    name: str,
    steps: int,
    cpu: int | None = None,
    spin_us: float = 1000.0,
    batch_io: bool = True,
) -> None:
    """One team of one c172p flying ``steps`` lockstep steps; prints its steps/s."""
    from gymfg_il import Team
    from gymfg_il.aircraft import c172p
    from gymfg_il.controllers.autopilot import controller_for
    from gymfg_il.online.client import OnlineEnv
    from gymfg_il.tasks import LevelFlightTask

    team = Team(name, [(c172p(f"{name}-1"), LevelFlightTask)], episode_time_s=steps / 10 + 10)
    env = OnlineEnv(address, timeout_s=60, cpu=cpu, spin_us=spin_us, batch_io=batch_io)
    (obs,), _ = env.reset(team, seed=0)
    assert env.world is not None
    slot = env.world.slots[0]
    pilot = controller_for(slot.task, "c172p", env.dt, 0.75)
    t0 = time.perf_counter()
    for _ in range(steps):
        (obs,), *_ = env.step(pilot.act(obs))
    print(f"RATE {steps / (time.perf_counter() - t0)}", flush=True)
    env.close()


def bare_client(address: str, name: str, steps: int) -> None:
    """The messaging alone: one team reporting a fixed state every step, no simulation,
    sending and waiting as OnlineEnv does (batched I/O thread, polling)."""
    import os

    import zmq

    from gymfg_il.online.protocol import decode, encode
    from gymfg_il.online.threads import first_socket
    from gymfg_il.sim.properties import NAMES

    sock = first_socket(zmq.Context(), zmq.DEALER, batch=True)
    sock.connect(address)
    sock.send(encode({"type": "join", "team": name, "token": "", "aircraft": {name: "c172p"}}))
    decode(sock.recv(), "server")
    report = encode(
        {"type": "report", "team": name, "token": "", "states": {name: [0.5] * len(NAMES)}}
    )

    def recv() -> bytes:  # poll, yielding the CPU, for up to 1 ms
        deadline = time.perf_counter() + 1e-3
        while time.perf_counter() < deadline:
            try:
                return sock.recv(zmq.NOBLOCK)
            except zmq.Again:
                os.sched_yield()
        return sock.recv()

    t0 = time.perf_counter()
    for _ in range(steps):
        sock.send(report)
        os.sched_yield()
        while decode(recv(), "server")["type"] != "central":
            pass
    print(f"RATE {steps / (time.perf_counter() - t0)}", flush=True)
    sock.close(0)


def online(
    teams: int,
    steps: int,
    bare: bool = False,
    pinned: bool = False,
    spin_us: float = 1000.0,
    batch_io: bool = True,
) -> float:
    """Simulation steps/s of ``teams`` client processes in lockstep with a real server
    (``bare``: clients that only report, the messaging's own ceiling; ``pinned``: each
    client on a CPU of its own, ``OnlineEnv(cpu=i)``, as teams on separate machines;
    ``spin_us``: how long clients poll for a reply before sleeping on it; ``batch_io``:
    the ZeroMQ I/O threads of server and clients under SCHED_BATCH)."""
    import os

    cpus = sorted(os.sched_getaffinity(0))
    import socket
    import subprocess

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    server = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "gymfg_il.serve",
            "--mode",
            "fixed",
            "--teams",
            str(teams),
            "--port",
            str(port),
            "--batch-io" if batch_io else "--no-batch-io",
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
    )
    try:
        assert server.stdout is not None and b"serving" in server.stdout.readline()
        address = f"tcp://127.0.0.1:{port}"
        clients = [
            subprocess.Popen(
                [
                    sys.executable,
                    __file__,
                    "--bare-client" if bare else "--online-client",
                    address,
                    f"team{i}",
                    str(steps),
                    *(
                        []
                        if bare
                        else [
                            str(cpus[i % len(cpus)] if pinned else -1),
                            str(spin_us),
                            str(int(batch_io)),
                        ]
                    ),
                ],
                stdout=subprocess.PIPE,
            )
            for i in range(teams)
        ]
        rates = []
        for c in clients:
            out = c.communicate(timeout=600)[0].decode()
            rates += [
                float(line.split()[1]) for line in out.splitlines() if line.startswith("RATE")
            ]
        return min(rates)  # lockstep: the simulation runs at its slowest team's pace
    finally:
        server.terminate()
        server.wait(10)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("--json", type=Path, help="write the rows to this JSON file")
    p.add_argument("--quick", action="store_true", help="fewer, shorter rounds (a smoke run)")
    p.add_argument(
        "--online-client",
        nargs=6,
        metavar="ADDRESS TEAM STEPS CPU SPIN_US BATCH_IO",
        help=argparse.SUPPRESS,
    )
    p.add_argument(
        "--bare-client", nargs=3, metavar=("ADDRESS", "TEAM", "STEPS"), help=argparse.SUPPRESS
    )
    args = p.parse_args(argv)
    if args.online_client:
        address, team, steps, cpu, spin, batch = args.online_client
        online_client(
            address,
            team,
            int(steps),
            int(cpu) if int(cpu) >= 0 else None,
            float(spin),
            batch == "1",
        )
        return 0
    if args.bare_client:
        bare_client(args.bare_client[0], args.bare_client[1], int(args.bare_client[2]))
        return 0
    steps, rounds = (200, 2) if args.quick else (900, 7)
    rows: list[dict[str, object]] = []

    def row(
        name: str,
        value: float,
        unit: str,
        target: float | None,
        higher_is_better: bool = True,
        **extra: object,
    ) -> None:
        rows.append(
            {
                "name": name,
                "value": value,
                "unit": unit,
                "target": target,
                "higher_is_better": higher_is_better,
                **extra,
            }
        )

    r = env_vs_raw(steps, rounds)
    print(f"env.step (c172p, 10 Hz)          {r['env']:11,.0f} steps/s")
    print(f"raw FGFDMExec, same I/O          {r['raw']:11,.0f} steps/s")
    print(f"env_step_vs_raw_jsbsim           {r['ratio']:11.3f}   (target >= 0.90)\n")
    row("env_step_vs_raw_jsbsim", r["ratio"], "ratio", 0.90)

    r = eight_vs_one(steps // 2, rounds)
    print(f"1 aircraft                       {r['one']:11,.0f} aircraft-steps/s")
    print(f"8 aircraft                       {r['eight']:11,.0f} aircraft-steps/s")
    print(f"per_aircraft_8_vs_1              {r['ratio']:11.3f}   (target >= 0.85)\n")
    row("per_aircraft_8_vs_1", r["ratio"], "ratio", 0.85)

    r = rollout_workers(6 if args.quick else 16, 2 if args.quick else 4)
    print(f"rollouts, 1 worker               {r['one']:11.2f} s")
    print(f"rollouts, 2 workers, new pool    {r['new']:11.2f} s  ({r['ratio_new']:.2f}x)")
    print(f"rollouts, 2 workers, kept        {r['kept']:11.2f} s")
    print(
        f"rollout_workers_2_vs_1           {r['ratio']:11.2f}x  (target >= 1.8; "
        f"pure-Python 2-process ceiling here now: {cpu_ceiling(3):.2f}x)\n"
    )
    row("rollout_workers_2_vs_1", r["ratio"], "ratio", 1.8, new_pool_ratio=r["ratio_new"])

    r = dataset_build(5 if args.quick else 20)
    print(f"LeRobot add_frame+save_episode   {r['stock']:11,.0f} frames/s (from memory)")
    print(
        f"dataset_build_frames_per_s       {r['ours']:11,.0f} frames/s (from MCAP logs), "
        f"{r['ratio']:.1f}x  (target >= 20,000)\n"
    )
    row("dataset_build_frames_per_s", r["ours"], "frames/s", 20000)

    r = manual_loop(5 if args.quick else 20)
    print(
        f"manual loop at 30 Hz (GUI + MCAP), {r['frames']} frames: period error median "
        f"{r['median']:.2f} ms"
    )
    print(f"manual_loop_p99_period_error_ms  {r['p99']:11.2f} ms  (target < 5)\n")
    row("manual_loop_p99_period_error_ms", r["p99"], "ms", 5.0, higher_is_better=False)

    bare = online(2, 300 if args.quick else 3000, bare=True)
    print(
        f"2 teams, messaging alone (no simulation) {bare:9,.0f} steps/s  (the lockstep's ceiling)"
    )
    sides = {
        "clients that sleep on every reply (spin_us=0)": {"spin_us": 0.0},
        "ZeroMQ I/O threads at the default policy (batch_io off)": {"batch_io": False},
        "each client on its own CPU (OnlineEnv(cpu=i))": {"pinned": True},
        "default (clients poll up to 1 ms; I/O threads batched)": {},
    }
    runs: dict[str, list[float]] = {side: [] for side in sides}
    for _ in range(1 if args.quick else 3):  # alternating rounds: a slow spell hits all sides
        for side, options in sides.items():
            runs[side].append(online(2, 300 if args.quick else 2000, **options))  # type: ignore[arg-type]
    for side, rates in runs.items():
        print(f"2 teams, {side}: best {max(rates):7,.0f}, median {np.median(rates):7,.0f} steps/s")
    sleeping, unbatched, pinned, default = runs.values()
    row("online_2_teams_pinned_steps_per_s", max(pinned), "steps/s", None)
    rate = max(default)
    print(f"online_2_teams_steps_per_s {rate:13,.0f} steps/s  (target >= 2,000)")
    row(
        "online_2_teams_steps_per_s",
        rate,
        "steps/s",
        2000,
        median=float(np.median(default)),
        sleeping_clients=max(sleeping),
        io_threads_default_policy=max(unbatched),
    )
    for teams in (8, 16):
        rate = online(teams, 300 if args.quick else 2000)
        print(f"online_{teams}_teams_steps_per_s {rate:13,.0f} steps/s  (reported, one run)")
        row(f"online_{teams}_teams_steps_per_s", rate, "steps/s", None)
    print()

    sample = Path(__file__).resolve().parents[1] / "datasets/sample-altitude-c172p/dataset"
    r = train_pipeline(sample, 1000 if args.quick else 4000)
    print(f"LeRobotDataset + DataLoader      {r['stock']:11,.0f} frames/s")
    print(
        f"train_pipeline_frames_per_s      {r['ours']:11,.0f} frames/s, {r['ratio']:,.0f}x  "
        "(target >= 500,000)"
    )
    row("train_pipeline_frames_per_s", r["ours"], "frames/s", 500000)

    if args.json:
        args.json.write_text(json.dumps(rows, indent=2))
        print(f"\nwrote {args.json}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
