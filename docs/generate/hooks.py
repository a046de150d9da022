"""MkDocs hooks of this site (``hooks:`` in mkdocs.yml).

The generated reference sections are navigated by ``SUMMARY.md`` files (mkdocs-literate-nav);
once the navigation is built from them they are not pages of their own, so they are dropped
before the build, out of the site and its search.
"""

from __future__ import annotations

from typing import Any


def on_nav(nav: Any, config: Any, files: Any) -> Any:
    for file in [f for f in files if f.src_uri.endswith("/SUMMARY.md")]:
        files.remove(file)
    return nav
