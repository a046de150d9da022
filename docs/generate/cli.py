"""The CLI reference: one page per ``python -m gymfg_il.<command>``, from the command's own parser.

Run by mkdocs-gen-files at build time. A command is a module of ``gymfg_il`` that has a
``main(argv)`` and runs it as ``__main__`` (found by walking the package, deprecation shims
left out). Its parser is the one ``main`` builds from the config dataclasses (``gymfg_il/cli.py``):
``main`` is called with ``argparse.ArgumentParser.parse_known_args`` replaced by a catch, so it
stops where it would parse and nothing runs. A command that takes a recipe as its first
argument (``RECIPE.toml``) is asked for that parser too. A command without an argparse parser
is shown by its module docstring.
"""

from __future__ import annotations

import argparse
import ast
import html
import importlib
import sys
from collections.abc import Iterator
from pathlib import Path

import mkdocs_gen_files

sys.path.insert(0, str(Path(__file__).resolve().parent))
from package_walk import PACKAGE, first_line, is_shim, modules
from package_walk import ROOT as REPO

sys.path.insert(0, str(REPO))


class Caught(BaseException):
    """Raised in place of parsing: carries the parser ``main`` built."""

    def __init__(self, parser: argparse.ArgumentParser) -> None:
        self.parser = parser


def catch(self: argparse.ArgumentParser, *args: object, **kwargs: object) -> None:
    raise Caught(self)


def commands() -> Iterator[tuple[str, Path, ast.Module]]:
    """(module name, path, tree) of every command, ``__main__`` of a package included."""
    for parts, path, tree in modules():
        if is_shim(tree):
            continue
        if path.name == "__init__.py" and (path.parent / "__main__.py").exists():
            main_path = path.parent / "__main__.py"
            main_tree = ast.parse(main_path.read_text())
            if not is_shim(main_tree):
                yield ".".join(parts), main_path, main_tree
            continue
        runs_main = any(
            isinstance(n, ast.If) and "__main__" in ast.unparse(n.test) for n in tree.body
        )
        has_main = any(isinstance(n, ast.FunctionDef) and n.name == "main" for n in tree.body)
        if runs_main and has_main:
            yield ".".join(parts), path, tree


def parsers(module: str, path: Path) -> list[argparse.ArgumentParser]:
    """The parsers ``module``'s ``main`` builds: for no arguments and for a recipe."""
    source = path.read_text()
    if "ArgumentParser(" not in source and "cli.parser(" not in source:
        return []
    target = importlib.import_module(module if path.name != "__main__.py" else module + ".__main__")
    found: dict[str, argparse.ArgumentParser] = {}
    saved = argparse.ArgumentParser.parse_known_args
    argparse.ArgumentParser.parse_known_args = catch  # type: ignore[method-assign,assignment]
    try:
        for argv in ([], ["RECIPE.toml"]):
            try:
                target.main(argv)
            except Caught as caught:
                found.setdefault(caught.parser.prog, caught.parser)
    finally:
        argparse.ArgumentParser.parse_known_args = saved  # type: ignore[method-assign]
    return list(found.values())


def cell(text: str) -> str:
    """Text for a Markdown table cell: no HTML, no emphasis, no table breaks."""
    text = html.escape(" ".join(text.split()), quote=False)
    for ch in "\\*_[]|`":
        text = text.replace(ch, "\\" + ch)
    return text


def prose(text: str) -> str:
    """A description or epilog as Markdown paragraphs (not a code block, whose long lines
    would be cut off): its indented lines (commands, examples) stay a code block."""
    lines = text.replace("``", "`").splitlines()
    margin = min((len(x) - len(x.lstrip()) for x in lines if x.strip()), default=0)
    return "\n".join(html.escape(x[margin:], quote=False) for x in lines) + "\n\n"


def flag(action: argparse.Action) -> str:
    names = ", ".join(action.option_strings) or action.metavar or action.dest
    if action.choices and not isinstance(action, argparse._SubParsersAction):
        names += " {" + ",".join(map(str, action.choices)) + "}"
    elif action.option_strings and action.nargs != 0:
        names += " " + (action.metavar or action.dest.upper())
    return f"`{names}`"


def describe(p: argparse.ArgumentParser, level: int, about: str = "") -> Iterator[str]:
    """Markdown for one parser: its description (or ``about``, the help its parent gives it),
    usage, a table of its arguments, its epilog, then each subcommand a level below."""
    yield f"{'#' * level} `{p.prog}`\n\n"
    description = (p.description or about).strip("\n")
    if description:
        yield prose(description)
    yield "```text\n" + p.format_usage().strip() + "\n```\n\n"
    formatter = p._get_formatter()
    rows, subs = [], []
    for action in p._actions:
        if isinstance(action, argparse._HelpAction):
            continue
        if isinstance(action, argparse._SubParsersAction):
            helps = {a.dest: a.help or "" for a in action._choices_actions}
            subs = [(name, sub, helps.get(name, "")) for name, sub in action.choices.items()]
            continue
        text = formatter._expand_help(action) if action.help else ""
        rows.append(f"| {flag(action)} | {cell(text)} |\n")
    if rows:
        yield "| argument | what it does |\n| --- | --- |\n"
        yield from rows
        yield "\n"
    if p.epilog:
        yield prose(p.epilog.strip("\n"))
    if subs:
        yield "| command | what it does |\n| --- | --- |\n"
        yield from (f"| `{name}` | {cell(h)} |\n" for name, _, h in subs)
        yield "\n"
        for _, sub, h in subs:
            yield from describe(sub, level + 1, h)


def summary(tree: ast.Module) -> str:
    """The module docstring's first paragraph, less its ``python -m ...``: prefix."""
    text = first_line(tree)
    if text.startswith("``python -m") and "``: " in text:
        text = text.split("``: ", 1)[1]
    return text.replace("``", "`").replace("|", "\\|")


def main() -> None:
    index = [
        "# Command line\n\n"
        "Every command is `python -m gymfg_il.<command>`; its flags are built from the "
        "command's config dataclass (`gymfg_il/cli.py`), so this page, `--help` and the "
        "defaults cannot drift apart.\n\n| command | what it does |\n| --- | --- |\n"
    ]
    nav = ["* [Overview](index.md)\n"]
    for module, path, tree in commands():
        name = module.removeprefix(PACKAGE + ".")
        page = name.replace(".", "/") + ".md"
        found = parsers(module, path)
        with mkdocs_gen_files.open(f"reference/cli/{page}", "w") as f:
            if found:
                f.write(f"# {name}\n\n")
                for p in found:
                    f.writelines(describe(p, 2))
            else:
                f.write(f"# {name}\n\n```text\n{ast.get_docstring(tree)}\n```\n")
        mkdocs_gen_files.set_edit_path(f"reference/cli/{page}", path.relative_to(REPO))
        index.append(f"| [`python -m {module}`]({page}) | {summary(tree)} |\n")
        nav.append(f"* [{name}]({page})\n")
    with mkdocs_gen_files.open("reference/cli/index.md", "w") as f:
        f.writelines(index)
    with mkdocs_gen_files.open("reference/cli/SUMMARY.md", "w") as f:
        f.writelines(nav)


main()
