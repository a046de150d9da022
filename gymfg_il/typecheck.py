"""Checking the values of a config dataclass against its annotations, for values that come
from files (recipes, JSON) or code rather than a typed command line: ``dynamic = "no"`` in a
recipe is an error that names the field and the type wanted, not a silently true flag.

Every field named ``seed`` is also held to the one seed rule (``seed_problem``), so each
command's ``--seed`` and each recipe's ``seed`` are checked alike."""

from __future__ import annotations

import dataclasses
import math
import types
import typing
from pathlib import Path
from typing import Any, Literal


def _name(kind: Any) -> str:
    if typing.get_origin(kind) is Literal:
        return " or ".join(repr(c) for c in typing.get_args(kind))
    if typing.get_origin(kind) in (typing.Union, types.UnionType):  # None: an option left unset
        return " or ".join(_name(a) for a in typing.get_args(kind) if a is not type(None))
    return getattr(kind, "__name__", str(kind).replace("typing.", ""))


def _fits(value: Any, kind: Any) -> bool:
    origin, args = typing.get_origin(kind), typing.get_args(kind)
    if kind is Any:
        return True
    if origin in (typing.Union, types.UnionType):
        return any(_fits(value, a) for a in args)
    if kind is type(None):
        return value is None
    if origin is Literal:
        return value in args
    if kind is bool:
        return isinstance(value, bool)
    if kind is int:
        return isinstance(value, int) and not isinstance(value, bool)
    if kind is float:
        return (
            isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)
        )
    if kind is Path:
        return isinstance(value, (str, Path))
    if origin in (list, tuple):
        if not isinstance(value, (list, tuple)):
            return False
        if origin is tuple and args and Ellipsis not in args:
            return len(value) == len(args) and all(map(_fits, value, args))
        return not args or all(_fits(v, args[0]) for v in value)
    if origin is dict or kind is dict:
        return isinstance(value, dict)
    if isinstance(kind, type):
        return isinstance(value, kind)
    return True


SEED_LIMIT = 2**32
SEED_RULE = "0 <= seed < 2**32"


def seed_problem(seed: object, episodes: int = 1) -> str | None:
    """Why ``seed`` (the first of ``episodes`` consecutive seeds) is not a seed, or None.

    Seeds are integers 0 <= seed < 2**32, a range every seeded part takes: gymnasium's
    generators refuse negative seeds (-1 was a traceback), numpy's legacy RandomState refuses
    2**32 and above, and the log writer stops at 2**64 (a traceback). Episode i flies
    seed + i, so the last episode's seed is held to the rule too."""
    if isinstance(seed, bool) or not isinstance(seed, int):
        return f"seed={seed!r}: want an integer, {SEED_RULE}"
    if not 0 <= seed < SEED_LIMIT:
        return f"seed={seed}: a seed is an integer {SEED_RULE} ({SEED_LIMIT}); give one in range"
    last = seed + max(episodes, 1) - 1
    if last >= SEED_LIMIT:
        return (
            f"seed={seed}: episode {last - seed} has seed {last}, and a seed is an integer "
            f"{SEED_RULE}; start at {SEED_LIMIT - episodes} or below"
        )
    return None


def type_problems(obj: Any) -> list[str]:
    """``field=value: want <type>`` for every field of the dataclass ``obj`` whose value does
    not fit its annotation (a finite number for floats; ``true``/``false`` for flags)."""
    hints = typing.get_type_hints(type(obj))
    problems = []
    for f in dataclasses.fields(obj):
        value = getattr(obj, f.name)
        kind = hints[f.name]
        if not _fits(value, kind):
            problems.append(f"{f.name}={value!r}: want {_name(kind)}")
        elif f.name == "seed" and value is not None:
            problems += filter(None, [seed_problem(value)])
    return problems
