"""Who made an exported dataset and with what code: the author, author email, code permalink
and requirements a Minari dataset records. The user gives them (``--author``,
``--author-email``, ``--code-permalink``); what they leave out is taken from GymFG-IL's own
package metadata (pyproject's ``authors`` and ``urls``), and what neither says stays unset:
nothing is invented."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from email.utils import getaddresses
from importlib.metadata import PackageNotFoundError, metadata, version

PACKAGE = "gymfg-il"
# Project-URL labels that name where the code is, in the order they are preferred
CODE_URLS = ("source", "repository", "code", "homepage")


@dataclass(frozen=True)
class Credits:
    """What a Minari dataset says of its making (empty: not set)."""

    author: tuple[str, ...] = ()
    author_email: tuple[str, ...] = ()
    code_permalink: str | None = None
    requirements: tuple[str, ...] = ()

    def unset(self) -> list[str]:
        """The flags of what is not set."""
        given = {
            "--author": self.author,
            "--author-email": self.author_email,
            "--code-permalink": self.code_permalink,
        }
        return [flag for flag, value in given.items() if not value]


def package_credits() -> Credits:
    """GymFG-IL's authors, their emails and its code's address from its installed metadata,
    and the pip requirements that fly the env again (GymFG-IL and JSBSim at their versions)."""
    try:
        meta = metadata(PACKAGE)
    except PackageNotFoundError:
        return Credits()
    people = getaddresses([str(meta.get("Author-email") or "")])
    names = [n for n in (meta.get("Author") or "").split(",") if n.strip()]
    names += [name for name, _ in people if name]
    emails = [address for _, address in people if address]
    urls = {}
    for entry in meta.get_all("Project-URL") or []:
        label, _, url = str(entry).partition(",")
        urls[label.strip().lower()] = url.strip()
    code = next((urls[k] for k in CODE_URLS if urls.get(k)), None)
    return Credits(
        tuple(dict.fromkeys(n.strip() for n in names)),
        tuple(dict.fromkeys(emails)),
        code,
        (f"{PACKAGE}=={meta['Version']}", f"jsbsim=={version('jsbsim')}"),
    )


def credits(
    author: Sequence[str] = (), author_email: Sequence[str] = (), code_permalink: str | None = None
) -> Credits:
    """The user's values, each left out one taken from the package (``package_credits``)."""
    package = package_credits()
    return Credits(
        tuple(author) or package.author,
        tuple(author_email) or package.author_email,
        code_permalink or package.code_permalink,
        package.requirements,
    )
