"""Every command's ``--help`` says what its options do, not how runs went: no result figure
(a percentage, or "x of y" counted in runs) and no link to a results page, in any command or
subcommand (``python -m gymfg_il.train``, ``collect``, ``eval``, ``serve``, ``demo``)."""

from __future__ import annotations

import argparse
import importlib
import re

import pytest

COMMANDS = [  # (module, the arguments before --help that choose its parser)
    ("gymfg_il.train", []),
    ("gymfg_il.collect", []),
    ("gymfg_il.collect", ["recipe.toml"]),  # a recipe's own parser
    ("gymfg_il.eval", []),
    ("gymfg_il.serve", []),
    ("gymfg_il.demo", []),
]
RESULT = re.compile(r"\d\s?%|\b\d+ of \d+\b|docs/results|results/|results page")
# percentages that are settings, not results: the phrase that holds each
SETTINGS = ("cosine-decayed to 5 %",)


class _Parsed(Exception):
    """Raised in place of parsing: the parser a command built, caught before it runs."""

    def __init__(self, parser: argparse.ArgumentParser) -> None:
        self.parser = parser


def _parser(module: str, argv: list[str], monkeypatch) -> argparse.ArgumentParser:
    def grab(self, args=None, namespace=None):
        raise _Parsed(self)

    monkeypatch.setattr(argparse.ArgumentParser, "parse_known_args", grab)
    with pytest.raises(_Parsed) as parsed:
        importlib.import_module(module).main([*argv, "--help"])
    return parsed.value.parser


def _helps(parser: argparse.ArgumentParser, name: str):
    """(the command line, its help text) of ``parser`` and of every subcommand below it."""
    yield name, parser.format_help()
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for sub, child in action.choices.items():
                yield from _helps(child, f"{name} {sub}")


@pytest.mark.parametrize(("module", "argv"), COMMANDS, ids=lambda c: str(c))
def test_no_help_text_holds_a_result_figure_or_a_results_link(module, argv, monkeypatch):
    found = {}
    for name, text in _helps(_parser(module, argv, monkeypatch), " ".join([module, *argv])):
        flat = " ".join(text.split())
        for setting in SETTINGS:
            flat = flat.replace(setting, "")
        hits = [flat[max(0, m.start() - 60) : m.end() + 20] for m in RESULT.finditer(flat)]
        if hits:
            found[name] = hits
    assert not found, found


def test_the_check_finds_a_figure_and_a_link():
    text = "success 94 % held out; 7 of 8 envs; see docs/results/rl.md"
    assert len(RESULT.findall(text)) == 3
