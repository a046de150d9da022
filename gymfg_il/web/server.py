"""The web cockpit's server (``python -m gymfg_il.collect web``).

Starlette on uvicorn (ASGI, with the ``websockets`` library under it; ``docs/guides/web.md``
says why): ``/fly`` serves the cockpit page from this package (``web/static``: no CDN, nothing
downloaded), ``/ws`` is each pilot's websocket (``web.protocol``).

Physics stays here: each pilot who opens their invite gets a cockpit session of their own
(``cockpit.session``, the same loop as ``collect manual``) on a thread, stepped in real time
at the flight's rate; the page draws the readings it is sent and sends back what the pilot
does (``web.link``). Every pilot's episodes go to their own MCAP log in ``OUT/logs`` as they
fly, and one dataset updater (one helper process, the only writer) keeps ``OUT/dataset`` up to
date with every saved episode of every pilot. A dropped socket discards the episode in flight
and nothing saved; the same invite resumes; ``kill -9`` of the server loses no saved episode
(``collect recover OUT`` rebuilds the dataset from the logs).

What a page may do is checked: an invite token to fly (``web.invites``), messages of bounded
size, rate and content (``web.protocol``), a bounded number of sockets; a socket that breaks
a rule is closed with the reason and the server flies on.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import sys
import threading
import time
from collections.abc import Callable
from importlib import resources
from typing import Any
from urllib.parse import urlsplit

from gymfg_il.collectors.session import check_appendable, check_out_folder
from gymfg_il.envs.options import FlightOptions
from gymfg_il.errors import ConfigError
from gymfg_il.web.config import WebConfig
from gymfg_il.web.invites import find, invites, names_from
from gymfg_il.web.link import PilotLink
from gymfg_il.web.pilots import Pilot, Pilots
from gymfg_il.web.protocol import (
    HELLO_S,
    MAX_MESSAGE_BYTES,
    ProtocolError,
    RateLimit,
    decode,
    encode,
    hello,
    inputs,
)

log = logging.getLogger(__name__)

WAITING_PER_INVITE = 2  # sockets that have not said hello yet, per invite (and 4 more)
NEEDS = "the web cockpit needs its extra: pip install -e '.[web]' (starlette, uvicorn, websockets)"


def _same_origin(headers: Any) -> bool:
    """A page from this server, or no page at all (a client that is not a browser sends no
    Origin): another site's page in a pilot's browser may not open sockets here."""
    origin = headers.get("origin")
    if origin is None:
        return True
    return urlsplit(origin).netloc == headers.get("host", "")


class WebServer:
    """Serve ``config``'s web cockpit (module docstring); ``say`` prints the server's output
    (pilots joining and leaving, episodes saved and discarded)."""

    def __init__(self, config: WebConfig, say: Callable[[str], None] | None = None) -> None:
        self.config = config
        self.say = say or (lambda text: print(text, flush=True))
        check_out_folder(config.out)
        flight = config.flight()
        env = flight.make_env()
        try:
            check_appendable(
                config.out,
                env.observation_names,
                flight.agent_hz,
                None,
                list(config.images),
                config.image_size,
            )
        finally:
            env.close()
        self.flight_options = {
            k: (str(v) if not isinstance(v, (int, float, bool, str, dict)) else v)
            for k, v in FlightOptions.given(config).items()
        }
        self.flight_options["agent_hz"] = flight.agent_hz
        names = (
            names_from(config.invites)
            if config.invites is not None
            else [f"pilot-{k + 1}" for k in range(config.pilots)]
        )
        self.invites = invites(config.out, names, config.seed)
        self.pilots = Pilots(config, self.invites, self.flight_options, self.say)
        self.waiting = 0  # sockets that have not said hello yet
        self.port = config.port
        self.serving = threading.Event()
        self._uvicorn: Any = None

    # -- the app --------------------------------------------------------------------------
    def app(self) -> Any:
        """The ASGI app: the page, its script, and the pilots' websocket."""
        try:
            from starlette.applications import Starlette
            from starlette.responses import HTMLResponse, Response
            from starlette.routing import Route, WebSocketRoute
        except ImportError as err:
            raise ConfigError(f"{NEEDS} ({err})") from None

        static = resources.files("gymfg_il.web") / "static"
        page = (static / "cockpit.html").read_text(encoding="utf-8")
        script = (static / "cockpit.js").read_text(encoding="utf-8")
        headers = {
            "Cache-Control": "no-store",
            "X-Content-Type-Options": "nosniff",
            "Content-Security-Policy": "default-src 'self'; connect-src 'self' ws: wss:; "
            "style-src 'self' 'unsafe-inline'",
            "Referrer-Policy": "no-referrer",
        }

        async def index(request: Any) -> Any:
            return HTMLResponse(
                "<!doctype html><title>GymFG-IL web cockpit</title><p>Open the invite link "
                "you were given (it looks like /fly#invite=...).</p>",
                headers=headers,
            )

        async def fly(request: Any) -> Any:
            return HTMLResponse(page, headers=headers)

        async def js(request: Any) -> Any:
            return Response(script, media_type="text/javascript", headers=headers)

        async def no_icon(request: Any) -> Any:
            return Response(status_code=204)

        return Starlette(
            routes=[
                Route("/", index),
                Route("/favicon.ico", no_icon),
                Route("/fly", fly),
                Route("/cockpit.js", js),
                WebSocketRoute("/ws", self.socket),
            ]
        )

    # -- a pilot's socket -----------------------------------------------------------------
    async def socket(self, websocket: Any) -> None:
        """One page's websocket, from hello to close (module docstring)."""
        if not _same_origin(websocket.headers) or self.waiting >= self._waiting_limit():
            await websocket.close(code=1013)  # refused before it is accepted (HTTP 403)
            return
        pilot: Pilot | None = None
        self.waiting += 1
        try:
            await websocket.accept()
            try:
                pilot = await self._join(websocket)
            finally:
                self.waiting -= 1
            if pilot is not None:
                await self._fly(websocket, pilot)
        except ProtocolError as err:
            await self._close(websocket, 1008, err.reason, pilot)
        except Exception as err:  # the server flies on
            if type(err).__name__ not in ("WebSocketDisconnect", "ConnectionClosed"):
                log.exception("a pilot's socket failed")
                await self._close(websocket, 1011, f"server error: {type(err).__name__}", pilot)
        finally:
            if pilot is not None and pilot.socket is websocket:
                pilot.socket = None
                if pilot.link is not None:
                    pilot.link.detach()
                self.say(f"pilot {pilot.invite.name} left")

    def _waiting_limit(self) -> int:
        return WAITING_PER_INVITE * len(self.invites) + 4

    async def _close(self, websocket: Any, code: int, reason: str, pilot: Pilot | None) -> None:
        who = f"pilot {pilot.invite.name}" if pilot is not None else "a page"
        self.say(f"{who}: socket closed ({reason})")
        with contextlib.suppress(Exception):
            await websocket.close(code=code, reason=reason)

    async def _receive(self, websocket: Any) -> str | bytes | None:
        """The next message's data, None once the page went."""
        message = await websocket.receive()
        if message["type"] == "websocket.disconnect":
            return None
        data = message.get("text")
        return data if data is not None else message.get("bytes", b"")

    async def _join(self, websocket: Any) -> Pilot | None:
        try:
            data = await asyncio.wait_for(self._receive(websocket), HELLO_S)
        except TimeoutError:
            raise ProtocolError(f"no hello within {HELLO_S:g} s") from None
        if data is None:
            return None
        said = hello(decode(data))
        invite = find(self.invites, said.invite)
        if invite is None:
            raise ProtocolError("no such invite")
        pilot = self.pilots.by_name[invite.name]
        pilot.joins.take(time.monotonic())  # a storm of reopenings is refused
        if self.config.episodes and pilot.saved >= self.config.episodes:
            raise ProtocolError(f"you have saved your {pilot.saved} episode(s); thank you")
        flying = sum(p.socket is not None and p is not pilot for p in self.pilots.by_name.values())
        if flying >= self.config.pilots:
            raise ProtocolError(f"the server is full ({self.config.pilots} pilots); try later")
        old, pilot.socket = pilot.socket, websocket  # the newest page flies
        if old is not None:
            if pilot.link is not None:  # the episode in flight was the other page's
                pilot.link.detach()
            await self._close(old, 1008, "this invite was opened again elsewhere", pilot)
        failed = await asyncio.to_thread(self.pilots.start, pilot, said.device)
        if pilot.socket is not websocket:  # a newer page took over meanwhile (it was told)
            return None
        if failed is not None:
            pilot.socket = None
            raise ProtocolError(f"the session could not start: {failed}")
        self.say(f"pilot {invite.name} joined ({said.device})")
        return pilot

    async def _fly(self, websocket: Any, pilot: Pilot) -> None:
        link = pilot.link
        assert link is not None and link.welcome is not None
        loop = asyncio.get_running_loop()
        newest: list[bytes] = []
        wake = asyncio.Event()

        def put(data: bytes) -> None:
            newest[:] = [data]  # only the newest frame waits
            wake.set()

        def sender(data: bytes) -> None:  # from the session's thread
            loop.call_soon_threadsafe(put, data)

        await websocket.send_text(encode(link.welcome).decode())
        if pilot.socket is not websocket or pilot.link is not link:  # taken over meanwhile
            return
        link.attach(sender)
        send = asyncio.create_task(self._send(websocket, newest, wake, link))
        try:
            rate, seq = RateLimit(), -1
            while pilot.socket is websocket:
                data = await self._receive(websocket)
                if data is None:
                    return
                rate.take(time.monotonic())
                message = inputs(decode(data), seq)
                seq = message.seq
                link.received(message)
        finally:
            send.cancel()
            with contextlib.suppress(asyncio.CancelledError, Exception):
                await send

    async def _send(
        self, websocket: Any, newest: list[bytes], wake: asyncio.Event, link: PilotLink
    ) -> None:
        while True:
            await wake.wait()
            wake.clear()
            if newest:
                data = newest.pop()
                if data:
                    await websocket.send_text(data.decode())
            if link.close_reason is not None:
                await websocket.close(code=1000, reason=link.close_reason[:120])
                return

    # -- serving --------------------------------------------------------------------------
    def run(self) -> int:
        """Serve until interrupted (Ctrl-C or SIGTERM), then finish the dataset."""
        try:
            import uvicorn
        except ImportError as err:
            raise ConfigError(f"{NEEDS} ({err})") from None
        app = self.app()
        if self.config.open_to_others:
            self.say(
                f"WARNING: serving on {self.config.host}, beyond this machine: anyone who can "
                "reach it and holds an invite flies, over plain HTTP; put it behind a TLS "
                "proxy (docs/guides/web.md)"
            )
        server = uvicorn.Server(
            uvicorn.Config(
                app,
                host=self.config.host,
                port=self.config.port,
                ws="websockets-sansio",
                ws_max_size=MAX_MESSAGE_BYTES,
                ws_ping_interval=5.0,  # a line that died unclosed is closed within 10 s
                ws_ping_timeout=5.0,
                log_level="warning",
                lifespan="off",
            )
        )
        self._uvicorn = server
        try:
            asyncio.run(self._serve(server))
        except KeyboardInterrupt:  # uvicorn hands Ctrl-C back once it has shut down
            pass
        except SystemExit as exit_:  # uvicorn's startup failure (the port is taken)
            raise ConfigError(
                f"cannot serve on {self.config.host}:{self.config.port} (see above); "
                "give another --port, or 0 for any free one"
            ) from exit_
        finally:
            self.close()
        return 0

    async def _serve(self, server: Any) -> None:
        # the dataset's helper starts now, not as the first pilot's first episode starts (a
        # fork then would hold up that pilot's frames)
        await asyncio.to_thread(self.pilots.updater.warm)
        task = asyncio.create_task(server.serve())
        while not server.started and not task.done():
            await asyncio.sleep(0.02)
        if server.started:
            self.port = server.servers[0].sockets[0].getsockname()[1]
            self._announce()
            self.serving.set()
        await task

    def _announce(self) -> None:
        base = f"http://{self.config.host}:{self.port}"
        if ":" in self.config.host:
            base = f"http://[{self.config.host}]:{self.port}"
        self.say(f"serving the web cockpit at {base}/ (Ctrl-C stops it)")
        self.say(f"data: {self.config.out}/logs (every step) and {self.config.out}/dataset")
        for invite in self.invites:
            self.say(f"invite {invite.name}: {invite.link(base)}")
        self.say(f"{len(self.invites)} invite(s); waiting for pilots")

    def stop(self) -> None:
        """Ask the server to stop (from another thread)."""
        if self._uvicorn is not None:
            self._uvicorn.should_exit = True

    def close(self) -> None:
        """End every pilot's session (an episode in flight is discarded) and finish the
        dataset."""
        saved, built = self.pilots.close()
        where = f"{self.config.out}/dataset" if built else "none built"
        self.say(f"saved {saved} episode(s) from {len(self.invites)} invite(s); dataset: {where}")
        sys.stdout.flush()
