"""Who is in an online simulation: the teams that joined, which callsigns they own, who may
join at all (secrets), and how many may be there at once.

Rules the server relies on:

- Authentication: when any secret is configured (per team or shared), every team needs one:
  a team that is not listed and has no shared secret to present is refused. Only a server
  with no secret at all lets anyone in (it says so loudly and listens on loopback only
  unless told otherwise; see ``StateServer``).
- Bounds: at most ``max_teams`` records at once. When full, records of teams that are no
  longer flying (finished) and have been silent for the stall timeout make room, oldest
  first; otherwise the join is refused as full. A join that would let some team's central
  state outgrow what a client accepts (``online.sizes``) is refused as too large.
- Callsigns of a team with its own secret (``--team NAME:SECRET``) are that team's: a
  callsign belongs to the listed team whose name it is, or begins with, followed by anything
  but a letter (team ``red``: ``red``, ``red-1``, ``red2``, ``red lead``; not ``reddish``;
  where two listed names fit, the longer: ``red-team-1`` is team ``red-team``'s). No other
  team may join with it, and such a team joins with its own callsigns only, so a team with
  its own secret can never be locked out by another holding its callsigns. A team of the
  shared secret or of a server without secrets has no name of its own (anyone with the
  secret may join under it), and its callsigns are first come, first served.
- Holding: a team holds its name and callsigns only while it is connected and reporting. A
  team is silent when it owes the server a report (it has its reply, or has just joined) or
  an answer to a ``wait`` (the server tells waiting teams why they wait, and they answer
  ``alive``) for longer than the stall timeout; the server then drops it (``StateServer``),
  and its name and callsigns are free again. The whole roster is cleared when a simulation
  ends, so a k-fixed server hosts one simulation after another for any teams.
"""

from __future__ import annotations

import hmac
import time
from dataclasses import dataclass, field

from gymfg_il.online.protocol import MAX_MESSAGE_BYTES
from gymfg_il.online.sizes import largest_central, rows_bytes


class Refused(Exception):
    """A request the server turns down; ``code`` goes back to the sender with the message."""

    def __init__(self, code: str, message: str) -> None:
        super().__init__(message)
        self.code = code


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
    # its last message, or the reply to its last report: it owes the server a message since
    last_seen: float = field(default_factory=time.monotonic)
    asked: float | None = None  # when the first wait it has not answered was sent
    states: dict[str, list[float]] = field(default_factory=dict)  # latest
    row_bytes: int = 0  # the most its rows take in the others' central states

    def __post_init__(self) -> None:
        self.members = frozenset(self.callsigns)

    def heard(self, now: float) -> None:
        """The team sent a message (a join, a report, an answer to a wait)."""
        self.last_seen, self.asked = now, None

    def silent_for(self, now: float) -> float:
        """How long the team has owed the server a message: a report, once it has its reply
        (or has just joined), or an answer to a wait, while it waits; 0 while it waits
        unasked (the server owes it the reply)."""
        if self.report is None:
            return now - self.last_seen
        return 0.0 if self.asked is None else now - self.asked


