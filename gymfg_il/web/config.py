"""What a web session flies and how it is served (``collect web``): ``WebConfig``."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

from gymfg_il.collectors.config import CollectConfig, ManualConfig
from gymfg_il.envs.options import FlightOptions

LOOPBACK = ("127.0.0.1", "localhost", "::1")


@dataclass
class WebConfig(CollectConfig):
    """A web cockpit: pilots fly from their browsers, each in an env of their own on this
    machine, in real time; every saved episode goes to one dataset (``web.server``).

    Attributes:
        episodes: episodes each pilot may save (0: until the server stops).
        pilots: how many pilots may fly at once (and, without --invites, how many invites
            are made: pilot-1 .. pilot-N).
        host: the address to serve on; 127.0.0.1 (this machine only) unless you mean to let
            others in (then put it behind a TLS proxy: the guide says how).
        port: the port to serve on (0: any free one; the address is printed).
        invites: a text file of the pilots' names, one a line; each gets an invite link.
            Default: pilot-1 .. pilot-N.
    """

    episodes: int = 0
    noise: float = field(default=0.0, metadata={"cli": False})  # a person is not perturbed
    out: Path = Path("datasets/web")
    pilots: int = 8
    host: str = "127.0.0.1"
    port: int = 8080
    invites: Path | None = None
    logs_gusts: ClassVar[bool] = True

    def fewest_episodes(self) -> int:
        return 0

    def problems(self) -> list[str]:
        problems = super().problems()
        if self.noise:
            problems.append("noise: a person's flight is not perturbed; fly --gusts LEVEL")
        if not 1 <= self.pilots <= 64:
            problems.append(f"pilots={self.pilots!r}: want 1..64")
        if not 0 <= self.port <= 65535:
            problems.append(f"port={self.port!r}: want 0..65535 (0: any free port)")
        if not self.host or any(c.isspace() for c in self.host):
            problems.append(f"host={self.host!r}: give an address, e.g. 127.0.0.1")
        return problems

    @property
    def open_to_others(self) -> bool:
        """Served beyond this machine (the server warns)."""
        return self.host not in LOOPBACK

    def pilot_session(self, name: str, seed: int, device: str, episodes: int) -> ManualConfig:
        """The cockpit session of one pilot (``cockpit.session``), flying from ``seed``, to
        save ``episodes`` (0: until the server stops)."""
        options: dict[str, Any] = FlightOptions.given(self)
        return ManualConfig(
            **options,
            episodes=episodes,
            seed=seed,
            out=self.out,
            images=list(self.images),
            image_size=self.image_size,
            device=device,  # type: ignore[arg-type]
            pilot="person",
            pilot_name=name,
            pilot_view="none",
        )
