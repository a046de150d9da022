"""Settings of the central state server (``python -m gymfg_il.serve`` is built from them)."""

from __future__ import annotations

import ipaddress
from dataclasses import dataclass, field
from typing import Literal

from gymfg_il.errors import ConfigError
from gymfg_il.names import name_problem
from gymfg_il.online.protocol import MODES
from gymfg_il.sim.properties import DEFAULT_OPPONENT_VIEW, indices

ON_STALL = ("drop", "pause", "end")


def loopback(address: str) -> bool:
    """Whether ``address`` is this machine's loopback (reachable from here only)."""
    if address in ("localhost", "::1"):
        return True
    try:
        return ipaddress.ip_address(address).is_loopback
    except ValueError:
        return False


@dataclass
class ServerConfig:
    """Settings of the central state server.

    Attributes:
        mode: fixed: k teams, starts when all joined, ends when one completes; open: teams
            join and leave at step boundaries.
        teams: k, for the fixed mode.
        bind: address to listen on; loopback unless told otherwise.
        port: TCP port (0 picks a free one).
        secrets: team -> secret; a team not listed needs ``shared_secret``. Team names
            follow ``gymfg_il.names`` (printable, 1 to 64 characters). A listed team's
            callsigns are named after it, and no other team may take them
            (``online.roster``).
        shared_secret: one secret every team must present ("" and no per-team secrets = no
            authentication).
        timeout_s: seconds of silence after which a team is dropped (its name and callsigns
            are free again), or, where others wait for it, counts as stalled.
        on_stall: what a stalled team does to the others: drop it (it may rejoin), pause the
            others, or end the simulation.
        opponent_view: the state variables teams see of each other's aircraft (position and
            orientation by default).
        curve: encrypt with ZeroMQ CURVE; prints the public key clients need.
        max_teams: teams a server holds at once (joined or flying); more joins are refused
            as full.
        insecure: listen on an address other than loopback although no secret is set
            (anyone who can reach it may then join and read every aircraft's position).
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
    max_teams: int = 64
    insecure: bool = False

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
        if not 0 <= self.port <= 65535:
            problems.append(f"port={self.port} must lie in 0..65535 (0 picks a free one)")
        if not 1 <= self.max_teams <= 100_000:
            problems.append(f"max_teams={self.max_teams} must lie in 1..100000")
        if self.mode == "fixed" and self.teams > self.max_teams:
            problems.append(f"teams={self.teams} exceeds max_teams={self.max_teams}")
        for team, secret in self.secrets.items():
            problem = name_problem(team, "team name")
            if problem is not None:
                problems.append(problem)
            elif not (isinstance(secret, str) and secret):
                problems.append(f"team {team!r} has an empty secret: give NAME:SECRET")
        no_secret = not (self.secrets or self.shared_secret)
        if no_secret and not self.insecure and not loopback(self.bind):
            problems.append(
                f"bind={self.bind!r} with no secret would let anyone who can reach it join "
                "and read every aircraft's position: give --secret or --team NAME:SECRET, "
                "or --insecure if that is what you want"
            )
        self.opponent_view = tuple(self.opponent_view)
        indices(self.opponent_view)
        if problems:
            raise ConfigError("server: " + "; ".join(problems))
