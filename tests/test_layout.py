"""The package's layout keeps its promises: every import runs down the layers (a package
imports only from the layers below it, and from itself), the library never imports through
an old path kept for users (``gymfg_il.moved``), and no module is over 400 lines."""

import ast
from functools import cache
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1] / "gymfg_il"

# bottom to top; a package may import from its own layer and the ones before it
LAYERS = [
    {"errors", "typecheck", "names", "units", "moved", "agent", "files"},
    {"aircraft", "workers"},
    {"sim"},
    {"flightgear"},
    {"tasks"},
    {"controllers"},
    {"viz", "display"},
    {"envs"},
    {"online"},
    {"policies", "manual"},
    {"rollout"},
    {"recording"},
    {"datasets"},
    {"collectors"},
    {"cockpit"},
    {"learning", "web"},
    {"evaluation", "export", "rl"},
    {"cli", "collect", "train", "eval", "serve", "demo", "lerobot_env"},
]
LAYER = {name: i for i, names in enumerate(LAYERS) for name in names}


def modules():
    return sorted(p for p in ROOT.rglob("*.py") if p.name != "__init__.py" or p.parent != ROOT)


def top(path: Path) -> str:
    return path.relative_to(ROOT).parts[0].removesuffix(".py")


def imported_modules(path: Path) -> set[str]:
    """Every dotted name an import of ``path`` may load: ``from a.b import c`` gives both
    ``a.b`` and ``a.b.c`` (``c`` may be a module)."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            found.add(node.module)
            found.update(f"{node.module}.{a.name}" for a in node.names)
        elif isinstance(node, ast.Import):
            found.update(a.name for a in node.names)
    return found


def imported(path: Path) -> set[str]:
    """The top-level packages and modules of gymfg_il that ``path`` imports from."""
    parts = (name.split(".") for name in imported_modules(path))
    return {p[1] for p in parts if p[0] == "gymfg_il" and len(p) > 1}


def dotted(path: Path) -> str:
    parts = path.relative_to(ROOT.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def test_every_package_has_a_layer():
    tops = {top(p) for p in modules()}
    assert tops <= set(LAYER), sorted(tops - set(LAYER))


@pytest.mark.parametrize("path", modules(), ids=lambda p: str(p.relative_to(ROOT)))
def test_imports_run_down_the_layers(path):
    own = LAYER[top(path)]
    upward = sorted(name for name in imported(path) if LAYER.get(name, -1) > own)
    assert not upward, f"{path.relative_to(ROOT)} (layer {own}) imports {upward} from above"


@cache  # every module's test asks; parsing the package once per test took 100 s
def old_paths() -> frozenset[str]:
    """The modules kept only so that imports users write keep working (tiny shims that
    forward every name; a module that lives on and forwards the few names that moved out of
    it, ``moved.forward_names``, is no old path)."""
    return frozenset(
        dotted(p)
        for p in modules()
        if "gymfg_il.moved.forward" in imported_modules(p) and p.stem != "__main__"
    )


def test_the_old_paths_are_the_ones_users_were_told_about():
    assert old_paths() == {
        "gymfg_il.collectors.manual",
        "gymfg_il.collectors.manual_keys",
        "gymfg_il.collectors.manual_view",
        "gymfg_il.collectors.screenshot",
        "gymfg_il.collectors.synthetic",
        "gymfg_il.collectors.timing",
        "gymfg_il.collectors.updater",
        "gymfg_il.controllers.agent",
        "gymfg_il.display.guidance",
        "gymfg_il.display.instruments",
        "gymfg_il.manual.cockpit",
        "gymfg_il.rl.env",
        "gymfg_il.rl.forward",
        "gymfg_il.rl.sampling",
        "gymfg_il.rl.vec",
        "gymfg_il.manual.gui",
        "gymfg_il.manual.pfd",
        "gymfg_il.viz.flightgear",
        "gymfg_il.viz.multiplayer",
        "gymfg_il.viz.netfdm",
        "gymfg_il.viz.peers",
    }


@pytest.mark.parametrize("path", modules(), ids=lambda p: str(p.relative_to(ROOT)))
def test_the_library_never_imports_through_an_old_path(path):
    through = sorted(imported_modules(path) & old_paths())
    assert not through, f"{path.relative_to(ROOT)} imports {through}: use their new home"


def test_no_module_is_over_400_lines():
    big = {
        str(p.relative_to(ROOT.parent)): n
        for p in [*ROOT.rglob("*.py"), *(ROOT.parent / "benchmarks").rglob("*.py")]
        if (n := len(p.read_text().splitlines())) > 400
    }
    assert not big, big


# import circles inside a package (lazy imports inside functions count: reading one module
# still means reading the other); no new one may appear. The one left: FlightSpec.solo() and
# FlightSpec.make_env(), the front door of the docs, build the options and the env that are
# built from a FlightSpec (the imports run only when they are called)
KNOWN_CIRCLES = {
    ("envs.flight", "envs.options", "envs.single"),
}


def import_circles() -> list[tuple[str, ...]]:
    """Groups of modules of one top-level package that import each other, each group as the
    sorted module names without ``gymfg_il.`` (any import statement, top level or not)."""
    names = {dotted(p): p for p in ROOT.rglob("*.py")}
    edges = {
        name: {m for m in imported_modules(path) if m in names and m != name}
        for name, path in names.items()
    }

    def package(name: str) -> str:
        return name.split(".")[1] if "." in name else ""

    def reach(start: str) -> set[str]:
        seen: set[str] = set()
        todo = [start]
        while todo:
            for m in edges[todo.pop()]:
                if m not in seen and package(m) == package(start):
                    seen.add(m)
                    todo.append(m)
        return seen

    reached = {name: reach(name) for name in names}
    groups = {
        tuple(sorted(m.removeprefix("gymfg_il.") for m in reached[n] if n in reached[m]))
        for n in names
        if n in reached[n]
    }
    return sorted(groups)


def test_no_import_circle_inside_a_package():
    new = [circle for circle in import_circles() if circle not in KNOWN_CIRCLES]
    assert not new, new


def test_no_function_is_over_60_lines():
    """STYLE.md: a function a reader cannot hold at once is several; #53 set the bound."""
    long = {
        f"{p.relative_to(ROOT.parent)}:{node.name}": node.end_lineno - node.lineno + 1
        for p in modules()
        for node in ast.walk(ast.parse(p.read_text()))
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef)
        and node.end_lineno - node.lineno + 1 > 60
    }
    assert not long, long
