"""The central state server: teams report their aircraft's states every step, the server
assembles the central state and sends each team what it may see of the others.

Modes: ``fixed`` (k teams: the simulation starts when all k have reported, further teams are
refused, it ends when one team completes) and ``open`` (teams join at any step boundary and
leave when they are done). The opponent restriction is applied here, so a client never
receives more than the opponent view.

A team that falls silent (it owes a report, or an answer to the ``wait`` messages that tell
waiting teams why they wait, for ``timeout_s``) is dropped: its name and callsigns are free
again and it may join anew, in every mode. Where other teams wait for its report, it may
instead pause them (it is kept while they wait) or end the simulation, as configured. A
team that leaves is dropped at once. Malformed and oversized messages are refused with an
error reply; the log says so in full a few times and then in one summary line per ten
seconds (``online.refusals``), so a flood cannot flood the log. Who may join, and how many
at once, is ``online.roster``'s business.
"""

from __future__ import annotations

import logging
import time
from typing import Any

from gymfg_il.errors import ConfigError
from gymfg_il.online.config import ServerConfig
from gymfg_il.online.protocol import MAX_MESSAGE_BYTES, ProtocolError, decode, encode
from gymfg_il.online.refusals import RefusalLog
from gymfg_il.online.roster import Refused, Roster, TeamRecord
from gymfg_il.online.threads import first_socket
from gymfg_il.sim.properties import indices

__all__ = ["ServerConfig", "StateServer"]
log = logging.getLogger(__name__)


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
            self._encrypt()
        self.port = self._listen()
        self.view_idx = indices(tuple(config.opponent_view))
        self._view = self.view_idx.tolist()
        self._last_stall_check = 0.0
        self.roster = Roster(
            config.secrets,
            config.shared_secret,
            config.max_teams,
            config.teams if config.mode == "fixed" else None,
            config.timeout_s,
            len(self.view_idx),
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
        # waiting teams hear why at this interval, and must answer within the timeout
        self._wait_every = min(0.5, config.timeout_s / 4)

    def _encrypt(self) -> None:
        """CurveZMQ on the socket: a new key pair (the public key in ``public_key``, for the
        clients) and an authenticator that lets any client key in."""
        import zmq
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

    def _listen(self) -> int:
        """Bind the socket to the configured address and port (any free one where none is
        given); the port. An address it cannot bind closes the server and says why."""
        import zmq

        config = self.config
        try:
            if config.port:
                self.sock.bind(f"tcp://{config.bind}:{config.port}")
                return config.port
            return self.sock.bind_to_random_port(f"tcp://{config.bind}")
        except zmq.ZMQError as err:
            self.close()
            where = f"{config.bind}:{config.port or 'any port'}"
            raise ConfigError(
                f"cannot listen on {where} ({err}); is another server using the port, or "
                "is the address not one of this machine's?"
            ) from None

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
        team.heard(time.monotonic())
        team.active = True  # (re)joins the lockstep at this step boundary
        self._maybe_broadcast()

    def _own(self, identity: bytes, msg: dict[str, Any]) -> TeamRecord | None:
        """The team that sent ``msg``, if it joined from this connection with this token."""
        team = self.teams.get(msg["team"])
        if team is None or team.identity != identity:
            return None
        return team if self.roster.same_token(team, msg.get("token", "")) else None

    def _alive(self, identity: bytes, msg: dict[str, Any]) -> None:
        team = self._own(identity, msg)  # (no answer: a stale one is harmless)
        if team is not None:
            team.heard(time.monotonic())

    def _leave(self, identity: bytes, msg: dict[str, Any]) -> None:
        team = self._own(identity, msg)
        if team is not None:
            log.info("team %s left", team.name)
            self._forget([team])

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
        view, now = self._view, time.monotonic()
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
            team.last_seen = now  # it owes the next report from now on
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
        self._tell([t for t in active if t.report is not None], reason)

    def _tell(self, waiting: list[TeamRecord], reason: str) -> None:
        """Tell waiting teams why they wait; each must answer within the timeout."""
        now = time.monotonic()
        for t in waiting:
            self._send(t.identity, {"type": "wait", "reason": reason})
            if t.asked is None:
                t.asked = now
        self._paused_notice = now

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
        timeout = self.config.timeout_s
        active = [t for t in self.teams.values() if t.active]
        starting = self.config.mode == "fixed" and not self.running
        if starting and now - self._paused_notice > self._wait_every:
            self._tell_waiting(active)
        silent = [t for t in self.teams.values() if t.silent_for(now) > timeout]
        if not silent:
            return
        waiting = [t for t in active if t.report is not None and t not in silent]
        stalled = [t for t in silent if t.active and t.report is None]
        if waiting and stalled and self.config.on_stall != "drop":  # they hold the others
            names = _names(stalled)
            if self.config.on_stall == "end":
                self._broadcast(waiting, reason=f"team {names} stopped reporting")
                return
            # pause: the others wait for the stalled teams, which are kept meanwhile
            silent = [t for t in silent if t not in stalled]
            if now - self._paused_notice > self._wait_every:
                self._tell(waiting, f"paused: waiting for {names}")
        for t in silent:
            log.warning(
                "dropped team %s: silent for %.1f s; its name and callsigns are free",
                t.name,
                t.silent_for(now),
            )
            if t.report is not None:  # it waits: tell it (it may join again)
                message = f"team {t.name!r} was dropped: it did not answer for {timeout:g} s"
                self._send(t.identity, {"type": "error", "code": "dropped", "message": message})
        self._forget(silent)

    def _forget(self, teams: list[TeamRecord]) -> None:
        """Drop ``teams`` from the roster (the others stop seeing them; their names and
        callsigns are free), and go on without them."""
        if not teams:
            return
        for t in teams:
            self.roster.remove(t.name)
        if self.running and not any(t.active for t in self.teams.values()):
            self._new_simulation("every team left")
        else:
            self._maybe_broadcast()

    # -- loop ----------------------------------------------------------------------------
    def handle(self, identity: bytes, data: bytes) -> None:
        try:
            msg = decode(data, "client")
        except ProtocolError as err:
            self._error(identity, err.code, str(err))
            return
        {"join": self._join, "report": self._report, "alive": self._alive, "leave": self._leave}[
            msg["type"]
        ](identity, msg)

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


def _names(teams: list[TeamRecord]) -> str:
    """One team's name, and how many more (a reason stays within ``sizes.REASON_MAX_BYTES``)."""
    more = f" (and {len(teams) - 1} more)" if len(teams) > 1 else ""
    return f"{teams[0].name}{more}"
