"""Command lines built from config dataclasses: one flag per field, its help taken from the
``Attributes:`` section of the class docstring (so the docs and ``--help`` cannot drift)."""

from __future__ import annotations

import argparse
import dataclasses
import re
import typing
from pathlib import Path
from typing import Any


def field_docs(cls: type) -> dict[str, str]:
    doc = cls.__doc__ or ""
    section = doc.split("Attributes:", 1)[1] if "Attributes:" in doc else ""
    docs: dict[str, str] = {}
    current = None
    for line in section.splitlines():
        m = re.match(r"\s{4,8}(\w+):\s*(.*)", line)
        if m and not line.startswith(" " * 12):
            current = m.group(1)
            docs[current] = m.group(2).strip()
        elif current and line.strip():
            docs[current] += " " + line.strip()
    return docs


def add_dataclass_args(
    parser: argparse.ArgumentParser, cls: type, skip: tuple[str, ...] = ()
) -> None:
    """One ``--field-name`` per dataclass field; lists take several values, bools are flags."""
    docs = field_docs(cls)
    hints = typing.get_type_hints(cls)
    for f in dataclasses.fields(cls):
        if f.name in skip:
            continue
        default = (
            f.default
            if f.default is not dataclasses.MISSING
            else (f.default_factory() if f.default_factory is not dataclasses.MISSING else None)
        )
        kind = hints[f.name]
        origin = typing.get_origin(kind)
        args = [a for a in typing.get_args(kind) if a is not type(None)]
        flag = "--" + f.name.replace("_", "-")
        text = f"{docs.get(f.name, '')} (default: {default})".replace("%", "%%")
        if kind is bool:
            parser.add_argument(
                flag, action=argparse.BooleanOptionalAction, default=default, help=text
            )
        elif origin is list:
            parser.add_argument(flag, nargs="+", type=args[0], default=default, help=text)
        else:
            base: Any = args[0] if args else kind
            if base not in (int, float, str, Path):
                base = str
            parser.add_argument(flag, type=base, default=default, help=text)


def dataclass_from_args(cls: type, ns: argparse.Namespace, **extra: Any) -> Any:
    names = {f.name for f in dataclasses.fields(cls)}
    values = {k: v for k, v in vars(ns).items() if k in names}
    return cls(**{**values, **extra})
