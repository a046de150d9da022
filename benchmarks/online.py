"""The online lockstep: simulation steps/s of client processes (one c172p each, flown by its
autopilot at 10 Hz) in lockstep with a real server on loopback.

Each round measures what the machine gives (2 and 16 teams that only report without
simulating: the messaging alone; one aircraft's physics and autopilot in one process) beside
2 and 16 simulating teams, and rates each against its bound: for 2 teams
1/(1/messaging + 1/physics), for 16 the smaller of the 16-team messaging rate and
cores x physics / 16. Two teams also run beside clients that sleep on every reply
(``spin_us=0``), I/O threads at the default scheduling policy and clients pinned to a CPU each.
8 teams are one run.

    python -m benchmarks.online --client ADDRESS TEAM STEPS CPU SPIN_US BATCH_IO
    python -m benchmarks.online --bare-client ADDRESS TEAM STEPS

are the client processes it starts (they print ``RATE <steps/s>``).
"""

from __future__ import annotations

import argparse
import os
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from benchmarks.common import Row

ROOT = Path(__file__).resolve().parents[1]


def client(
    address: str,
    name: str,
    steps: int,
    cpu: int | None = None,
    spin_us: float = 1000.0,
    batch_io: bool = True,
) -> None:
    """One team of one c172p flying ``steps`` lockstep steps; prints its steps/s."""
    import logging

    # the server's "waiting for N more teams to join" while the others start is the
    # benchmark's start, not news: only errors are shown
    logging.getLogger("gymfg_il.online").setLevel(logging.ERROR)
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


def physics(steps: int) -> float:
    """One aircraft's physics rate: the clients' team (one c172p, its autopilot, 10 Hz) flown
    in this process by ``OfflineEnv``, no messaging; simulation steps/s."""
    from gymfg_il import Team
    from gymfg_il.aircraft import c172p
    from gymfg_il.controllers.autopilot import controller_for
    from gymfg_il.envs import OfflineEnv
    from gymfg_il.tasks import LevelFlightTask

    team = Team("solo", [(c172p("solo-1"), LevelFlightTask)], episode_time_s=steps / 10 + 10)
    env = OfflineEnv()
    (obs,), _ = env.reset(team, seed=0)
    assert env.world is not None
    pilot = controller_for(env.world.slots[0].task, "c172p", env.dt, 0.75)
    t0 = time.perf_counter()
    for _ in range(steps):
        (obs,), *_ = env.step(pilot.act(obs))
    return steps / (time.perf_counter() - t0)