class Roster:
    """The team records of one server.

    Args:
        secrets: team -> secret.
        shared_secret: the secret of every team not in ``secrets``.
        max_teams: records at once (joined, flying, or waiting to rejoin).
        fixed_teams: k, for a k-fixed simulation (None: open).
        away_s: how long a team that is not flying keeps its record against newcomers when
            the roster is full (the stall timeout).
        view_width: the values in each opponent row (the opponent view's length).
    """

    def __init__(
        self,
        secrets: dict[str, str],
        shared_secret: str,
        max_teams: int,
        fixed_teams: int | None = None,
        away_s: float = 5.0,
        view_width: int = 6,
    ) -> None:
        self.secrets, self.shared_secret = dict(secrets), shared_secret
        self.name_lengths = sorted({len(n) for n in self.secrets}, reverse=True)
        self.max_teams, self.fixed_teams, self.away_s = max_teams, fixed_teams, away_s
        self.view_width = view_width
        self.teams: dict[str, TeamRecord] = {}
        self.owner: dict[str, str] = {}  # callsign -> team

    @property
    def open_to_all(self) -> bool:
        """No secret is configured: anyone may join as any team."""
        return not (self.secrets or self.shared_secret)

    def authorised(self, team: str, token: str) -> bool:
        if self.open_to_all:
            return True
        secret = self.secrets.get(team) or self.shared_secret
        return bool(secret) and hmac.compare_digest(secret.encode(), str(token).encode())

    def same_token(self, team: TeamRecord, token: object) -> bool:
        """Whether a message carries the token its team joined with."""
        return hmac.compare_digest(team.token.encode(), str(token).encode())

    def check_token(self, team: str, token: str) -> None:
        if self.authorised(team, token):
            return
        if not (self.secrets.get(team) or self.shared_secret):
            raise Refused(
                "unauthorised",
                f"team {team!r} is not on this server's list of teams; ask its operator for "
                "a team secret",
            )
        raise Refused("unauthorised", f"team {team!r}: wrong or missing token")

    def reserved_for(self, callsign: str) -> str | None:
        """The team with its own secret that ``callsign`` belongs to (module docstring), or
        None: no team's."""
        for end in self.name_lengths:  # longest first
            if callsign[:end] in self.secrets and not callsign[end : end + 1].isalpha():
                return callsign[:end]
        return None

    def check_callsigns(self, name: str, callsigns: list[str]) -> None:
        """Refuse (``forbidden``) a join with another team's callsigns, or, from a team with
        its own secret, with callsigns not named after it."""
        owners = {c: self.reserved_for(c) for c in callsigns}
        foreign = [f"{c!r} (of team {o!r})" for c, o in owners.items() if o not in (None, name)]
        if foreign:
            yours = f"after your own, e.g. {name + '-1'!r}" if name in self.secrets else "otherwise"
            raise Refused(
                "forbidden",
                f"team {name!r} may not fly {_some(foreign)}: a callsign named after a team "
                f"with its own secret is that team's; name your aircraft {yours}",
            )
        strays = [repr(c) for c, o in owners.items() if o is None and name in self.secrets]
        if strays:
            raise Refused(
                "forbidden",
                f"team {name!r} has its own secret, so its callsigns are named after it (its "
                f"name, or its name then anything but a letter: {name + '-1'!r}, "
                f"{name + ' lead'!r}), and no other team may take them: rename {_some(strays)}",
            )

    def join(self, identity: bytes, name: str, token: str, callsigns: list[str]) -> TeamRecord:
        """Admit (or readmit) a team; Refused says why not."""
        self.check_token(name, token)
        self.check_callsigns(name, callsigns)
        known = self.teams.get(name)
        if known is not None:
            if known.active and known.identity != identity:
                raise Refused(
                    "duplicate",
                    f"team {name!r} is already connected; team names are unique in a simulation",
                )
            if sorted(known.callsigns) != sorted(callsigns):
                raise Refused("roster", f"team {name!r} rejoined with other aircraft")
            known.identity, known.token = identity, token  # rejoin
            known.report, known.done = None, False
            known.heard(time.monotonic())
            return known
        if self.fixed_teams is not None and len(self.teams) >= self.fixed_teams:
            raise Refused(
                "full",
                f"this simulation takes {self.fixed_teams} teams and has them all; try another "
                "server or wait for it to end",
            )
        if len(self.teams) >= self.max_teams and not self._make_room():
            raise Refused(
                "full",
                f"this server holds {self.max_teams} teams at most and has them all; try again "
                "later",
            )
        taken = [repr(c) for c in callsigns if c in self.owner]
        if taken:
            raise Refused(
                "duplicate",
                f"callsigns {_some(taken)} are taken by other teams; callsigns are unique in a "
                "simulation",
            )
        record = TeamRecord(name, identity, token, callsigns)
        record.row_bytes = rows_bytes(name, callsigns, self.view_width)
        largest = largest_central([t.row_bytes for t in self.teams.values()] + [record.row_bytes])
        if largest > MAX_MESSAGE_BYTES:
            raise Refused(
                "too_large",
                f"with team {name!r}'s {len(callsigns)} aircraft a team's central state could "
                f"take {largest} bytes, and a client accepts {MAX_MESSAGE_BYTES} at most: join "
                "with fewer aircraft or shorter callsigns and team name, or use a server with "
                "fewer teams or a narrower --view",
            )
        self.teams[name] = record
        for c in callsigns:
            self.owner[c] = name
        return record

    def _make_room(self) -> bool:
        """Forget the team that has been away longest, if one has been away (not flying,
        silent) for the stall timeout."""
        now = time.monotonic()
        away = [t for t in self.teams.values() if not t.active and now - t.last_seen > self.away_s]
        if not away:
            return False
        self.remove(min(away, key=lambda t: t.last_seen).name)
        return True

    def remove(self, name: str) -> None:
        team = self.teams.pop(name, None)
        if team is not None:
            for c in team.callsigns:
                self.owner.pop(c, None)

    def clear(self) -> None:
        self.teams.clear()
        self.owner.clear()


def _some(items: list[str], shown: int = 3) -> str:
    """The first few of ``items``, and how many more (a refusal names a few of 64 callsigns
    of 64 characters, and stays within what a client accepts: ``protocol.MAX_TEXT``)."""
    more = f" (and {len(items) - shown} more)" if len(items) > shown else ""
    return ", ".join(items[:shown]) + more
