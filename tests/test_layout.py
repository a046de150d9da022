"""The package's layout keeps its promises: every import runs down the layers (a package
imports only from the layers below it, and from itself), and no module is over 400 lines."""

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1] / "gymfg_il"

# bottom to top; a package may import from its own layer and the ones before it
LAYERS = [
    {"errors", "typecheck", "names"},
    {"aircraft", "workers"},
    {"sim"},
    {"tasks"},
    {"controllers"},
    {"viz"},
    {"envs"},
    {"online"},
    {"policies", "manual"},
    {"rollout"},
    {"recording"},
    {"datasets"},
    {"collectors"},
    {"learning"},
    {"evaluation", "export"},
    {"cli", "collect", "train", "eval", "serve", "demo", "lerobot_env"},
]
LAYER = {name: i for i, names in enumerate(LAYERS) for name in names}


def modules():
    return sorted(p for p in ROOT.rglob("*.py") if p.name != "__init__.py" or p.parent != ROOT)


def top(path: Path) -> str:
    return path.relative_to(ROOT).parts[0].removesuffix(".py")


def imported(path: Path) -> set[str]:
    tree = ast.parse(path.read_text())
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names = [node.module]
        elif isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        else:
            continue
        for name in names:
            parts = name.split(".")
            if parts[0] == "gymfg_il" and len(parts) > 1:
                found.add(parts[1])
    return found


def test_every_package_has_a_layer():
    tops = {top(p) for p in modules()}
    assert tops <= set(LAYER), sorted(tops - set(LAYER))


@pytest.mark.parametrize("path", modules(), ids=lambda p: str(p.relative_to(ROOT)))
def test_imports_run_down_the_layers(path):
    own = LAYER[top(path)]
    upward = sorted(name for name in imported(path) if LAYER.get(name, -1) > own)
    assert not upward, f"{path.relative_to(ROOT)} (layer {own}) imports {upward} from above"


def test_no_module_is_over_400_lines():
    big = {
        str(p.relative_to(ROOT.parent)): n
        for p in [*ROOT.rglob("*.py"), *(ROOT.parent / "benchmarks").rglob("*.py")]
        if (n := len(p.read_text().splitlines())) > 400
    }
    assert not big, big
