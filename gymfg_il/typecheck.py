"""Checking the values of a config dataclass against its annotations, for values that come
from files (recipes, JSON) or code rather than a typed command line: ``dynamic = "no"`` in a
recipe is an error that names the field and the type wanted, not a silently true flag."""

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
    return problems
