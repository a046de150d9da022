"""The central state server: teams report their aircraft's states every step, the server
assembles the central state and sends each team what it may see of the others.

Modes: ``fixed`` (k teams: the simulation starts when all k have reported, further teams are
refused, it ends when one team completes) and ``open`` (teams join at any step boundary and
leave when they are done). The opponent restriction is applied here, so a client never
receives more than the opponent view. A team that stops reporting for ``timeout_s`` is
dropped (it may rejoin under its name and token), pauses the others, or ends the simulation,
as configured. Malformed and oversized messages are refused with an error reply; the log says
so in full a few times and then in one summary line per ten seconds, so a flood cannot flood
the log. Who may join, and how many at once, is ``online.roster``'s business.
"""

from __future__ import annotations

import collections
import logging
import time
from typing import Any

from gymfg_il.errors import ConfigError
from gymfg_il.online.config import ServerConfig
from gymfg_il.online.protocol import MAX_MESSAGE_BYTES, ProtocolError, decode, encode
from gymfg_il.online.roster import Refused, Roster, TeamRecord
from gymfg_il.online.threads import first_socket
from gymfg_il.sim.properties import indices

__all__ = ["ServerConfig", "StateServer"]
log = logging.getLogger(__name__)


class RefusalLog:
    """Refused messages in the log: the first few of every ``window_s`` in full, the rest
    counted and summarised in one line when the window closes."""

    def __init__(self, full: int = 5, window_s: float = 10.0) -> None:
        self.full, self.window_s = full, window_s
        self.start = time.monotonic()
        self.logged = 0
        self.quiet: collections.Counter[str] = collections.Counter()

    def refused(self, code: str, message: str) -> None:
        self.flush()
        if self.logged < self.full:
            self.logged += 1
            log.warning("refused a message (%s): %s", code, message)
        else:
            self.quiet[code] += 1

    def flush(self, now: float | None = None) -> None:
        now = time.monotonic() if now is None else now
        if now - self.start < self.window_s:
            return
        if self.quiet:
            counts = ", ".join(f"{code}: {n}" for code, n in sorted(self.quiet.items()))
            log.warning(
                "refused %d more messages in the last %.0f s (%s)",
                sum(self.quiet.values()),
                now - self.start,
                counts,
            )
        self.start, self.logged = now, 0
        self.quiet.clear()


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
        try:
            if config.port:
                self.sock.bind(f"tcp://{config.bind}:{config.port}")
                self.port = config.port
            else:
                self.port = self.sock.bind_to_random_port(f"tcp://{config.bind}")
        except zmq.ZMQError as err:
            self.close()
            where = f"{config.bind}:{config.port or 'any port'}"
            raise ConfigError(
                f"cannot listen on {where} ({err}); is another server using the port, or "
                "is the address not one of this machine's?"
            ) from None
        self.view_idx = indices(tuple(config.opponent_view))
        self._view = self.view_idx.tolist()
        self._last_stall_check = 0.0
        self.roster = Roster(
            config.secrets,
            config.shared_secret,
            config.max_teams,
            config.teams if config.mode == "fixed" else None,
            config.timeout_s,
        )
        self.teams = self.roster.teams  # name -> record (the roster's own dict)
        self.refusals = RefusalLog()
        if self.roster.open_to_all:
            log.warning(
                "no secrets given: any client that reaches %s may join as any team and read "
                "every aircraft's position (give --secret or --team NAME:SECRET)",
                config.bind,
            )
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
        self.refusals.refused(code, message)
        self._send(identity, {"type": "error", "code": code, "message": message})

    # -- requests ------------------------------------------------------------------------
    def _join(self, identity: bytes, msg: dict[str, Any]) -> None:
        name = msg["team"]
        try:
            self.roster.join(identity, name, msg.get("token", ""), list(msg["aircraft"]))
        except Refused as refusal:
            self._error(identity, refusal.code, str(refusal))
            return
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
        if not self.roster.same_token(team, msg.get("token", "")):
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
        team.active = team.reported = True  # (re)joins the lockstep at this step boundary
        self._maybe_broadcast()

    def _leave(self, identity: bytes, msg: dict[str, Any]) -> None:
        team = self.teams.get(msg["team"])
        if team is not None and team.identity == identity:
            team.active, team.report, team.states = False, None, {}  # others stop seeing it
            log.info("team %s left", team.name)
            if self.config.mode == "fixed" and not self.running:
                self.roster.remove(team.name)  # its slot of the coming simulation is free
            elif self.running and not any(t.active for t in self.teams.values()):
                self._new_simulation("every team left")
                return
            self._maybe_broadcast()

    # -- lockstep ------------------------------------------------------------------------
    def _maybe_broadcast(self) -> None:
        active = [t for t in self.teams.values() if t.active]
        if not active:
            return
        if self.config.mode == "fixed" and not self.running:
            if len(active) < self.config.teams or any(t.report is None for t in active):
                self._tell_waiting(active)
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

    def _tell_waiting(self, active: list[TeamRecord]) -> None:
        """Tell the teams waiting for a k-fixed start what they wait for (a client's wait
        clock restarts on it)."""
        missing = self.config.teams - len(active)
        reason = (
            f"waiting for {missing} more team{'s' if missing != 1 else ''} to join"
            if missing > 0
            else "waiting for every team's first report"
        )
        for t in active:
            if t.report is not None:
                self._send(t.identity, {"type": "wait", "reason": reason})
        self._paused_notice = time.monotonic()

    def _new_simulation(self, reason: str) -> None:
        """End the simulation; the roster is cleared, so any teams may play the next one
        (the clients of this one join again when they reset)."""
        log.info("simulation %d ended at tick %d: %s", self.simulation, self.tick, reason)
        self.simulation += 1
        self.tick = 0
        self.running = False
        self.roster.clear()

    def _check_stalls(self) -> None:
        now = time.monotonic()
        self.refusals.flush(now)
        for name in self.roster.free_unreported(now, self.config.timeout_s):
            log.warning("freed the slot of team %s: it joined but never reported", name)
        active = [t for t in self.teams.values() if t.active]
        waiting = [t for t in active if t.report is not None]
        if self.config.mode == "fixed" and not self.running:
            if waiting and now - self._paused_notice > 0.5:
                self._tell_waiting(active)
            return
        if not waiting:
            if self.running and not active:  # everyone left or was dropped: start afresh
                self._new_simulation("every team left")
            return
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
        elif now - self._paused_notice > 0.5:
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
