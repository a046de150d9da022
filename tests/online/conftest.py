"""Fixtures of the online tests: real server processes on loopback."""

import os
import subprocess
import sys

import pytest
import zmq

ENV = {**os.environ, "PYTHONUNBUFFERED": "1"}


@pytest.fixture
def serve(tmp_path):
    """Start ``python -m gymfg_il.serve OPTIONS`` on a free port; yields (address, process,
    log file: the server's stderr)."""
    procs = []

    def start(*options, expect_serving=True):
        err = tmp_path / f"server{len(procs)}.err"
        proc = subprocess.Popen(
            [sys.executable, "-m", "gymfg_il.serve", "--port", "0", *options],
            stdout=subprocess.PIPE,
            stderr=open(err, "w"),  # noqa: SIM115 (the process owns it)
            env=ENV,
        )
        procs.append(proc)
        if not expect_serving:
            proc.wait(60)
            return None, proc, err
        line = proc.stdout.readline().decode()
        assert "serving" in line, err.read_text()
        return line.split()[-1], proc, err

    yield start
    for proc in procs:
        proc.terminate()
        proc.wait(10)


@pytest.fixture
def server(serve):
    """``serve``, answering (address, process) with ``process.log``: the server's stderr,
    its log."""

    def start(*options):
        address, proc, log = serve(*options)
        proc.log = log
        return address, proc

    return start


@pytest.fixture
def zmq_ctx():
    """A context for a test's raw sockets, destroyed (its sockets closed, nothing lingering)
    after the test, passed or failed. A context left to the garbage collector with a socket
    still holding an unsent message blocks in ``term()``: a test that failed that way once
    hung the rest of a CI run, in whichever later test the collector ran."""
    ctx = zmq.Context()
    yield ctx
    ctx.destroy(linger=0)
