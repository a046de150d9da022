"""A pilot on a bad line: a TCP proxy between page and server adds 100 ms to the round trip
and loses 5 % of what it carries (each loss held back by TCP's minimum retransmission
timeout, 200 ms, with everything behind it, as TCP delivers in order). The episodes still
record, and the card says the rate achieved and the delay the server saw."""

from __future__ import annotations

import asyncio
import random
import re
import time

import pytest

from gymfg_il.web.headless import fly

pytestmark = [pytest.mark.network, pytest.mark.slow]

ONE_WAY_S = 0.05  # each way: 100 ms added to the round trip
LOSS = 0.05
RETRANSMIT_S = 0.2  # Linux's minimum TCP retransmission timeout


async def _carry(reader, writer, rng) -> None:
    """Forward ``reader`` to ``writer`` late, in order; a lost chunk holds up the rest."""
    queue: asyncio.Queue = asyncio.Queue()
    last = 0.0

    async def deliver() -> None:
        while True:
            due, data = await queue.get()
            if data is None:
                writer.close()
                return
            await asyncio.sleep(max(0.0, due - time.monotonic()))
            writer.write(data)
            await writer.drain()

    sender = asyncio.ensure_future(deliver())
    try:
        while data := await reader.read(65536):
            due = time.monotonic() + ONE_WAY_S + (RETRANSMIT_S if rng.random() < LOSS else 0.0)
            last = max(last, due)
            queue.put_nowait((last, data))
    finally:
        queue.put_nowait((last, None))
        await sender


async def _proxy(upstream_port: int, rng) -> asyncio.Server:
    async def link(client_reader, client_writer):
        server_reader, server_writer = await asyncio.open_connection("127.0.0.1", upstream_port)
        await asyncio.gather(
            _carry(client_reader, server_writer, rng),
            _carry(server_reader, client_writer, rng),
            return_exceptions=True,
        )

    return await asyncio.start_server(link, "127.0.0.1", 0)


def test_a_slow_lossy_line_still_records_and_the_card_says_the_delay(serve):
    served = serve("--episode-time", "4", "--pilots", "1")
    port = int(re.search(r":(\d+)$", served.base).group(1))

    async def through_the_proxy():
        proxy = await _proxy(port, random.Random(5))
        near = proxy.sockets[0].getsockname()[1]
        async with proxy:
            return await fly(f"ws://127.0.0.1:{near}/ws", served.invites["pilot-1"], 2)

    flown = asyncio.run(through_the_proxy())
    assert flown.saved == 2, flown.closed
    assert served.stop() == 0
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    data = LeRobotDataset("local/web", root=served.out / "dataset")
    episodes = data.meta.episodes
    assert data.num_episodes == 2
    # the server kept its rate; the input came 100 ms and more late, some frames later
    assert all(29.0 < r < 31.0 for r in episodes["gymfg/rate_hz"])
    assert all(d >= 100.0 for d in episodes["gymfg/input_delay_ms"])
    assert all(a >= 4 for a in episodes["gymfg/input_age_frames"])
    card = (served.out / "dataset" / "README.md").read_text()
    found = re.findall(r"episode \d: ([\d.]+) Hz, jitter [\d.]+ ms, \d+ late, input delay p99 "
                       r"(\d+) ms \((\d+) frames\)", card)  # fmt: skip
    assert len(found) == 2 and all(int(ms) >= 100 for _, ms, _ in found), card
