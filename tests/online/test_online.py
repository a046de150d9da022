"""Real server and client processes on loopback."""

import os
import socket
import struct
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import zmq
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gymfg_il.errors import ConfigError
from gymfg_il.online.client import OnlineEnv
from gymfg_il.online.protocol import VERSION, ServerError, decode, encode

pytestmark = pytest.mark.network
HERE = Path(__file__).parent
sys.path.insert(0, str(HERE))
import run_team  # noqa: E402
from waiting import Lines, wait_until  # noqa: E402

ENV = {**os.environ, "PYTHONUNBUFFERED": "1"}


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture
def server(tmp_path):
    """Start ``python -m gymfg_il.serve`` with the test's options; yields its address and
    process (``proc.log``: its stderr, the server's log)."""
    procs = []

    def start(*options):
        port = free_port()
        log = tmp_path / f"server{len(procs)}.log"
        proc = subprocess.Popen(
            [sys.executable, "-m", "gymfg_il.serve", "--port", str(port), *options],
            stdout=subprocess.PIPE,
            stderr=open(log, "w"),  # noqa: SIM115 (the process owns it)
            env=ENV,
        )
        proc.log = log
        procs.append(proc)
        assert b"serving" in proc.stdout.readline()
        return f"tcp://127.0.0.1:{port}", proc

    yield start
    for proc in procs:
        proc.terminate()
        proc.wait(10)


