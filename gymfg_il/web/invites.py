"""Who may fly a web session: one invite per pilot, a name and a secret token.

The tokens live in the session folder's ``invites.json`` (readable by its owner only), so a
server started again on the same folder hands out the same links. Names come from
``--invites FILE`` (one pilot's name a line; ``#`` starts a comment) or are ``pilot-1`` ..
``pilot-N``. A pilot's episodes fly seeds of their own: pilot k (0-based, in the file's
order) flies ``seed + k * SEED_BLOCK`` on, so two pilots never fly the same case and a
pilot's cases do not depend on who else is flying.
"""

from __future__ import annotations

import hmac
import json
import os
import secrets
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

from gymfg_il.collectors.session import INVITES
from gymfg_il.errors import ConfigError
from gymfg_il.names import name_problem

SEED_BLOCK = 10_000  # seeds between two pilots' first episodes


@dataclass(frozen=True)
class Invite:
    """One pilot: the name stored with their episodes, the token their link carries, the
    seed of their first episode."""

    name: str
    token: str
    seed: int

    def link(self, base: str) -> str:
        """The link to hand out (the token in the fragment: it never reaches a server log)."""
        return f"{base}/fly#invite={self.token}"


def names_from(path: Path) -> list[str]:
    """The pilots' names in ``path`` (one a line), checked."""
    try:
        text = Path(path).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as err:
        raise ConfigError(f"--invites {path}: cannot read it ({err}); give a text file") from None
    names = [line.split("#", 1)[0].strip() for line in text.splitlines()]
    names = [n for n in names if n]
    problems = [p for n in names if (p := name_problem(n, "pilot name"))]
    problems += [f"pilot name {n!r} holds '|'" for n in names if "|" in n]
    doubled = sorted(n for n, count in Counter(names).items() if count > 1)
    if doubled:
        problems.append(f"named twice: {doubled}")
    if not names:
        problems.append("no names (one pilot's name a line)")
    if problems:
        raise ConfigError(f"--invites {path}: " + "; ".join(problems[:5]))
    return names


def invites(out: Path, names: list[str], seed: int) -> list[Invite]:
    """The invites of ``names`` (tokens kept in ``out/invites.json``, made where missing)."""
    path = out / INVITES
    tokens: dict[str, str] = {}
    if path.exists():
        try:
            loaded = json.loads(path.read_text())
        except (OSError, ValueError) as err:
            raise ConfigError(
                f"{path} is damaged ({err}); delete it to issue new invites"
            ) from None
        if isinstance(loaded, dict):
            tokens = {k: v for k, v in loaded.items() if isinstance(v, str) and len(v) >= 16}
    made = {name: tokens.get(name) or secrets.token_urlsafe(24) for name in names}
    if made != tokens:
        out.mkdir(parents=True, exist_ok=True)
        fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
        with os.fdopen(fd, "w") as f:
            json.dump({**tokens, **made}, f, indent=1)
    return [Invite(name, made[name], seed + k * SEED_BLOCK) for k, name in enumerate(names)]


def find(invites: list[Invite], token: str) -> Invite | None:
    """The invite whose token is ``token`` (compared in constant time), or None."""
    found = None
    for invite in invites:
        if hmac.compare_digest(invite.token.encode(), token.encode()):
            found = invite
    return found
