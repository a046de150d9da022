"""A team's connection to the central state server: one ZeroMQ DEALER socket, the CPU it
may be pinned to, and the receive loop that polls while replies come fast.

``OnlineEnv`` (``online.client``) speaks the simulation's messages over it; this module
knows only how they travel.
"""

from __future__ import annotations

import logging
import os
import time
from typing import Any

from gymfg_il.errors import ConfigError
from gymfg_il.online.protocol import ProtocolError, ServerError, decode, encode, printable
from gymfg_il.online.threads import first_socket

log = logging.getLogger(__name__)


class ServerLink:
    """The socket to ``address`` (see ``OnlineEnv`` for the arguments)."""

    def __init__(
        self,
        address: str,
        *,
        token: str,
        server_key: bytes | None,
        timeout_s: float,
        cpu: int | None,
        spin_us: float,
        batch_io: bool,
    ) -> None:
        import zmq

        if not (
            isinstance(spin_us, int | float)
            and not isinstance(spin_us, bool)
            and 0 <= spin_us * 1e-6 < timeout_s
        ):
            raise ConfigError(
                f"spin_us={spin_us!r}: give 0 (no polling) or a time in microseconds "
                f"below timeout_s={timeout_s:g} s"
            )
        self.address, self.token, self.timeout_s = address, token, timeout_s
        self._spin_s = spin_us * 1e-6
        self._wait_s = 0.0  # moving average of the wait for a reply
        self._clock = time.perf_counter
        self._affinity: set[int] | None = None  # the calling thread's, while pinned
        if cpu is not None:
            available = os.sched_getaffinity(0)
            if cpu not in available:
                raise ConfigError(f"cpu={cpu!r}: this process may run on CPUs {sorted(available)}")
            self._affinity = available
            os.sched_setaffinity(0, {cpu})  # this thread, and the I/O thread started below
        # the client's own context: its I/O thread starts pinned with it, and batched
        self.ctx: Any = zmq.Context()
        self._batch_io = batch_io
        try:
            self.sock = first_socket(self.ctx, zmq.DEALER, batch_io)
            self.sock.setsockopt(zmq.LINGER, 0)
            self.sock.setsockopt(zmq.RCVTIMEO, int(timeout_s * 1000))
            if server_key is not None:
                public, secret = zmq.curve_keypair()
                self.sock.curve_publickey, self.sock.curve_secretkey = public, secret
                self.sock.curve_serverkey = server_key
            self.sock.connect(address)
        except Exception:
            if hasattr(self, "sock"):
                self.sock.close(0)
            self.release()
            raise
        self._waiting = ""  # the last reason the server gave for making the team wait
        self._team = ""  # the team the last message was sent for
        self.width: int | None = None  # values per opponent row, once the server said

    def request(self, msg: dict[str, Any], team: str, expect: str) -> dict[str, Any]:
        self.send(msg, team)
        return self.receive(expect)

    def send(self, msg: dict[str, Any], team: str) -> None:
        self._team = team
        self.sock.send(encode({**msg, "team": team, "token": self.token}))

    def yield_after_send(self) -> None:
        """Let a batched I/O thread that shares this CPU send now; not while replies are slow
        to come (many teams sharing few CPUs): the yield then hands the CPU to another team
        and costs this one a context switch (16 teams on 2 cores: ~7%)."""
        if self._batch_io and self._wait_s < self._spin_s:
            os.sched_yield()

    def recv(self) -> bytes:
        """The next message: polled for up to ``spin_us`` while replies have been coming
        that fast, else slept on at once (RCVTIMEO bounds the sleep)."""
        import zmq

        clock = self._clock
        start = clock()
        if self._wait_s < self._spin_s:  # (typical waits: many teams sharing CPUs poll less)
            recv, pause = self.sock.recv, os.sched_yield
            deadline = start + self._spin_s
            while True:
                try:
                    data = recv(zmq.NOBLOCK)
                    break
                except zmq.Again:
                    if clock() > deadline:
                        data = self.sock.recv()
                        break
                    pause()  # the I/O thread bringing the reply may need this CPU
        else:
            data = self.sock.recv()
        # a moving average of the waits, each counted as at most twice the polling time, so
        # one long wait (a join, a reset, a paused server) does not turn polling off
        waited = min(clock() - start, 2 * self._spin_s)
        self._wait_s += 0.1 * (waited - self._wait_s)
        return data

    def receive(self, expect: str) -> dict[str, Any]:
        """The next reply, of type ``expect``. An error reply, a malformed message, a reply
        of another type or a silent server is a ``ServerError``; ``wait`` replies are
        answered (the team is still there) and logged once per reason."""
        import zmq

        while True:
            try:
                data = self.recv()
            except zmq.Again:
                raise ServerError(
                    "timeout",
                    f"no answer from {self.address} within "
                    f"{self.timeout_s:g} s; is the server running?",
                ) from None
            try:
                reply = decode(data, "server", self.width)
            except ProtocolError as err:
                raise ServerError("malformed", f"the server sent a bad message: {err}") from None
            kind = reply["type"]
            if kind == expect:
                return reply
            if kind == "error":
                raise ServerError(reply["code"], printable(reply["message"]))
            if kind != "wait":
                raise ServerError(
                    "malformed", f"the server sent a {kind!r} message where a {expect!r} was due"
                )
            # a paused or not yet started simulation
            self.send({"type": "alive"}, self._team)
            reason = printable(reply["reason"])
            if reason != self._waiting:  # said once per reason, not once per second
                log.warning("%s: %s", self.address, reason)
                self._waiting = reason

    def release(self) -> None:
        """End the context and give a pinned thread its CPUs back."""
        if not self.ctx.closed:
            self.ctx.term()  # its socket is closed by now
        if self._affinity is not None:
            os.sched_setaffinity(0, self._affinity)
            self._affinity = None

    def close(self, linger_ms: int) -> None:
        """Close the socket (what is queued gets ``linger_ms`` to go out) and the context."""
        self.sock.close(linger=linger_ms)
        self.release()