def bare_client(address: str, name: str, steps: int) -> None:
    """The messaging alone: one team reporting a fixed state every step, no simulation,
    sending and waiting as OnlineEnv does (batched I/O thread, polling)."""
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
    alive = encode({"type": "alive", "team": name, "token": ""})  # answers a wait, as a team must

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
        while (kind := decode(recv(), "server")["type"]) != "central":
            if kind == "wait":
                sock.send(alive)
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
    client on a CPU of its own, ``OnlineEnv(cpu=i)``; ``spin_us``: how long clients poll for
    a reply before sleeping on it; ``batch_io``: the ZeroMQ I/O threads of server and
    clients under SCHED_BATCH)."""
    cpus = sorted(os.sched_getaffinity(0))
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    server = subprocess.Popen(
        [
            sys.executable, "-m", "gymfg_il.serve", "--mode", "fixed", "--teams", str(teams),
            "--port", str(port), "--batch-io" if batch_io else "--no-batch-io",
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        cwd=ROOT,
        env=env,
    )  # fmt: skip
    try:
        assert server.stdout is not None and b"serving" in server.stdout.readline()
        address = f"tcp://127.0.0.1:{port}"
        clients = []
        for i in range(teams):
            how = ["--bare-client"] if bare else ["--client"]
            args = [address, f"team{i}", str(steps)]
            if not bare:
                cpu = cpus[i % len(cpus)] if pinned else -1
                args += [str(cpu), str(spin_us), str(int(batch_io))]
            cmd = [sys.executable, "-m", "benchmarks.online", *how, *args]
            clients.append(subprocess.Popen(cmd, stdout=subprocess.PIPE, cwd=ROOT, env=env))
        rates = []
        for c in clients:
            out = c.communicate(timeout=600)[0].decode()
            rates += [float(x.split()[1]) for x in out.splitlines() if x.startswith("RATE")]
        return min(rates)  # lockstep: the simulation runs at its slowest team's pace
    finally:
        server.terminate()
        server.wait(10)


DEFAULT = "default (clients poll up to 1 ms; I/O threads batched)"


def rows(quick: bool) -> list[Row]:
    """Each online rate beside what the machine gives in the same round: the messaging alone
    (clients that report without simulating) and one aircraft's physics alone."""
    steps = 300 if quick else 2000
    sides = {
        "clients that sleep on every reply (spin_us=0)": {"spin_us": 0.0},
        "ZeroMQ I/O threads at the default policy (batch_io off)": {"batch_io": False},
        "each client on its own CPU (OnlineEnv(cpu=i))": {"pinned": True},
        DEFAULT: {},
    }
    runs: dict[str, list[float]] = {side: [] for side in sides}
    bound2, bound16, ratio2, ratio16 = [], [], [], []
    rates16, bare16s, physics_rates = [], [], []
    cores = len(os.sched_getaffinity(0))
    for _ in range(1 if quick else 3):  # alternating rounds: a slow spell hits all sides
        bare2 = online(2, 3 * steps, bare=True)
        solo = physics(steps)
        for side, options in sides.items():
            runs[side].append(online(2, steps, **options))  # type: ignore[arg-type]
        bound2.append(1 / (1 / bare2 + 1 / solo))
        ratio2.append(runs[DEFAULT][-1] / bound2[-1])
        bare16 = online(16, steps // 2, bare=True)
        rate16 = online(16, steps // 2)
        bound16.append(min(bare16, cores * solo / 16))
        ratio16.append(rate16 / bound16[-1])
        rates16.append(rate16)
        bare16s.append(bare16)
        physics_rates.append(solo)
    default = runs[DEFAULT]
    physics_line = (
        f"one c172p's physics and autopilot alone {np.median(physics_rates):9,.0f} steps/s"
    )
    detail2 = [
        physics_line,
        f"2 teams, bound 1/(1/messaging + 1/physics) {np.median(bound2):7,.0f}",
    ]
    detail2 += [
        f"2 teams, {side}: best {max(r):7,.0f}, median {np.median(r):7,.0f} steps/s"
        for side, r in runs.items()
    ]
    detail16 = [
        f"16 teams, messaging alone {np.median(bare16s):7,.0f}; {cores} cores x physics / 16 "
        f"{cores * np.median(physics_rates) / 16:7,.0f}; simulated {np.median(rates16):7,.0f}"
        " steps/s (medians)",
        f"per-round ratios {', '.join(f'{x:.2f}' for x in ratio16)}",
    ]
    sleeping, unbatched, pinned, _ = runs.values()
    return [
        Row(
            "online_2_teams_vs_bound",
            float(np.median(ratio2)),
            "ratio",
            0.85,
            detail=[*detail2, f"per-round ratios {', '.join(f'{x:.2f}' for x in ratio2)}"],
            extra={
                "steps_per_s": float(np.median(default)),
                "bound": float(np.median(bound2)),
                "sleeping_clients": max(sleeping),
                "io_threads_default_policy": max(unbatched),
                "pinned": max(pinned),
            },
        ),
        Row(
            "online_16_teams_vs_bound",
            float(np.median(ratio16)),
            "ratio",
            0.6,
            detail=detail16,
            extra={"steps_per_s": float(np.median(rates16)), "bound": float(np.median(bound16))},
        ),
        Row("online_8_teams_steps_per_s", online(8, steps // 2), "steps/s"),
    ]


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--client", nargs=6, metavar="ARG")
    p.add_argument("--bare-client", nargs=3, metavar="ARG")
    p.add_argument("--rate", nargs=2, type=int, metavar=("TEAMS", "STEPS"), help="one run")
    args = p.parse_args(argv)
    if args.client:
        address, team, steps, cpu, spin, batch = args.client
        client(
            address, team, int(steps), int(cpu) if int(cpu) >= 0 else None, float(spin),
            batch == "1",
        )  # fmt: skip
    elif args.bare_client:
        bare_client(args.bare_client[0], args.bare_client[1], int(args.bare_client[2]))
    elif args.rate:
        print(online(*args.rate))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
