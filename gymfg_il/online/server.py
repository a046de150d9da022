"""The central state server: teams report their aircraft's states every step, the server
assembles the central state and sends each team what it may see of the others.

Modes: ``fixed`` (k teams: the simulation starts when all k have reported, further teams are
refused, it ends when one team completes) and ``open`` (teams join at any step boundary and
leave when they are done). The opponent restriction is applied here, so a client never
receives more than the opponent view. A team that stops reporting for ``timeout_s`` is
dropped (it may rejoin under its name and token), pauses the others, or ends the simulation,
as configured. Malformed and oversized messages are refused with an error reply and logged.
"""

from __future__ import annotations

import hmac
import logging
import time
from dataclasses import dataclass, field
from typing import Any, Literal

from gymfg_il.errors import ConfigError
from gymfg_il.online.protocol import MAX_MESSAGE_BYTES, ProtocolError, decode, encode
from gymfg_il.online.threads import first_socket
from gymfg_il.sim.properties import DEFAULT_OPPONENT_VIEW, indices

log = logging.getLogger(__name__)

MODES = ("fixed", "open")
ON_STALL = ("drop", "pause", "end")


@dataclass
class TeamRecord:
    name: str
    identity: bytes
    token: str
    callsigns: list[str]
    members: frozenset[str] = field(init=False)  # the callsigns, as a set
    active: bool = False  # takes part in the lockstep
    report: dict[str, list[float]] | None = None  # this tick's report
    done: bool = False
    last_seen: float = field(default_factory=time.monotonic)
    states: dict[str, list[float]] = field(default_factory=dict)  # latest

    def __post_init__(self) -> None:
        self.members = frozenset(self.callsigns)


@dataclass
class ServerConfig:
    """Settings of the central state server.

    Attributes:
        mode: fixed: k teams, starts when all joined, ends when one completes; open: teams
            join and leave at step boundaries.
        teams: k, for the fixed mode.
        bind: address to listen on; loopback unless told otherwise.
        port: TCP port (0 picks a free one).
        secrets: team -> secret; a team not listed needs ``shared_secret``.
        shared_secret: one secret every team must present ("" and no per-team secrets = no
            authentication).
        timeout_s: seconds of silence after which a team counts as stalled (while others
            wait).
        on_stall: what a stalled team does to the others: drop it (it may rejoin), pause the
            others, or end the simulation.
        opponent_view: the state variables teams see of each other's aircraft (position and
            orientation by default).
        curve: encrypt with ZeroMQ CURVE; prints the public key clients need.
        batch_io: run the server's ZeroMQ I/O thread under Linux's SCHED_BATCH policy, so
            that the replies of a tick are queued without the I/O thread preempting the
            server after the first one, and go out together when the server next waits
            (see ``gymfg_il.online.threads``). False keeps the default policy.
    """

    mode: Literal["fixed", "open"] = "fixed"
    teams: int = 2
    bind: str = "127.0.0.1"
    port: int = 5555
    secrets: dict[str, str] = field(default_factory=dict, metadata={"cli": False})
    shared_secret: str = field(default="", metadata={"flag": "--secret"})
    timeout_s: float = field(default=5.0, metadata={"flag": "--timeout"})
    on_stall: Literal["drop", "pause", "end"] = "drop"
    opponent_view: tuple[str, ...] = field(
        default=DEFAULT_OPPONENT_VIEW, metadata={"flag": "--view"}
    )
    curve: bool = False
    batch_io: bool = True

    def __post_init__(self) -> None:
        problems = []
        if self.mode not in MODES:
            problems.append(f"mode={self.mode!r}: choose fixed or open")
        if self.mode == "fixed" and self.teams < 1:
            problems.append(f"teams={self.teams}: a fixed simulation needs k >= 1")
        if self.on_stall not in ON_STALL:
            problems.append(f"on_stall={self.on_stall!r}: choose drop, pause or end")
        if not self.timeout_s > 0:
            problems.append(f"timeout_s={self.timeout_s} must be > 0")
        self.opponent_view = tuple(self.opponent_view)
        indices(self.opponent_view)
        if problems:
            raise ConfigError("server: " + "; ".join(problems))


