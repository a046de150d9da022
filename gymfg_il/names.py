"""The one rule for names that reach logs, windows, files and the wire.

Callsigns, team names, pilot names, aircraft model names and dataset repo ids are printable
text of 1 to 64 characters (the online protocol's limit), with no space at either end (a lone
space would read as no name). A newline would forge a line in a
log, ESC would drive the terminal that prints it, NUL cuts C strings, and a right-to-left
override makes a name read as another; all are refused with the rule in the message.
"""

from __future__ import annotations

from gymfg_il.errors import ConfigError

NAME_MAX = 64
RULE = (
    "printable characters only (no control, format or separator codes, no space at either "
    f"end), 1 to {NAME_MAX} long"
)


class BadNameError(ConfigError):
    """A name with control characters, or empty, or over the length limit."""


def name_problem(value: object, what: str) -> str | None:
    """Why ``value`` is not an acceptable ``what`` (callsign, team, ...), or None."""
    if not isinstance(value, str):
        return f"{what} must be a string, got {type(value).__name__}"
    if not 0 < len(value) <= NAME_MAX:
        return f"{what} {value[:NAME_MAX]!r}... is {len(value)} characters; a {what} is {RULE}"
    # str.isprintable is False for Cc (controls), Cf (format: RLO, zero width), Zl/Zp and
    # every space but ' ', and for unassigned code points
    if not value.isprintable():
        bad = next(c for c in value if not c.isprintable())
        return f"{what} {value!r} holds {bad!r} (U+{ord(bad):04X}); a {what} is {RULE}"
    if value != value.strip():
        return f"{what} {value!r} starts or ends with a space; a {what} is {RULE}"
    return None


def check_name(value: object, what: str) -> str:
    """``value`` when it is an acceptable ``what``; else BadNameError naming the rule."""
    problem = name_problem(value, what)
    if problem is not None:
        raise BadNameError(problem)
    assert isinstance(value, str)
    return value
