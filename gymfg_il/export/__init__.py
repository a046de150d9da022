"""Our logs and datasets in the formats other tools open: Tacview's ACMI (``acmi``) and
Farama's Minari (``minari``). ``python -m gymfg_il.collect export --help`` lists them."""