class StateServer:
    """Serve until ``stop()`` (or for ``run(seconds)``)."""

    def __init__(self, config: ServerConfig) -> None:
        import zmq

        self.config = config
        self.ctx = zmq.Context()
        self.sock = first_socket(self.ctx, zmq.ROUTER, config.batch_io)
        self.sock.setsockopt(zmq.LINGER, 0)
        self.sock.setsockopt(zmq.MAXMSGSIZE, 4 * MAX_MESSAGE_BYTES)
        self.auth: Any = None
        self.public_key: bytes | None = None
        if config.curve:
            import zmq.auth
            from zmq.auth.thread import ThreadAuthenticator

            self.auth = ThreadAuthenticator(self.ctx)
            self.auth.start()
            self.auth.configure_curve(domain="*", location=zmq.auth.CURVE_ALLOW_ANY)
            public, secret = zmq.curve_keypair()
            self.sock.curve_secretkey = secret
            self.sock.curve_publickey = public
            self.sock.curve_server = True
            self.public_key = public
        if config.port:
            self.sock.bind(f"tcp://{config.bind}:{config.port}")
            self.port = config.port
        else:
            self.port = self.sock.bind_to_random_port(f"tcp://{config.bind}")
        self.view_idx = indices(tuple(config.opponent_view))
        self._view = self.view_idx.tolist()
        self._last_stall_check = 0.0
        self.teams: dict[str, TeamRecord] = {}
        self.owner: dict[str, str] = {}  # callsign -> team
        self.tick = 0
        self.simulation = 0
        self.running = False  # the lockstep has started
        self.refused = 0
        self._stop = False
        self._paused_notice = 0.0

    @property
    def address(self) -> str:
        return f"tcp://{self.config.bind}:{self.port}"

    # -- plumbing ------------------------------------------------------------------------
    def _send(self, identity: bytes, msg: dict[str, Any]) -> None:
        import zmq

        try:
            self.sock.send_multipart([identity, encode(msg)], flags=zmq.NOBLOCK)
        except zmq.ZMQError as err:  # a vanished peer must not stop the server
            log.warning("could not send to %r: %s", identity, err)

    def _error(self, identity: bytes, code: str, message: str) -> None:
        self.refused += 1
        log.warning("refused a message (%s): %s", code, message)
        self._send(identity, {"type": "error", "code": code, "message": message})

    def _authorised(self, team: str, token: str) -> bool:
        secret = self.config.secrets.get(team, self.config.shared_secret)
        if not secret:
            return True
        return hmac.compare_digest(secret.encode(), str(token).encode())

    # -- requests ------------------------------------------------------------------------
    def _join(self, identity: bytes, msg: dict[str, Any]) -> None:
        name, token = msg["team"], msg.get("token", "")
        if not self._authorised(name, token):
            self._error(identity, "unauthorised", f"team {name!r}: wrong or missing token")
            return
        callsigns = list(msg["aircraft"])
        known = self.teams.get(name)
        if known is not None:
            if known.active and known.identity != identity:
                self._error(
                    identity,
                    "duplicate",
                    f"team {name!r} is already connected; team names are unique in a simulation",
                )
                return
            if sorted(known.callsigns) != sorted(callsigns):
                self._error(identity, "roster", f"team {name!r} rejoined with other aircraft")
                return
            known.identity, known.token = identity, token  # rejoin
            known.report, known.done, known.last_seen = None, False, time.monotonic()
        else:
            if self.config.mode == "fixed" and len(self.teams) >= self.config.teams:
                self._error(
                    identity,
                    "full",
                    f"this simulation takes {self.config.teams} "
                    "teams and has them all; try another server or wait for it to end",
                )
                return
            taken = [c for c in callsigns if c in self.owner]
            if taken:
                self._error(
                    identity,
                    "duplicate",
                    f"callsigns {taken} are taken by other "
                    "teams; callsigns are unique in a simulation",
                )
                return
            self.teams[name] = TeamRecord(name, identity, token, callsigns)
            for c in callsigns:
                self.owner[c] = name
        log.info("team %s joined (%d teams)", name, len(self.teams))
        self._send(
            identity,
            {
                "type": "welcome",
                "team": name,
                "mode": self.config.mode,
                "opponent_view": list(self.config.opponent_view),
                "simulation": self.simulation,
            },
        )

    def _report(self, identity: bytes, msg: dict[str, Any]) -> None:
        name = msg["team"]
        team = self.teams.get(name)
        if team is None or team.identity != identity:
            self._error(
                identity,
                "unknown",
                f"team {name!r} has not joined from this connection; send join first",
            )
            return
        if not hmac.compare_digest(team.token.encode(), str(msg.get("token", "")).encode()):
            self._error(identity, "unauthorised", f"team {name!r}: wrong token")
            return
        states = msg["states"]
        if states.keys() != team.members:  # (one set comparison on the common path)
            foreign = sorted(states.keys() - team.members)
            if foreign:
                self._error(
                    identity,
                    "forbidden",
                    f"team {name!r} may only report its own aircraft, not {foreign}",
                )
            else:
                missing = sorted(team.members - states.keys())
                self._error(identity, "malformed", f"team {name!r} did not report {missing}")
            return
        team.report, team.done = states, bool(msg.get("done", False))
        team.states = states
        team.last_seen = time.monotonic()
        team.active = True  # (re)joins the lockstep at this step boundary
        self._maybe_broadcast()

    def _leave(self, identity: bytes, msg: dict[str, Any]) -> None:
        team = self.teams.get(msg["team"])
        if team is not None and team.identity == identity:
            team.active, team.report, team.states = False, None, {}  # others stop seeing it
            log.info("team %s left", team.name)
            self._maybe_broadcast()

    # -- lockstep ------------------------------------------------------------------------
    def _maybe_broadcast(self) -> None:
        active = [t for t in self.teams.values() if t.active]
        if not active:
            return
        if self.config.mode == "fixed" and not self.running:
            if len(active) < self.config.teams or any(t.report is None for t in active):
                return  # waiting for all k teams
            self.running = True
        if any(t.report is None for t in active):
            return
        self._broadcast(active)

    def _broadcast(self, active: list[TeamRecord], reason: str = "") -> None:
        done_teams = [t.name for t in active if t.done]
        end = (bool(done_teams) and self.config.mode == "fixed") or bool(reason)
        if done_teams and not reason:
            reason = f"team {done_teams[0]} completed"
        view = self._view
        rows = {
            t.name: [[c, t.name, [t.states[c][i] for i in view]] for c in t.callsigns]
            for t in self.teams.values()
            if t.states
        }
        for team in active:
            opponents = [
                row for name, team_rows in rows.items() if name != team.name for row in team_rows
            ]
            self._send(
                team.identity,
                {
                    "type": "central",
                    "tick": self.tick,
                    "opponents": opponents,
                    "done": end,
                    "reason": reason,
                },
            )
            team.report = None
        self.tick += 1
        if self.config.mode == "open":
            for team in active:
                if team.done:  # finished teams leave an open simulation
                    team.active = False
                    team.states = {}
        if end:
            self._new_simulation(reason)

    def _new_simulation(self, reason: str) -> None:
        log.info("simulation %d ended at tick %d: %s", self.simulation, self.tick, reason)
        self.simulation += 1
        self.tick = 0
        self.running = False
        for team in self.teams.values():
            team.active, team.report, team.done, team.states = False, None, False, {}

    def _check_stalls(self) -> None:
        active = [t for t in self.teams.values() if t.active]
        waiting = [t for t in active if t.report is not None]
        if not waiting or (self.config.mode == "fixed" and not self.running):
            return
        now = time.monotonic()
        stalled = [
            t for t in active if t.report is None and now - t.last_seen > self.config.timeout_s
        ]
        if not stalled:
            return
        names = ", ".join(t.name for t in stalled)
        if self.config.on_stall == "drop":
            for t in stalled:
                t.active, t.states = False, {}
                log.warning("dropped team %s: silent for %.1f s", t.name, now - t.last_seen)
            self._maybe_broadcast()
        elif self.config.on_stall == "end":
            self._broadcast(waiting, reason=f"team {names} stopped reporting")
        elif now - self._paused_notice > 1.0:
            self._paused_notice = now
            for t in waiting:
                self._send(t.identity, {"type": "wait", "reason": f"paused: waiting for {names}"})

    # -- loop ----------------------------------------------------------------------------
    def handle(self, identity: bytes, data: bytes) -> None:
        try:
            msg = decode(data, "client")
        except ProtocolError as err:
            self._error(identity, err.code, str(err))
            return
        {"join": self._join, "report": self._report, "leave": self._leave}[msg["type"]](
            identity, msg
        )

    def run(self, seconds: float | None = None) -> None:
        import zmq

        end = None if seconds is None else time.monotonic() + seconds
        # a blocking receive with a timeout: one call per message, no poller in between
        self.sock.setsockopt(zmq.RCVTIMEO, max(10, int(min(self.config.timeout_s, 1.0) * 250)))
        recv, handle = self.sock.recv_multipart, self.handle
        while not self._stop and (end is None or time.monotonic() < end):
            try:
                frames = recv()
            except zmq.Again:
                self._check_stalls()
                continue
            if len(frames) == 2:
                handle(frames[0], frames[1])
            else:
                log.warning("dropped a message of %d frames", len(frames))
            now = time.monotonic()
            if now - self._last_stall_check > 0.05:  # not after every message
                self._last_stall_check = now
                self._check_stalls()

    def stop(self) -> None:
        self._stop = True

    def close(self) -> None:
        self.sock.close(0)
        if self.auth is not None:
            self.auth.stop()
        self.ctx.term()
