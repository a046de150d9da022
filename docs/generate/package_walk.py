"""Walk ``gymfg_il`` for the reference pages (shared by ``api.py`` and ``cli.py``)."""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = "gymfg_il"


def new_home(tree: ast.Module) -> str | None:
    """Where a deprecation shim's names went: the module it forwards to
    (``__getattr__ = forward(__name__, "gymfg_il.new.home")``, ``gymfg_il/moved.py``), or None
    for a module that is no shim. A module that warns ``DeprecationWarning`` at import or from
    its own ``__getattr__`` is a shim too (its new home then read from its docstring)."""
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(
            isinstance(t, ast.Name) and t.id == "__getattr__" for t in node.targets
        ):
            strings = [
                c.value
                for c in ast.walk(node.value)
                if isinstance(c, ast.Constant) and isinstance(c.value, str)
            ]
            return strings[-1] if strings else ""
        if isinstance(node, ast.FunctionDef) and node.name != "__getattr__":
            continue
        if isinstance(node, ast.FunctionDef | ast.Expr | ast.If | ast.Try | ast.With):
            for call in ast.walk(node):
                if (
                    isinstance(call, ast.Call)
                    and "warn" in ast.unparse(call.func)
                    and "DeprecationWarning" in ast.unparse(call)
                ):
                    return ""
    return None


def is_shim(tree: ast.Module) -> bool:
    """Whether the module only keeps an old import path working (``new_home``)."""
    return new_home(tree) is not None


def first_line(tree: ast.Module) -> str:
    doc = ast.get_docstring(tree) or ""
    return " ".join(doc.split("\n\n", 1)[0].split())


def modules() -> list[tuple[tuple[str, ...], Path, ast.Module]]:
    found = []
    for path in sorted((ROOT / PACKAGE).rglob("*.py")):
        parts = path.relative_to(ROOT).with_suffix("").parts
        if parts[-1] == "__init__":
            parts = parts[:-1]
        if any(p.startswith("_") for p in parts):
            continue
        found.append((parts, path, ast.parse(path.read_text(), str(path))))
    return found
