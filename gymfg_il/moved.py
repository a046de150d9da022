"""Old import paths that keep working for now: each is a tiny module whose names are looked
up in the module's new home (``forward``), or a name that moved out of a module that still
lives (``forward_names``), with a ``DeprecationWarning`` that names the new home.

The library itself never imports through an old path (``tests/test_layout.py`` checks it).
"""

from __future__ import annotations

import importlib
import warnings
from collections.abc import Callable, Mapping
from typing import Any


def forward(old: str, new: str, gone: Mapping[str, str] | None = None) -> Callable[[str], Any]:
    """The module ``__getattr__`` of the old module ``old``: each name comes from ``new``,
    with a DeprecationWarning pointing at the line that used the old path. ``gone``: names
    that have no new home, each with what replaced it (the AttributeError says so)."""

    def __getattr__(name: str) -> Any:
        if name.startswith("__"):  # module machinery (``__all__``, ``__wrapped__``, ...)
            raise AttributeError(f"module {old!r} has no attribute {name!r}")
        if gone and name in gone:
            raise AttributeError(f"{old}.{name} is gone: {gone[name]}")
        module = importlib.import_module(new)
        if not hasattr(module, name):
            raise AttributeError(f"module {old!r} (now {new}) has no attribute {name!r}")
        value = getattr(module, name)
        warnings.warn(
            f"{old} has moved to {new}: import {name} from {new}",
            DeprecationWarning,
            stacklevel=2,
        )
        return value

    return __getattr__


def forward_names(
    old: str, moved: Mapping[str, str], gone: Mapping[str, str] | None = None
) -> Callable[[str], Any]:
    """The module ``__getattr__`` of ``old``, a module that still lives but some of whose
    names moved: each name of ``moved`` comes from the module it maps to, with a
    DeprecationWarning pointing at the line that used the old path; ``gone``: names that
    have no new home, each with what replaced it (the AttributeError says so); any other
    name it lacks is an AttributeError, as without this. (The new home is imported when the
    name is first asked for, so a name moved below a module does not tie the two together.)"""

    def __getattr__(name: str) -> Any:
        if gone and name in gone:
            raise AttributeError(f"{old}.{name} is gone: {gone[name]}")
        if name not in moved:
            raise AttributeError(f"module {old!r} has no attribute {name!r}")
        new = moved[name]
        value = getattr(importlib.import_module(new), name)
        warnings.warn(
            f"{old}.{name} has moved to {new}: import {name} from {new}",
            DeprecationWarning,
            stacklevel=2,
        )
        return value

    return __getattr__
