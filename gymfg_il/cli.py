"""Command lines built from config dataclasses, one way for every command: one ``--flag`` per
field, its help taken from the ``Attributes:`` section of the class docstring and its default
printed beside it (so the docs, the defaults and ``--help`` cannot drift).

Field types decide the flag: ``bool`` is ``--x/--no-x``; ``Literal[...]`` lists its choices;
``list[T]`` takes several values; ``T | None`` is optional. A field's ``metadata`` may rename
its flag (``{"flag": "--episode-time"}``) or keep it off the command line (``{"cli": False}``).
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import re
import sys
import types
import typing
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

SUPPRESS = argparse.SUPPRESS


def field_docs(cls: type) -> dict[str, str]:
    """Field name -> its line(s) in the ``Attributes:`` section of the docstring of ``cls``,
    or of the base class that declares the field (a config built on ``FlightOptions`` takes
    its flight options' docs from there)."""
    docs: dict[str, str] = {}
    for klass in reversed(cls.__mro__):
        if "__doc__" in vars(klass) and dataclasses.is_dataclass(klass):
            docs.update(_attributes(klass.__doc__ or ""))
    return {k: v.replace("``", "") for k, v in docs.items()}


def _attributes(doc: str) -> dict[str, str]:
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


def summary(cls: type) -> str:
    """The docstring of ``cls`` up to its ``Attributes:`` section, on one line."""
    text = (cls.__doc__ or "").split("Attributes:", 1)[0]
    return " ".join(text.replace("``", "`").split())


def _default(f: dataclasses.Field[Any]) -> Any:
    if f.default is not dataclasses.MISSING:
        return f.default
    if f.default_factory is not dataclasses.MISSING:
        return f.default_factory()
    return None


def parser(prog: str, doc: str | None, epilog: str | None = None) -> argparse.ArgumentParser:
    """A parser whose description is ``doc`` as written (its reStructuredText double
    backquotes as Markdown's single ones: ``x`` reads `x`)."""
    return argparse.ArgumentParser(
        prog=prog,
        description=plain(doc),
        epilog=plain(epilog),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )


def plain(text: str | None) -> str | None:
    """``text`` with reStructuredText's double backquotes as single ones."""
    return None if text is None else text.replace("``", "`")


def add_fields(
    p: argparse.ArgumentParser,
    cls: type,
    *,
    only: tuple[str, ...] | None = None,
    skip: tuple[str, ...] = (),
    defaults: Mapping[str, Any] | None = None,
    flags: Mapping[str, str] | None = None,
    shown: Mapping[str, str] | None = None,
    overrides_only: bool = False,
) -> None:
    """One flag per field of the dataclass ``cls`` (``only``/``skip`` choose the fields;
    ``only`` also takes one whose metadata keeps it off most commands, ``cli=False``;
    ``defaults`` and ``flags`` change a field's default and flag name for this command;
    ``shown`` says in words what a field left out means, e.g. "the policy's";
    ``overrides_only``: a flag left out is absent from the namespace, e.g. recipe overrides)."""
    docs = field_docs(cls)
    hints = typing.get_type_hints(cls)
    defaults, flags, shown = dict(defaults or {}), dict(flags or {}), dict(shown or {})
    for f in dataclasses.fields(cls):
        if f.name in skip or (only is not None and f.name not in only):
            continue
        if not f.metadata.get("cli", True) and (only is None or f.name not in only):
            continue  # a field kept off the command line, unless a command asks for it
        default = defaults.get(f.name, _default(f))
        flag = flags.get(f.name) or f.metadata.get("flag") or "--" + f.name.replace("_", "-")
        text = docs.get(f.name, "")
        if f.name in shown:
            text += f" (default: {shown[f.name]})"
        elif default is not None and default != [] and default != {}:
            text += f" (default: {default.__name__ if isinstance(default, type) else default})"
        options: dict[str, Any] = {
            "help": text.replace("%", "%%"),
            "default": SUPPRESS if overrides_only else default,
            "dest": f.name,
        }
        required = f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING
        if f.metadata.get("positional"):
            flag = f.name
            del options["dest"]
            if not required:
                options["nargs"] = "?"
        elif required and not overrides_only:
            options["required"] = True
        if not _add_flag(p, flag, hints[f.name], f, options) and required:
            raise TypeError(f"{cls.__name__}.{f.name}: a required field no flag can give")


def _add_flag(
    p: argparse.ArgumentParser,
    flag: str,
    hint: Any,
    f: dataclasses.Field[Any],
    options: dict[str, Any],
) -> bool:
    """Add the flag a field of type ``hint`` takes; False for a type no flag gives (dict-valued
    and other structured fields come from recipes, not flags)."""
    kind, origin = hint, typing.get_origin(hint)
    args = [a for a in typing.get_args(kind) if a is not type(None)]
    if origin in (typing.Union, types.UnionType) and args:
        kind, origin = args[0], typing.get_origin(args[0])
        args = list(typing.get_args(args[0]))
    if kind is bool:
        p.add_argument(flag, action=argparse.BooleanOptionalAction, **options)
    elif origin is typing.Literal:
        choices = list(typing.get_args(kind))
        p.add_argument(flag, choices=choices, type=type(choices[0]), **options)
    elif origin in (list, tuple):
        # a repeatable flag gathers every use (--policy A --policy B); others take one list;
        # a fixed-length tuple takes exactly its length
        fixed = origin is tuple and Ellipsis not in args
        nargs: int | str = len(args) if fixed else "+"
        action = "extend" if f.metadata.get("repeat") else "store"
        p.add_argument(flag, nargs=nargs, type=args[0] if args else str, action=action, **options)
    elif kind in (int, float, str, Path):
        p.add_argument(flag, type=kind, **options)
    else:
        return False
    return True


def build(cls: type, ns: argparse.Namespace, **extra: Any) -> Any:
    """An instance of ``cls`` from the namespace's values of its fields (and ``extra``).

    A ``--seed`` is held to the one seed rule (``typecheck.seed_problem``) here, for every
    command, before the config sees it; a config that knows its episodes checks the last
    episode's seed too."""
    from gymfg_il.errors import ConfigError
    from gymfg_il.typecheck import seed_problem

    names = {f.name for f in dataclasses.fields(cls)}
    values = {k: v for k, v in vars(ns).items() if k in names}
    if values.get("seed") is not None:
        problem = seed_problem(values["seed"])
        if problem is not None:
            raise ConfigError(f"--seed: {problem}")
    return cls(**{**values, **extra})


def run(main: Callable[[], int]) -> int:
    """Run an entry point: a project error, or a full disk, is one line on stderr and exit
    status 2."""
    from gymfg_il.errors import GymFGError, disk_full

    try:
        return main()
    except GymFGError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # the reader went away (``| head``): stop quietly, as cat does
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())  # no flush error at exit
        return 1
    except Exception as err:
        where = disk_full(err)
        if where is None:
            raise
        print(
            f"error: the disk is full ({where}): free some space and run the command again; "
            "what was saved before stays as it was (a policy is replaced only once the new one "
            "is whole; a session's completed episodes are in its logs: python -m "
            "gymfg_il.collect recover SESSION)",
            file=sys.stderr,
        )
        return 2


