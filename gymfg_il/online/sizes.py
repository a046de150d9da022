"""How large a central state can grow. The server checks the bound at every join, so that
no team is ever sent more than a client accepts (``protocol.MAX_MESSAGE_BYTES``): a team's
aircraft, callsigns and name are fixed when it joins, and msgpack writes no number wider
than 9 bytes."""

from __future__ import annotations

import msgpack

from gymfg_il.online.protocol import encode

REASON_MAX_BYTES = 512  # the server's reasons name one team at most (<= 64 x 4 bytes)


def rows_bytes(team: str, callsigns: list[str], width: int) -> int:
    """The most bytes the rows of ``team`` take in the others' central states, with
    ``width`` values per row (each as a float64, msgpack's widest number)."""
    values = [0.0] * width
    return sum(len(msgpack.packb([c, team, values], use_bin_type=True)) for c in callsigns)


# an empty central state with the widest tick and reason; its row list's header grows from
# 1 byte (up to 15 rows) to at most 5
HEADER_BYTES = 4 + len(
    encode(
        {
            "type": "central",
            "tick": 2**64 - 1,
            "opponents": [],
            "done": False,
            "reason": "r" * REASON_MAX_BYTES,
        }
    )
)


def largest_central(rows: list[int]) -> int:
    """The largest central state a team receives where the teams' rows take ``rows``
    bytes each: the header and every other team's rows."""
    return HEADER_BYTES + sum(rows) - min(rows, default=0)
