"""``python -m gymfg_il.viz.multiplayer`` is now ``python -m gymfg_il.flightgear.multiplayer``;
the old command keeps working for now and says so."""

import sys

from gymfg_il.flightgear.multiplayer.__main__ import main

if __name__ == "__main__":
    print(
        "note: python -m gymfg_il.viz.multiplayer is deprecated; "
        "use python -m gymfg_il.flightgear.multiplayer",
        file=sys.stderr,
    )
    raise SystemExit(main())