def progress_bar(total: int, desc: str, unit: str, enabled: bool = True) -> Any:
    """A tqdm bar on stderr (disabled: nothing is drawn). Where stderr is not a terminal (a
    log file, CI), a bar would redraw itself into the log: a line every ``LogBar.EVERY_S``
    seconds and one at the end stand in for it."""
    from tqdm import tqdm

    if enabled and not sys.stderr.isatty():
        return LogBar(total, desc, unit)
    return tqdm(total=total, desc=desc, unit=unit, disable=not enabled, file=sys.stderr)


class LogBar:
    """A progress bar for a log: plain lines, no redrawing (tqdm's methods that the entry
    points use)."""

    EVERY_S = 30.0

    def __init__(self, total: int, desc: str, unit: str) -> None:
        import time

        self.total, self.desc, self.unit, self.n = total, desc, unit, 0
        self._clock = time.monotonic
        self._started = self._said = self._clock()
        self._postfix = ""
        self._closed = False

    def update(self, n: int = 1) -> None:
        self.n += n
        if self._clock() - self._said >= self.EVERY_S:
            self._say()

    def set_postfix(self, **values: Any) -> None:
        self._postfix = ", ".join(f"{k}={v}" for k, v in values.items())

    def set_postfix_str(self, text: str, refresh: bool = True) -> None:
        self._postfix = text

    def close(self) -> None:
        if not self._closed:
            self._closed = True
            self._say()

    def _say(self) -> None:
        self._said = self._clock()
        took = self._said - self._started
        extra = f", {self._postfix}" if self._postfix else ""
        print(
            f"{self.desc}: {self.n}/{self.total} {self.unit} in {took:.0f} s{extra}",
            file=sys.stderr,
            flush=True,
        )
