"""How a client waits for the server: ZeroMQ I/O threads batched or not, a client pinned to
one CPU, and polling while replies are quick, sleeping while they are slow (a fake clock)."""

import os
import time
from pathlib import Path

import pytest
import zmq

from gymfg_il.errors import ConfigError
from gymfg_il.online.client import OnlineEnv

pytestmark = pytest.mark.network


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
