"""The online client env: the same API as ``OfflineEnv``, with the other teams on a central
state server. The team's aircraft are simulated here (JSBSim stays local to the team); their
states are reported every step and the server answers with what the team may see of the
others.

    env = OnlineEnv("tcp://127.0.0.1:5555", token="secret")
    team_state, opponent_states = env.reset(team, seed=0)
    ... env.step(np.hstack(actions)) ...   # exactly the paper's loop
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from gymfg_il.envs.actions import team_controls
from gymfg_il.envs.config import EnvConfig
from gymfg_il.envs.team import Team
from gymfg_il.envs.world import SimPool, World
from gymfg_il.errors import ConfigError, EnvStateError
from gymfg_il.flightgear.peers import MultiplayerConfig
from gymfg_il.online.link import ServerLink
from gymfg_il.online.protocol import ServerError, printable
from gymfg_il.sim.properties import ORIENTATION, POSITION
from gymfg_il.sim.timing import DEFAULT_AGENT_HZ, DEFAULT_SIM_HZ

_LEAVE_LINGER_MS = 250
_FORGOTTEN = ("unknown", "dropped")  # error codes of a server that no longer has the team
log = logging.getLogger(__name__)


class OnlineEnv:
    """A team's end of an online simulation.

    Args:
        address: the server (``tcp://host:port``).
        token: the team's secret (per-team or shared), if the server asks for one.
        server_key: the server's CURVE public key, when it encrypts.
        timeout_s: how long to wait for the server before giving up (after ``spin_us`` of
            polling; a ``wait`` message from a paused server restarts the clock).
        sim_hz, agent_hz: rates, as in ``OfflineEnv``.
        views, traffic: FlightGear views of the team's aircraft, as in ``OfflineEnv``; the
            opponents appear in them as multiplayer traffic (from what the server lets the
            team see of them).
        cpu: run this client and ZeroMQ's I/O thread on this one CPU (the thread's CPUs
            come back at ``close``). Where several teams share a machine, give each its own
            CPU: unpinned, the scheduler at times stacks two busy clients on one CPU. On the
            2-core benchmark VM two pinned teams ran 4-22% faster than unpinned ones in
            alternating rounds (medians 2,154 vs 2,077, 2,202 vs 2,001, 2,303 vs 1,880
            steps/s). Pinning is left to the caller: a pinned thread's child processes
            inherit its one CPU.
        spin_us: how long to poll for the server's reply, yielding the CPU between polls,
            before sleeping on it (0: sleep at once). Waking a sleeping thread is slow on a
            virtual machine, and the lockstep pays for it at every step: on the 2-core
            benchmark VM, polling made two-team lockstep clearly faster (benchmarks/run.py
            prints both). It costs at most ``spin_us`` of CPU per step, and stops while
            replies take longer than that (many teams sharing few CPUs).
        batch_io: run this client's ZeroMQ I/O thread under Linux's SCHED_BATCH policy and
            yield the CPU right after each report, so the report leaves at once while the
            thread never preempts the env elsewhere (see ``gymfg_il.online.threads``).
        multiplayer: FlightGear multiplayer (``MultiplayerConfig``): people flying FlightGear
            join as opponents of this team, as in ``OfflineEnv``. This client listens on
            ``listen_port`` itself (each client that sets it needs a port of its own) and
            sends its own aircraft to ``send_to``; the server does not relay FlightGear
            aircraft to the other teams (a team that wants them sets its own
            ``multiplayer``). The client then keeps to the wall clock (real time), and so
            holds the whole lockstep to it. The server's opponent view must be position and
            orientation variables only (all a FlightGear aircraft shows): ``reset`` raises
            ``ConfigError`` otherwise.

    ``reset`` and ``step`` return what ``OfflineEnv`` returns; ``truncated`` also becomes True
    when the server ends the simulation (in a k-fixed simulation, when any team completes),
    with ``info["server_reason"]``. A simulation that ends as it begins (a team completing at
    its first report) makes ``reset`` join the next one; a team the server dropped (silent
    for the server's timeout) joins again at its next report. Every reply is checked against
    the protocol: a malformed one is a ``ServerError`` (code ``malformed``), as are refusals
    and a silent server.

    With ``multiplayer``, the FlightGear aircraft heard follow the server's rows in
    ``opponent_states`` (sorted by callsign; ``info["opponent_callsigns"]`` names every row),
    are reward targets by callsign, and leave after ``timeout_s`` of silence. A callsign
    the server relays is shown as the server has it, not as FlightGear echoes it.
    """

    def __init__(
        self,
        address: str,
        *,
        token: str = "",
        server_key: bytes | None = None,
        timeout_s: float = 10.0,
        sim_hz: int = DEFAULT_SIM_HZ,
        agent_hz: int = DEFAULT_AGENT_HZ,
        views: Mapping[str, Sequence[int]] | None = None,
        traffic: Mapping[str, Sequence[int]] | None = None,
        cpu: int | None = None,
        spin_us: float = 1000.0,
        batch_io: bool = True,
        multiplayer: MultiplayerConfig | None = None,
    ) -> None:
        self.address, self.token, self.timeout_s = address, token, timeout_s
        self.config = EnvConfig(
            sim_hz, agent_hz, views=views, traffic=traffic, multiplayer=multiplayer
        )
        self.link = ServerLink(
            address,
            token=token,
            server_key=server_key,
            timeout_s=timeout_s,
            cpu=cpu,
            spin_us=spin_us,
            batch_io=batch_io,
        )
        self._pool = SimPool(sim_hz, agent_hz)
        self.world: World | None = None
        self.team: Team | None = None
        self.view: tuple[str, ...] = ()
        self._pose_at: list[int] | None = None
        self.joined = False
        self._rng = np.random.default_rng()
        self._done = True
        self.opponents: list[str] = []

    @property
    def dt(self) -> float:
        return self.config.dt

    # -- wire ----------------------------------------------------------------------------
    def _request(self, msg: dict[str, Any], expect: str) -> dict[str, Any]:
        assert self.team is not None
        return self.link.request(msg, self.team.name, expect)

    def _join(self) -> None:
        """Join the server (again) and take the opponent view it announces."""
        team, world = self.team, self.world
        assert team is not None and world is not None
        aircraft = {a.callsign: a.model for a in team.aircraft}
        welcome = self._request({"type": "join", "aircraft": aircraft}, "welcome")
        if welcome["team"] != team.name:
            raise ServerError(
                "malformed", f"the server welcomed team {welcome['team']!r}, not {team.name!r}"
            )
        self.view = tuple(welcome["opponent_view"])
        self.link.width = len(self.view)
        self.joined = True  # (the server has the team: leave() tells it the team leaves)
        if self.config.multiplayer is not None:
            self._show_peers()
        if self.view != tuple(self.config.opponent_view):  # the server decides
            for view in world.external.values():
                view.rename(self.view)
        pose = POSITION + ORIENTATION
        self._pose_at = [self.view.index(n) for n in pose] if set(pose) <= set(self.view) else None

    def _answer(self, done: bool) -> dict[str, Any]:
        """The server's central state for the report just sent; a team the server has
        forgotten meanwhile (dropped after a silence, or a new simulation) joins again and
        reports anew."""
        try:
            return self.link.receive("central")
        except ServerError as err:
            if err.code not in _FORGOTTEN:
                raise
            log.warning("%s; joining again", err)
        self._join()
        self._send_report(done)
        return self.link.receive("central")

    def _show_peers(self) -> None:
        """FlightGear aircraft in the server's opponent view: position and orientation only."""
        assert self.world is not None
        pose = POSITION + ORIENTATION
        extra = [n for n in self.view if n not in pose]
        if extra:
            self.leave()
            raise ConfigError(
                f"the server at {self.address} shows opponents' {extra}, which FlightGear "
                f"aircraft do not send (they show only {list(pose)}); use a server whose "
                "--view is position and orientation variables, or drop multiplayer"
            )
        self.world.show_peers_as(self.view)

    def _states(self) -> dict[str, list[float]]:
        assert self.world is not None
        return {s.callsign: s.state.tolist() for s in self.world.slots}

    def _send_report(self, done: bool) -> None:
        assert self.team is not None
        self.link.send({"type": "report", "states": self._states(), "done": done}, self.team.name)

    def _report(self, done: bool) -> dict[str, Any]:
        """Report the team's states; the server's answer (see ``_answer``)."""
        self._send_report(done)
        return self._answer(done)

    def _opponents(self, central: dict[str, Any]) -> np.ndarray:
        rows = central["opponents"]
        self.opponents = [r[0] for r in rows]
        assert self.world is not None and self.team is not None
        own = set(self.opponents).intersection(self.team.callsigns)
        if own:
            raise ServerError(
                "malformed", f"the server shows the team's own {sorted(own)} as opponents"
            )
        # FlightGear aircraft this client hears, after the server's (which win a shared name)
        relayed = set(self.opponents)
        peers = [c for c in sorted(self.world.peers) if c not in relayed]
        self.opponents += peers
        if self._pose_at is not None and self.world.traffic:  # shown in the team's views
            others = self.world.others
            others.clear()
            for callsign, _, values in rows:
                others[callsign] = np.asarray(values, dtype=np.float64)[self._pose_at]
        external = self.world.external  # opponents a reward targets
        if external:
            shown = set()
            for callsign, _, values in rows:
                view = external.get(callsign)
                if view is not None:
                    view.values = np.asarray(values, dtype=np.float64)
                    shown.add(callsign)
            for callsign, view in external.items():  # not shown: absent from ctx.targets
                if callsign in shown:
                    continue
                if callsign in self.world.peers:  # heard from FlightGear
                    view.values = self.world.peer_row(callsign)
                else:
                    view.values = np.full(len(view.values), np.nan)
        table = [np.asarray(r[2], dtype=np.float64) for r in rows]
        table += [self.world.peer_row(c) for c in peers]
        if not table:
            return np.zeros((0, len(self.view)))
        return np.stack(table)

    # -- API -----------------------------------------------------------------------------
    def reset(
        self,
        team: Team | None = None,
        *,
        seed: int | None = None,
        options: Mapping[str, Any] | None = None,
    ) -> tuple[list[np.ndarray], np.ndarray]:
        if team is not None and team is not self.team:
            if self.world is not None:
                self.world.close()
            self.team = team
            self.world = World([team], self.config, self._pool, external_targets=True)
            self.joined = False
        if self.world is None or self.team is None:
            raise EnvStateError("the first reset needs your team: env.reset(team)")
        if not self.joined:
            self._join()
        if seed is not None:
            self._rng = np.random.default_rng(seed)
        overrides = dict((options or {}).get("initial_conditions", {}))
        self.world.reset(self._rng, overrides)
        central = self._report(done=False)
        while central["done"]:  # the simulation ended as it began (a team completed at once)
            reason = printable(central["reason"])
            log.warning("%s: %s at its start; joining the next", self.address, reason)
            self._join()
            central = self._report(done=False)
        self._done = False
        opponents = self._opponents(central)
        return [self.world.observation(s) for s in self.world.slots], opponents

    def step(
        self, team_actions: object
    ) -> tuple[list[np.ndarray], np.ndarray, np.ndarray, bool, bool, dict[str, Any]]:
        world, team = self.world, self.team
        if world is None or team is None or self._done:
            raise EnvStateError("call env.reset(team) before step (and again after the end)")
        world.step_physics(team_controls(team_actions, team.callsigns))
        terminated_now = all(s.terminated for s in world.slots)
        self._send_report(world.truncated)
        self.link.yield_after_send()
        # Rewards and observations need the other teams only when a reward targets them:
        # otherwise they are computed while the server gathers the other reports.
        early = not world.external
        try:
            if early:
                observations, rewards, terminated, info = self._outcome()
        finally:  # even when scoring fails, this tick's reply must not be left unread
            central = self._answer(world.truncated)
        opponents = self._opponents(central)
        if central["done"]:  # the simulation ended: its roster is gone, join the next anew
            self.joined = False
        if not early:
            observations, rewards, terminated, info = self._outcome()
        terminated = terminated or terminated_now
        truncated = (world.truncated or bool(central["done"])) and not terminated
        self._done = terminated or truncated
        info["tick"] = central["tick"]
        info["opponent_callsigns"] = list(self.opponents)
        info["server_reason"] = printable(central["reason"])
        return observations, opponents, rewards, terminated, truncated, info

    def _outcome(self) -> tuple[list[np.ndarray], np.ndarray, bool, dict[str, Any]]:
        """What the step returns of the team's own aircraft: observations, rewards, whether
        all are terminated, and the info the server's reply does not change."""
        world = self.world
        assert world is not None
        world.score()
        slots = world.slots
        terminated = [s.terminated for s in slots]
        info = {
            "step": world.steps,
            "time_s": world.steps * world.dt,
            "terminated": terminated,
            "reasons": {s.callsign: s.reason for s in slots if s.reason},
        }
        return (
            [world.observation(s) for s in slots],
            np.array([s.reward for s in slots]),
            all(terminated),
            info,
        )

    def leave(self) -> None:
        if self.joined and self.team is not None:
            self.link.send({"type": "leave"}, self.team.name)
            self.joined = False

    def close(self) -> None:
        try:
            self.leave()
        finally:
            # a leave still queued gets a moment to go out, so the others need not time out
            self.link.close(_LEAVE_LINGER_MS)
            if self.world is not None:
                self.world.close()
                self.world = None
            self._pool.close()
