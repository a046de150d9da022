"""Tasks named by import path, ``package.module:ClassName``: the rule a path follows, which
classes an aircraft can fly, and the trust a record (a dataset, a log, a checkpoint: a file
from outside) needs before GymFG builds the task it names.

- A path is dotted Python identifiers on both sides of one ``:``, none empty
  (``mypkg.tasks:ChaseTask``, ``gymfg_il.tasks.library:DummyTask``).
- It names a class an aircraft can fly: a subclass of ``Task``, not ``Task`` itself, not
  abstract, and, for a ``TargetTask``, one with its target ``family``.
- A record's path is built only when its module is imported already (the user's own code
  did it, or gave it as ``--task``) or listed in ``$GYMFG_TASK_MODULES`` (comma-separated):
  a file must never make GymFG import the code it names. ``__main__`` (``__mp_main__`` in a
  worker process) is never trusted from a record: it is whichever script runs now, not the
  code that wrote the record.
"""

from __future__ import annotations

import functools
import importlib
import inspect
import keyword
import os
import sys
from typing import Any

from gymfg_il.errors import ConfigError
from gymfg_il.tasks.base import Task
from gymfg_il.tasks.targets import TargetTask

TRUSTED_MODULES_ENV = "GYMFG_TASK_MODULES"
PATH_RULE = "package.module:ClassName (dotted Python identifiers on both sides of one ':')"
SCRIPT_MODULES = ("__main__", "__mp_main__")  # the script that runs now


def _dotted(text: str) -> bool:
    return all(part.isidentifier() and not keyword.iskeyword(part) for part in text.split("."))


def path_problem(path: str) -> str | None:
    """Why ``path`` is not an import path of a task, or None."""
    module, _, qualname = path.partition(":")
    if _dotted(module) and _dotted(qualname):
        return None
    return (
        f"task {path!r} is not an import path: give {PATH_RULE}, e.g. "
        "'gymfg_il.tasks.library:DummyTask', or a task family such as 'altitude'"
    )


def _abstract(cls: type[Task]) -> bool:
    return (
        cls is Task
        or inspect.isabstract(cls)
        or (issubclass(cls, TargetTask) and not hasattr(cls, "family"))
    )


def class_problem(path: str, found: object) -> str | None:
    """Why ``found``, the object ``path`` names, is not a task an aircraft can fly, or None."""
    if not (isinstance(found, type) and issubclass(found, Task)):
        # its type, not its value: a record naming sys:modules printed every module
        what = (
            f"the class {found.__name__}"
            if isinstance(found, type)
            else f"a {type(found).__name__}"
        )
        return f"{path!r} is {what}, not a Task class; name a Task subclass as {PATH_RULE}"
    if _abstract(found):
        return (
            f"{path!r} is {found.__qualname__}, a base no aircraft can fly (it lacks an "
            "observation, a reward or a target of its own): name a task built on it, a family "
            "such as 'altitude' or a class of your own"
        )
    return None


def import_task(path: str) -> type[Task]:
    """The task class ``path`` names, imported (ConfigError saying why not)."""
    problem = path_problem(path)
    if problem is not None:
        raise ConfigError(problem)
    module, _, qualname = path.partition(":")
    try:
        found: Any = importlib.import_module(module)
        for part in qualname.split("."):
            found = getattr(found, part)
    except (ImportError, AttributeError) as err:
        raise ConfigError(
            f"cannot import task {path!r} ({err}); is its package installed?"
        ) from None
    problem = class_problem(path, found)
    if problem is not None:
        raise ConfigError(problem)
    return found


def record_task_problem(name: object) -> str | None:
    """Why the task ``name`` read from a record may not be built, or None (a library family,
    checked where it is built, or a trusted path; see the module docstring). Nothing is
    imported: a path whose module is imported already is looked up in it."""
    if not isinstance(name, str) or ":" not in name:
        return None
    problem = path_problem(name)
    if problem is not None:
        return f"the record names a task that cannot be built: {problem}"
    module, _, qualname = name.partition(":")
    if module in SCRIPT_MODULES:
        return (
            f"the record names task {name!r}, a class of {module!r}: that is whichever script "
            "runs now, not the code that wrote the record. Move the task class into a module "
            f"of its own, name it as {PATH_RULE}, and record again"
        )
    trusted = {m.strip() for m in os.environ.get(TRUSTED_MODULES_ENV, "").split(",")} - {""}
    loaded = sys.modules.get(module)
    if loaded is None:
        if module in trusted:
            return None  # trusted by name: checked when it is imported (``import_task``)
        return (
            f"the record names task {name!r}, whose module {module!r} is not imported; a "
            "dataset, log or checkpoint may not make GymFG import code. If you trust that "
            f"module, import it first (give --task {name}, or import it in your script) or "
            f"set {TRUSTED_MODULES_ENV}={module}"
        )
    try:
        found = functools.reduce(getattr, qualname.split("."), loaded)
    except AttributeError:
        return (
            f"the record names task {name!r}, but module {module!r} has no {qualname!r}: "
            "was the class renamed or moved? Name it where it is now"
        )
    problem = class_problem(name, found)
    return None if problem is None else f"the record names a task that cannot fly: {problem}"
