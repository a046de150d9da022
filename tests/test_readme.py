"""The README's snippets run as written."""

import ast
import re
import socket
import subprocess
import sys
from pathlib import Path

import pytest

README = (Path(__file__).resolve().parents[1] / "README.md").read_text()


def python_blocks(containing):
    return [b for b in re.findall(r"```python\n(.*?)```", README, re.S) if containing in b]


@pytest.mark.network
def test_the_online_snippet_flies_two_teams_against_a_real_server(tmp_path):
    (snippet,) = python_blocks("threading.Thread")
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    server = subprocess.Popen(
        [sys.executable, "-m", "gymfg_il.serve", "--mode", "fixed", "--teams", "2",
         "--secret", "s3cret", "--port", str(port)],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
    )  # fmt: skip
    try:
        assert b"serving" in server.stdout.readline()
        script = tmp_path / "snippet.py"
        script.write_text(snippet.replace("5555", str(port)))
        run = subprocess.run(
            [sys.executable, str(script)], capture_output=True, text=True, timeout=120
        )
        assert run.returncode == 0, run.stderr
        seen = ast.literal_eval(run.stdout.strip().splitlines()[-1])
        assert seen == {"red": 1, "blue": 1}
    finally:
        server.terminate()
        server.wait(5)


def test_the_flight_spec_snippet_runs():
    (snippet,) = python_blocks("FlightSpec.solo")
    exec(compile(snippet, "README", "exec"), {})