def client(address, token, team, seed, seconds, out, spin_us=1000, rejoin=False):
    """A team's client process (``run_team.py``); with ``rejoin``, it keeps trying to join
    while the server says the team is connected."""
    return subprocess.Popen(
        [
            sys.executable,
            str(HERE / "run_team.py"),
            address,
            token,
            team,
            str(seed),
            str(seconds),
            str(out),
            str(spin_us),
            *(["rejoin"] if rejoin else []),
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        env=ENV,
    )


def test_online_run_matches_the_offline_env_bit_for_bit(server, tmp_path):
    address, _ = server("--mode", "fixed", "--teams", "2", "--secret", "s")
    # red polls for the server's replies (the default), blue sleeps on them at once
    red = client(address, "s", "red", 5, 6, tmp_path / "red.npy")
    blue = client(address, "s", "blue", 5, 6, tmp_path / "blue.npy", spin_us=0)
    for proc in (red, blue):
        out = proc.communicate(timeout=60)[0].decode()
        assert proc.returncode == 0, out
    online_red, online_blue = np.load(tmp_path / "red.npy"), np.load(tmp_path / "blue.npy")

    teams = run_team.teams(6)
    blue_states = []
    # the same two teams in one offline simulation, seeded alike
    from gymfg_il.envs import EnvConfig, World

    world = World([teams["red"], teams["blue"]], EnvConfig())
    world.reset(np.random.default_rng(5))
    agents = {
        s.callsign: run_team.controller_for(
            s.task, s.aircraft.model, world.dt, s.aircraft.profile.cruise_throttle
        )
        for s in world.slots
    }
    red_states = []
    for _ in range(60):
        actions = [
            tuple(np.clip(agents[s.callsign].act(world.observation(s)), [-1, -1, -1, 0], 1))
            for s in world.slots
        ]
        world.advance(actions)
        red_states.append(np.stack([s.state for s in world.team_slots["red"]]))
        blue_states.append(np.stack([s.state for s in world.team_slots["blue"]]))
    world.close()
    assert online_red.shape == (60, 2, len(red_states[0][0]))
    assert np.array_equal(online_red, np.array(red_states))
    assert np.array_equal(online_blue, np.array(blue_states))


def test_the_k_plus_first_team_is_refused(server):
    address, _ = server("--mode", "fixed", "--teams", "1")
    teams = run_team.teams(3)
    first = OnlineEnv(address)
    first.reset(teams["red"], seed=0)  # k = 1: the simulation has its team
    second = OnlineEnv(address, timeout_s=5)
    with pytest.raises(ServerError, match="full"):
        second.reset(teams["blue"], seed=0)
    first.close()
    second.close()


def test_a_killed_client_neither_hangs_nor_crashes_the_others_and_can_rejoin(server, tmp_path):
    address, srv = server(
        "--mode", "fixed", "--teams", "2", "--secret", "s", "--timeout", "1", "--on-stall", "drop"
    )
    red = client(address, "s", "red", 1, 300, tmp_path / "red.npy")
    blue = client(address, "s", "blue", 1, 300, tmp_path / "blue.npy")
    procs = [red, blue]
    try:
        red_out, blue_out = Lines(red), Lines(blue)
        blue_out.wait_for("step 1")
        # blue's second life starts up while blue flies (seconds on a busy machine) and
        # tries to join until the server has dropped blue, so red, flying alone once blue
        # is dropped, cannot finish before blue is back
        again = client(address, "s", "blue", 1, 300, tmp_path / "blue2.npy", rejoin=True)
        procs.append(again)
        again_out = Lines(again)
        assert "already connected" in again_out.wait_for("refused")
        blue.kill()
        blue.wait()
        # deadlines on silence: a slow lockstep passes, a hung one fails
        assert red_out.wait_for("done ") == "done 3000 team red completed", red_out.tail()
        assert "team red completed" in again_out.wait_for("done "), again_out.tail()
        assert red.wait(60) == 0 and again.wait(60) == 0
        assert "dropped team blue" in srv.log.read_text()  # after its 1 s timeout
        assert srv.poll() is None  # the server is still serving
    finally:
        for proc in procs:
            if proc.poll() is None:
                proc.kill()
                proc.wait()


def test_wrong_token_and_foreign_aircraft_are_refused(server):
    address, _ = server("--mode", "open", "--team", "red:r3d", "--team", "blue:blu3")
    teams = run_team.teams(3)
    with pytest.raises(ServerError, match="unauthorised"):
        OnlineEnv(address, token="guess", timeout_s=5).reset(teams["red"], seed=0)
    sock = zmq.Context.instance().socket(zmq.DEALER)
    sock.connect(address)
    sock.send(
        encode({"type": "join", "team": "red", "token": "r3d", "aircraft": {"red-1": "c172p"}})
    )
    assert decode(sock.recv(), "server")["type"] == "welcome"
    state = [0.0] * 26
    sock.send(
        encode(
            {
                "type": "report",
                "team": "red",
                "token": "r3d",
                "states": {"blue-1": state},
                "done": False,
            }
        )
    )
    reply = decode(sock.recv(), "server")
    assert reply["type"] == "error" and reply["code"] == "forbidden"
    sock.close(0)


def test_a_team_receives_only_the_opponent_view(server):
    address, _ = server("--mode", "open", "--view", "altitude_ft", "heading_deg")
    ctx = zmq.Context.instance()
    socks = {}
    for team, callsign in (("red", "red-1"), ("blue", "blue-1")):
        socks[team] = ctx.socket(zmq.DEALER)
        socks[team].connect(address)
        socks[team].send(encode({"type": "join", "team": team, "aircraft": {callsign: "c172p"}}))
        assert decode(socks[team].recv(), "server")["type"] == "welcome"
    secret = [float(i) for i in range(26)]  # every variable distinct
    socks["blue"].send(encode({"type": "report", "team": "blue", "states": {"blue-1": [0.0] * 26}}))
    decode(socks["blue"].recv(), "server")  # blue alone: tick 0
    socks["red"].send(encode({"type": "report", "team": "red", "states": {"red-1": secret}}))

    def blue_sees_red():  # blue flies alone until red's report joins it to the lockstep
        socks["blue"].send(
            encode({"type": "report", "team": "blue", "states": {"blue-1": [0.0] * 26}})
        )
        central = decode(socks["blue"].recv(), "server")
        assert central["type"] == "central"
        return central["opponents"]

    opponents = wait_until(blue_sees_red, "red in blue's central state")
    assert opponents == [["red-1", "red", [2.0, 6.0]]]  # altitude, heading only
    for s in socks.values():
        s.close(0)


@settings(max_examples=150, deadline=None, suppress_health_check=list(HealthCheck))
@given(
    payload=st.one_of(
        st.binary(max_size=300),
        st.recursive(
            st.one_of(
                st.none(), st.booleans(), st.integers(-(2**63), 2**64 - 1), st.floats(), st.text()
            ),
            lambda inner: (
                st.lists(inner, max_size=4)
                | st.dictionaries(st.text(max_size=8), inner, max_size=4)
            ),
            max_leaves=12,
        ),
        st.fixed_dictionaries(
            {
                "v": st.just(VERSION),
                "type": st.sampled_from(["join", "report", "leave"]),
                "team": st.text(max_size=70),
                "states": st.dictionaries(
                    st.text(max_size=5), st.lists(st.floats(), max_size=27), max_size=3
                ),
            }
        ),
    )
)
def test_fuzzed_messages_never_crash_the_server(fuzz_server, payload):
    _address, sock = fuzz_server
    import msgpack

    data = payload if isinstance(payload, bytes) else msgpack.packb(payload, use_bin_type=True)
    sock.send(data)
    if sock.poll(2000):
        reply = decode(sock.recv(), "server")
        assert reply["type"] in ("error", "welcome", "central")


@pytest.fixture(scope="module")
def fuzz_server():
    port = free_port()
    proc = subprocess.Popen(
        [sys.executable, "-m", "gymfg_il.serve", "--mode", "open", "--port", str(port)],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        env=ENV,
    )
    assert b"serving" in proc.stdout.readline()
    address = f"tcp://127.0.0.1:{port}"
    sock = zmq.Context.instance().socket(zmq.DEALER)
    sock.connect(address)
    yield address, sock
    sock.close(0)
    # after all the garbage, a real team still flies
    teams = run_team.teams(1)
    env = OnlineEnv(address, timeout_s=10)
    states, _ = run_team.fly(env, teams["red"], 0)
    env.close()
    alive = proc.poll() is None
    proc.terminate()
    proc.wait(5)
    assert alive and len(states) == 10


def io_thread_policies(pid, besides=()):
    """Thread id -> scheduling policy of each ZeroMQ I/O thread of process ``pid``, other
    than those ``besides``; waits for one (a new thread names itself once it runs)."""
    tasks = Path(f"/proc/{pid}/task")
    for _ in range(2000):
        found = {
            t.name: os.sched_getscheduler(int(t.name))
            for t in tasks.iterdir()
            if (t / "comm").read_text().startswith("ZMQbg/IO") and t.name not in besides
        }
        if found:
            return found
        time.sleep(0.001)
    return {}


@pytest.mark.skipif(not Path("/proc/self/task").is_dir(), reason="Linux only")
def test_io_threads_run_batched_unless_told_not_to(server):
    _, batched = server("--mode", "open")
    _, default = server("--mode", "open", "--no-batch-io")
    assert list(io_thread_policies(batched.pid).values()) == [os.SCHED_BATCH]
    assert list(io_thread_policies(default.pid).values()) == [os.SCHED_OTHER]
    for batch_io, policy in ((True, os.SCHED_BATCH), (False, os.SCHED_OTHER)):
        before = {t.name for t in Path("/proc/self/task").iterdir()}
        env = OnlineEnv("tcp://127.0.0.1:1", batch_io=batch_io)
        new = io_thread_policies(os.getpid(), besides=before)
        env.close()
        assert list(new.values()) == [policy]  # the client's own thread


def test_a_pinned_client_runs_on_its_cpu_and_refuses_one_it_may_not_use():
    import threading

    before = os.sched_getaffinity(0)
    cpu = sorted(before)[-1]
    seen = {}

    def client():  # in a thread: pinning applies to the calling thread only
        env = OnlineEnv("tcp://127.0.0.1:1", cpu=cpu)
        seen["affinity"] = os.sched_getaffinity(0)
        env.close()

    def pinned_then_closed():
        client()
        seen["after"] = os.sched_getaffinity(0)

    thread = threading.Thread(target=pinned_then_closed)
    thread.start()
    thread.join(30)
    assert seen["affinity"] == {cpu}
    assert seen["after"] == before  # close() gives the thread its CPUs back
    assert os.sched_getaffinity(0) == before  # the rest of the process is left alone
    with pytest.raises(ConfigError, match="cpu=4096"):
        OnlineEnv("tcp://127.0.0.1:1", cpu=4096)


@pytest.mark.parametrize("spin_us", [-1.0, float("nan"), float("inf"), "fast", True, 2e6])
def test_a_bad_polling_time_is_refused_by_name(spin_us):
    with pytest.raises(ConfigError, match=f"spin_us={spin_us!r}"):
        OnlineEnv("tcp://127.0.0.1:1", spin_us=spin_us, timeout_s=1.0)


class SlowServer:
    """A socket whose replies arrive ``delay`` seconds (of a fake clock) after a wait
    begins; counts the polls (non-blocking tries) and the blocking receives."""

    def __init__(self):
        self.now, self.delay, self.ready_at = 0.0, 0.0, None
        self.polls = self.sleeps = 0

    def clock(self):
        self.now += 20e-6  # every look at the clock costs 20 us
        return self.now

    def recv(self, flags=0):
        if self.ready_at is None:
            self.ready_at = self.now + self.delay
        if flags & zmq.NOBLOCK:
            self.polls += 1
            if self.now < self.ready_at:
                raise zmq.Again()
        else:
            self.sleeps += 1
            self.now = max(self.now, self.ready_at)
        self.ready_at = None
        return b"reply"

    def close(self, linger=0):
        pass


def test_a_client_polls_while_replies_are_quick_and_sleeps_while_they_are_slow():
    env = OnlineEnv("tcp://127.0.0.1:1", spin_us=1000)
    fake = SlowServer()
    env.link.sock.close(0)
    env.link.sock, env.link._clock = fake, fake.clock

    def waits(delay, n):
        fake.delay, fake.polls, fake.sleeps = delay, 0, 0
        for _ in range(n):
            assert env.link.recv() == b"reply"
        return fake.polls, fake.sleeps

    polls, sleeps = waits(300e-6, 20)  # quick replies: caught by polling, never slept on
    assert polls > 20 and sleeps == 0
    waits(5.0, 1)  # one long wait (a join, a reset) ...
    polls, sleeps = waits(300e-6, 5)  # ... does not turn polling off
    assert sleeps == 0
    waits(3e-3, 30)  # replies slower than spin_us, step after step: polling stops
    polls, sleeps = waits(3e-3, 5)
    assert polls == 0 and sleeps == 5
    polls, sleeps = waits(100e-6, 40)  # quick again: polling comes back
    assert fake.polls > 0 and waits(100e-6, 5)[1] == 0
    env.close()


def test_a_teams_views_show_its_opponents_as_traffic(server, tmp_path):
    """Every opponent the server lets the team see reaches the team's FlightGear view as
    multiplayer traffic, with the position the team received; the viewer itself does not."""
    from gymfg_il.viz import multiplayer as mp

    address, _ = server("--mode", "fixed", "--teams", "2")
    rx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    for port in range(23000, 32000):
        try:
            rx.bind(("127.0.0.1", port))
            break
        except OSError:
            continue
    rx.settimeout(10)
    blue = client(address, "", "blue", 0, 3, tmp_path / "blue.npy")
    env = OnlineEnv(address, timeout_s=20, traffic={"red-1": [rx.getsockname()[1]]})
    _, opponents = env.reset(run_team.teams(3)["red"], seed=0)
    for _ in range(5):
        _, opponents, *_ = env.step(np.zeros(8))
    env.close()
    blue.wait(30)
    packets = {}
    rx.setblocking(False)
    while True:
        try:
            data = rx.recv(1024)
        except BlockingIOError:
            break
        callsign = mp.HEADER.unpack_from(data)[-1].rstrip(b"\0").decode()
        packets[callsign] = struct.unpack_from(">3d", data, mp.HEADER.size + 96 + 16)
    rx.close()
    assert set(packets) == {"red-2", "blue-1"}  # teammate and opponent, not the viewer
    lat, lon, alt = opponents[0][:3]  # what the team saw of blue-1 (the view before the end)
    assert np.allclose(packets["blue-1"], mp.ecef(lat, lon, alt), atol=200)


def test_reward_targets_read_the_view_the_server_announces(server):
    """A reward that reads an opponent sees the variables the server sends, by name, even
    when the server's view is not the default one."""
    import threading
    from functools import partial

    from gymfg_il import Team
    from gymfg_il.aircraft import c172p
    from gymfg_il.sim.properties import INDEX
    from gymfg_il.tasks import DummyTask

    address, _ = server("--mode", "open", "--view", "heading_deg", "airspeed_kts")
    blue = zmq.Context.instance().socket(zmq.DEALER)
    blue.connect(address)
    blue.send(encode({"type": "join", "team": "blue", "aircraft": {"blue-1": "c172p"}}))
    assert decode(blue.recv(), "server")["type"] == "welcome"
    state = [0.0] * 26
    state[INDEX["heading_deg"]], state[INDEX["airspeed_kts"]] = 123.0, 98.0

    done = threading.Event()
    blue.setsockopt(zmq.RCVTIMEO, 10000)

    def fly_blue():  # reports until red has flown, so red always meets it in the lockstep
        while not done.is_set():
            blue.send(encode({"type": "report", "team": "blue", "states": {"blue-1": state}}))
            decode(blue.recv(), "server")

    thread = threading.Thread(target=fly_blue)
    thread.start()
    seen = []
    task = partial(
        DummyTask, reward=lambda ctx: seen.append(ctx.targets["blue-1"]["airspeed_kts"]) or 0.0
    )
    red_one = c172p("red-1")
    red = Team("red", [(red_one, task)], reward_function_targets={red_one: [c172p("blue-1")]})
    env = OnlineEnv(address, timeout_s=20)
    env.reset(red, seed=0)
    for _ in range(2):
        env.step(np.zeros(4))
    done.set()
    env.close()
    thread.join(20)
    blue.close(0)
    assert seen == [98.0, 98.0]


def test_a_team_that_leaves_holds_up_no_one(server):
    """``close`` sends ``leave`` and lets it go out: the other team flies on at once, not
    after the server's stall timeout (60 s here, beyond the client's 5 s), and stops seeing
    the team that left."""
    import threading

    from gymfg_il import Team
    from gymfg_il.aircraft import c172p
    from gymfg_il.tasks import DummyTask

    address, _ = server("--mode", "open", "--timeout", "60")
    blue = OnlineEnv(address, timeout_s=5)
    blue.reset(Team("blue", [(c172p("blue-1"), DummyTask)], episode_time_s=1e4), seed=1)

    def fly_blue():  # alone until red joins, then 5 steps in lockstep with red, then leave
        while "red-1" not in blue.step(np.zeros(4))[5]["opponent_callsigns"]:
            pass
        for _ in range(5):
            blue.step(np.zeros(4))
        blue.close()

    thread = threading.Thread(target=fly_blue)
    thread.start()
    red = OnlineEnv(address, timeout_s=5)
    red.reset(Team("red", [(c172p("red-1"), DummyTask)]), seed=0)
    seen = [red.step(np.zeros(4))[5]["opponent_callsigns"] for _ in range(12)]
    thread.join(10)
    red.close()
    assert seen[0] == ["blue-1"] and seen[-1] == []


def test_an_online_team_run_is_recorded_and_replays_bit_for_bit(server, tmp_path):
    from gymfg_il.recording.reader import read_log
    from gymfg_il.recording.recorder import Recorder
    from gymfg_il.recording.replay import replay_episode

    address, _ = server("--mode", "fixed", "--teams", "2")
    blue = client(address, "", "blue", 5, 3, tmp_path / "blue.npy")
    env = Recorder(OnlineEnv(address, timeout_s=20), tmp_path / "red", source="online")
    states, _ = run_team.fly(env, run_team.teams(3)["red"], 5)
    env.close()
    assert blue.wait(60) == 0
    log = read_log(next((tmp_path / "red" / "logs").glob("*.mcap")))
    assert log.session["online"] and [a.callsign for a in log.spec.aircraft_specs] == [
        "red-1",
        "red-2",
    ]
    (ep,) = log.complete_episodes
    assert np.array_equal(ep.steps["red-1"].state, states[:, 0])
    saw = ep.views("red")
    assert len(saw) == 30 and saw[-1].callsigns == ["blue-1"] and saw[-1].values.shape == (1, 6)
    blue_states = np.load(tmp_path / "blue.npy")
    from gymfg_il.sim.properties import DEFAULT_OPPONENT_VIEW, indices

    assert np.array_equal(saw[-1].values[0], blue_states[-1, 0][indices(DEFAULT_OPPONENT_VIEW)])
    assert replay_episode(log, ep).identical


def test_an_online_reward_on_an_opponent_replays_from_the_views_the_team_saw(server, tmp_path):
    from gymfg_il.aircraft import c172p, f15
    from gymfg_il.envs import Team
    from gymfg_il.recording.reader import read_log
    from gymfg_il.recording.recorder import Recorder
    from gymfg_il.recording.replay import replay_episode

    address, _ = server("--mode", "fixed", "--teams", "2")
    blue = client(address, "", "blue", 5, 3, tmp_path / "blue.npy")
    red = Team(
        "red",
        [(c172p("red-1"), run_team.ChaseTask)],
        reward_function_targets={c172p("red-1"): [f15("blue-1")]},
        episode_time_s=3,
    )
    env = Recorder(OnlineEnv(address, timeout_s=20), tmp_path / "red")
    run_team.fly(env, red, 5)
    env.close()
    assert blue.wait(60) == 0
    log = read_log(next((tmp_path / "red" / "logs").glob("*.mcap")))
    assert log.spec.external_callsigns() == ["blue-1"]
    (ep,) = log.complete_episodes
    rewards = ep.steps["red-1"].reward
    assert np.isfinite(rewards).all() and rewards.std() > 0  # blue's distance moved
    assert replay_episode(log, ep).identical  # states and rewards, from the logged views


def test_a_client_with_multiplayer_shows_flightgear_aircraft_to_its_team_alone(server):
    """A team's client hears FlightGear on its own port: the person follows the server's
    rows and is a reward target until silent; the server relays nothing of them to the
    other team. A sender on this machine plays FlightGear's part."""
    import threading

    from gymfg_il import Team
    from gymfg_il.aircraft import c172p
    from gymfg_il.tasks import DummyTask
    from gymfg_il.viz import multiplayer as mp
    from gymfg_il.viz import peers
    from gymfg_il.viz.peers import MultiplayerConfig

    person_pose = (37.62, -122.37, 3000.0, 20.0, 3.0, 280.0)
    listen, fg_in = free_udp_ports(2)
    address, _ = server("--mode", "open", "--timeout", "60")
    fg = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)  # FlightGear's --multiplay=in
    fg.bind(("127.0.0.1", fg_in))
    fg.settimeout(5)
    person = mp.TrafficSender([listen])
    flying = threading.Event()
    flying.set()

    def fly_person():  # FlightGear sends ~50 times a second while the person flies
        while flying.is_set():
            person.send("person", "c172p", person_pose)
            time.sleep(0.02)

    blue_saw: list[list[str]] = []
    blue = OnlineEnv(address, timeout_s=5)
    blue.reset(Team("blue", [(c172p("blue1"), DummyTask)], episode_time_s=1e4), seed=1)

    def fly_blue():  # until it has met red for 10 steps, then leave
        while len([s for s in blue_saw if "red1" in s]) < 10:
            blue_saw.append(blue.step(np.zeros(4))[5]["opponent_callsigns"])
        blue.close()

    seen = []

    def note_person(ctx):
        view = ctx.targets.get("person")
        seen.append(None if view is None else view.values.copy())
        return 0.0

    red1 = c172p("red1")
    red = Team(
        "red",
        [(red1, DummyTask(reward=note_person))],
        reward_function_targets={red1: [c172p("person")]},
        episode_time_s=1e4,
    )
    config = MultiplayerConfig(listen_port=listen, send_to=[("127.0.0.1", fg_in)], timeout_s=0.5)
    red_env = OnlineEnv(address, timeout_s=5, agent_hz=30, multiplayer=config)
    threads = [threading.Thread(target=fly_person), threading.Thread(target=fly_blue)]
    try:
        for thread in threads:  # blue flies on: red joins the lockstep at a step boundary
            thread.start()
        red_env.reset(red, seed=0)
        both = None  # what red saw while blue and the person were both there
        for _ in range(90):  # in lockstep with blue until it leaves (after 10 steps with red)
            _, rows, rewards, _, _, info = red_env.step(np.zeros(4))
            if both is None and info["opponent_callsigns"] == ["blue1", "person"]:
                both = rows, seen[-1]
            if both is not None and "blue1" not in info["opponent_callsigns"]:
                break
        assert both is not None  # the server's row, then FlightGear's
        rows, target = both
        assert rows.shape == (2, 6) and rows[1] == pytest.approx(person_pose, abs=1e-4)
        assert target == pytest.approx(person_pose, abs=1e-4)
        assert info["opponent_callsigns"] == ["person"]  # blue left; the person flies on
        assert peers.decode(fg.recv(4096)).callsign == "red1"  # our aircraft reaches FlightGear
        threads[1].join(10)
        flying.clear()
        threads[0].join(5)
        for _ in range(30):  # 1 s of silence: dropped after 0.5 s
            _, rows, rewards, _, _, info = red_env.step(np.zeros(4))
        assert info["opponent_callsigns"] == [] and rows.shape == (0, 6)
        assert seen[-1] is None and np.isfinite(rewards).all()
    finally:
        flying.clear()
        for thread in threads:
            if thread.is_alive():
                thread.join(10)
        red_env.close()
        person.close()
        fg.close()
    assert any("red1" in s for s in blue_saw)
    assert not any("person" in s for s in blue_saw)  # not relayed to the other team


def test_multiplayer_needs_a_server_view_flightgear_aircraft_can_fill(server):
    from gymfg_il import Team
    from gymfg_il.aircraft import c172p
    from gymfg_il.tasks import DummyTask
    from gymfg_il.viz.peers import MultiplayerConfig

    address, _ = server("--mode", "open", "--view", "altitude_ft", "airspeed_kts")
    env = OnlineEnv(
        address, timeout_s=5, multiplayer=MultiplayerConfig(listen_port=free_udp_ports(1)[0])
    )
    try:
        with pytest.raises(ConfigError, match=r"\['airspeed_kts'\]"):
            env.reset(Team("red", [(c172p("red1"), DummyTask)]), seed=0)
    finally:
        env.close()


def free_udp_ports(n):
    """``n`` free UDP ports FlightGear could store (below 32768)."""
    found = []
    for port in range(23000 + os.getpid() % 8000, 32000):
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
            try:
                s.bind(("127.0.0.1", port))
            except OSError:
                continue
        found.append(port)
        if len(found) == n:
            return found
    raise RuntimeError("no free UDP ports below 32000")
