"""Moved to ``gymfg_il.cockpit.screenshot`` (the cockpit's window pictures); this path keeps
working for now, with a DeprecationWarning, and ``python -m gymfg_il.collectors.screenshot``
runs ``python -m gymfg_il.cockpit.screenshot`` and says so."""

import importlib
import sys

from gymfg_il.moved import forward

__getattr__ = forward(__name__, "gymfg_il.cockpit.screenshot")

if __name__ == "__main__":
    print(
        "note: python -m gymfg_il.collectors.screenshot is deprecated; "
        "use python -m gymfg_il.cockpit.screenshot",
        file=sys.stderr,
    )
    raise SystemExit(importlib.import_module("gymfg_il.cockpit.screenshot").main())
