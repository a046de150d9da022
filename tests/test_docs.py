"""The documentation: the site builds with ``mkdocs build --strict`` (a broken link, anchor or
API reference fails), its generated references cover the package, every Python block of the
site and the README runs as written, every command parses, and the pictures of the window
are the window the code draws."""

import ast
import importlib.util
import os
import re
import socket
import subprocess
import sys
import warnings
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
# a Python block, with the reason it is not run where the page says so
BLOCK = re.compile(r"(?:<!-- not run here:([^\n]*?)-->\n)?```python\n(.*?)```", re.S)
MKDOCS_ENV = {**os.environ, "NO_MKDOCS_2_WARNING": "1", "DISABLE_MKDOCS_2_WARNING": "true"}


def blocks(page: Path) -> list[tuple[str | None, str]]:
    """(why it is not run, or None; the code) of every Python block of ``page``, in order."""
    return [(m.group(1), m.group(2)) for m in BLOCK.finditer(page.read_text())]


def name(page: Path) -> str:
    return str(page.relative_to(ROOT))


def mkdocs_build(config: Path, site: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "-f", str(config), "-d", str(site)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        env=MKDOCS_ENV,
        timeout=600,
    )


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    site = tmp_path_factory.mktemp("site")
    run = mkdocs_build(ROOT / "mkdocs.yml", site)
    assert run.returncode == 0, run.stderr[-6000:]
    return site


@pytest.mark.slow
def test_the_site_builds_strictly_with_a_page_per_module_and_command(site):
    spec = importlib.util.spec_from_file_location("walk", ROOT / "docs/generate/package_walk.py")
    walk = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(walk)
    missing = [
        ".".join(parts)
        for parts, _, tree in walk.modules()
        if not walk.is_shim(tree) and not (site / "reference/api" / Path(*parts[1:])).is_dir()
    ]
    assert not missing, f"no API page for {missing}"
    deprecated = (site / "reference/api/deprecated/index.html").read_text()
    assert "gymfg_il.controllers.agent" in deprecated  # an old path, with its new home
    train = (site / "reference/cli/train/index.html").read_text()
    assert "--epochs" in train and "--dataset" in train  # flags from TrainConfig's fields


def test_a_broken_link_fails_the_build(tmp_path):
    docs = tmp_path / "docs"
    docs.mkdir()
    (docs / "index.md").write_text("# Home\n\nSee [the guide](guides/nowhere.md).\n")
    config = tmp_path / "mkdocs.yml"
    config.write_text(
        f"INHERIT: {ROOT / 'mkdocs.yml'}\ndocs_dir: {docs}\nplugins: [search]\nnav: [index.md]\n"
        "hooks: []\n"
    )
    run = mkdocs_build(config, tmp_path / "site")
    assert run.returncode != 0
    assert "guides/nowhere.md" in run.stderr


def test_every_block_that_is_not_run_says_why():
    marks = {name(p): len(re.findall("^<!-- not run here:", p.read_text(), re.M)) for p in PAGES}
    said = {name(p): sum(1 for why, _ in blocks(p) if why and why.strip()) for p in PAGES}
    assert said == marks  # each mark directly precedes a Python block, with a reason


@pytest.mark.parametrize(
    "page", [p for p in PAGES if any(why is None for why, _ in blocks(p))], ids=name
)
def test_the_python_blocks_of_a_page_run_in_order(page, tmp_path, monkeypatch):
    for folder in ("datasets", "collectors"):  # the checkout's data, read where pages read it
        (tmp_path / folder).symlink_to(ROOT / folder)
    monkeypatch.chdir(tmp_path)
    namespace: dict[str, object] = {"__name__": "__main__"}
    with warnings.catch_warnings():
        warnings.filterwarnings("error", ".* has moved to ", DeprecationWarning)
        for i, (why, code) in enumerate(blocks(page)):
            if why is None:
                exec(compile(code, f"{name(page)}, block {i + 1}", "exec"), namespace)


@pytest.mark.network
def test_the_online_block_flies_two_teams_against_a_real_server(tmp_path):
    (snippet,) = [c for _, c in blocks(ROOT / "docs/guides/online.md") if "threading" in c]
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    server = subprocess.Popen(
        [sys.executable, "-m", "gymfg_il.serve", "--mode", "fixed", "--teams", "2",
         "--secret", "s3cret", "--port", str(port)],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
    )  # fmt: skip
    try:
        assert b"serving" in server.stdout.readline()
        script = tmp_path / "snippet.py"
        script.write_text(snippet.replace("5555", str(port)))
        run = subprocess.run(
            [sys.executable, str(script)], capture_output=True, text=True, timeout=120
        )
        assert run.returncode == 0, run.stderr
        seen = ast.literal_eval(run.stdout.strip().splitlines()[-1])
        assert seen == {"red": 1, "blue": 1}
    finally:
        server.terminate()
        server.wait(5)


