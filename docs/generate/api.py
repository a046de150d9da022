"""The API reference: one page per module of ``gymfg_il``, found by walking the package.

Run by mkdocs-gen-files at build time (``mkdocs build``); nothing is written to the repository.
A module is left out when it is private (``_name``), a ``__main__`` or a deprecation shim (a
module that warns ``DeprecationWarning`` when imported: those are listed on their own page,
with the new home their warning names).
"""

from __future__ import annotations

import sys
from pathlib import Path

import mkdocs_gen_files

sys.path.insert(0, str(Path(__file__).resolve().parent))
from package_walk import ROOT, first_line, modules, new_home


def main() -> None:
    nav = mkdocs_gen_files.Nav()
    pages: dict[str, str] = {}
    shims: list[tuple[str, str | None, str]] = []
    for parts, path, tree in modules():
        name = ".".join(parts)
        home = new_home(tree)
        if home is not None:
            shims.append((name, home, first_line(tree)))
            continue
        page = Path(*parts[1:], "index.md") if path.name == "__init__.py" else Path(*parts[1:])
        page = page if page.suffix == ".md" else page.with_suffix(".md")
        pages[name] = page.as_posix()
        nav[parts] = page.as_posix()
        with mkdocs_gen_files.open(Path("reference/api", page), "w") as f:
            f.write(f"# `{name}`\n\n::: {name}\n")
        mkdocs_gen_files.set_edit_path(Path("reference/api", page), path.relative_to(ROOT))
    lines = list(nav.build_literate_nav())
    if shims:
        lines.append("* [Deprecated import paths](deprecated.md)\n")
        with mkdocs_gen_files.open("reference/api/deprecated.md", "w") as f:
            f.write(
                "# Deprecated import paths\n\nThese old import paths still work, with a "
                "`DeprecationWarning` that names the new home; new code imports from there.\n\n"
                "| old import path | new home |\n| --- | --- |\n"
            )
            for name, home, line in shims:
                target = f"[`{home}`]({pages[home]})" if home in pages else line
                f.write(f"| `{name}` | {target.replace('|', '\\|')} |\n")
    with mkdocs_gen_files.open("reference/api/SUMMARY.md", "w") as f:
        f.writelines(lines)


main()