# a command of the site: `python -m gymfg_il.<command> ...` in a shell block
SHELL_BLOCK = re.compile(r"```(?:bash|sh|shell|console)\n(.*?)```", re.S)


def documented_commands() -> list[tuple[str, list[str]]]:
    """(where, argv after ``python -m``) of every gymfg_il command in a shell block of the
    site and the README (continuation lines joined, comments dropped)."""
    import shlex

    found = []
    for page in PAGES:
        for block in SHELL_BLOCK.findall(page.read_text()):
            for line in block.replace("\\\n", " ").splitlines():
                words = shlex.split(line.removeprefix("$ "), comments=True)
                while words and "=" in words[0] and not words[0].startswith("-"):
                    words = words[1:]  # VAR=value before the command
                if words[:2] == ["python", "-m"] and words[2].startswith("gymfg_il."):
                    found.append((f"{name(page)}: {' '.join(words[2:4])}", words[2:]))
    return found


class Parsed(BaseException):
    """Raised where a command would go on to run: its arguments parsed."""


@pytest.mark.parametrize("argv", [a for _, a in documented_commands()],
                         ids=[w for w, _ in documented_commands()])  # fmt: skip
def test_every_documented_command_parses(argv, monkeypatch, capsys):
    """#53: the manual guide's HG-DAgger command failed as written. Every command a page
    shows is parsed by its own parser (flags, choices, values): a flag renamed or removed
    fails here. What it needs to run (a display, a policy, minutes) is not run."""
    import argparse

    original = argparse.ArgumentParser.parse_known_args

    def parse(self, args=None, namespace=None):
        _, extras = original(self, args, namespace)
        if extras:
            self.error(f"unrecognized arguments: {' '.join(extras)}")
        raise Parsed

    monkeypatch.setattr(argparse.ArgumentParser, "parse_known_args", parse)
    module = importlib.import_module(argv[0])
    if not hasattr(module, "main"):  # a package's command: its __main__
        module = importlib.import_module(argv[0] + ".__main__")
    with pytest.raises(Parsed):
        module.main(argv[1:])
    assert "error:" not in capsys.readouterr().err


# the window's pictures, as docs/experiments/pictures.sh (make pictures) makes them: gui.png
# with no task, and window_<task>.png for each task of its loop
PICTURES_SH = (ROOT / "docs/experiments/pictures.sh").read_text()
GUI_SHOT = re.search(r'python -m gymfg_il\.cockpit\.screenshot "\$OUT/gui\.png"\n', PICTURES_SH)
TASK_SHOTS = re.search(
    r"for TASK in ([\w -]+); do\n\s+"
    r'python -m gymfg_il\.cockpit\.screenshot "\$OUT/window_\$TASK\.png" --task "\$TASK"\n',
    PICTURES_SH,
)
WINDOW_PICTURES = {
    "gui.png": [],
    **{f"window_{t}.png": ["--task", t] for t in (TASK_SHOTS[1].split() if TASK_SHOTS else [])},
}


def test_pictures_sh_makes_every_window_picture_of_the_docs():
    assert GUI_SHOT and TASK_SHOTS, "pictures.sh no longer makes the window's pictures so"
    made = {p.name for p in (ROOT / "docs/images").glob("window_*.png")} | {"gui.png"}
    assert made == set(WINDOW_PICTURES)


@pytest.mark.parametrize("picture", WINDOW_PICTURES)
def test_the_window_pictures_show_the_window_the_code_draws(picture, tmp_path):
    """#53: gui.png showed an older window than the code drew. Each window picture is drawn
    again, as pictures.sh draws it (the dummy video driver, fixed seeds: the same pixels on
    every run), and held to the committed one pixel for pixel."""
    import numpy as np
    from PIL import Image  # matplotlib's

    drawn = tmp_path / picture
    env = {**os.environ, "HF_HUB_OFFLINE": "1", "SDL_VIDEODRIVER": "dummy"}
    argv = ["-m", "gymfg_il.cockpit.screenshot", str(drawn), *WINDOW_PICTURES[picture]]
    run = subprocess.run(
        [sys.executable, *argv], cwd=ROOT, env=env, capture_output=True, text=True, timeout=600
    )
    assert run.returncode == 0, run.stderr[-3000:]
    new, old = (
        np.asarray(Image.open(p).convert("RGB")) for p in (drawn, ROOT / "docs/images" / picture)
    )
    if new.shape != old.shape:
        differ = f"it is {old.shape[1]}x{old.shape[0]}, the window {new.shape[1]}x{new.shape[0]}"
    else:
        differ = f"{int(np.any(new != old, axis=2).sum())} pixels differ"
    assert new.shape == old.shape and np.array_equal(new, old), (
        f"docs/images/{picture} is not the window the code draws ({differ}): run make pictures"
    )
