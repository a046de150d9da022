"""``python -m benchmarks.run``: every benchmark, side by side in one run, printed as rows
(name, value, unit, target) under the references measured beside them.

    python -m benchmarks.run [--quick] [--only physics,data,workers,manual,online,rl] [--json PATH]

Rows: env_step_vs_raw_jsbsim and per_aircraft_8_vs_1 (``physics``),
dataset_build_frames_per_s and train_pipeline_frames_per_s (``data``),
rollout_workers_vs_ceiling and ray_vs_pool_2_workers (``workers``),
camera_frames_per_s (``camera``),
manual_loop_p99_period_error_ms, synthetic_pilot_x_realtime and
input_to_record_p99_steps (``manual``), web_8_pilots_p99_period_error_ms and
web_input_to_record_p99_steps (``web``),
online_{2,8,16}_teams_steps_per_s and online_2_teams_pinned_steps_per_s (``online``),
rl_sampling_vs_physics_bound and rl_envs_alone_vs_physics_bound (its ceiling) with cores
and 4 x cores envs (``rl``). Ratios are medians of paired rounds (see ``benchmarks.common``).
"""

from __future__ import annotations

import argparse
import importlib
import json
from pathlib import Path

from benchmarks.common import Row, print_rows

CONCERNS = ("physics", "workers", "data", "camera", "manual", "web", "online", "rl")


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("--json", type=Path, help="write the rows to this JSON file")
    p.add_argument("--quick", action="store_true", help="fewer, shorter rounds (a smoke run)")
    p.add_argument("--only", default=",".join(CONCERNS), help="comma-separated concerns")
    args = p.parse_args(argv)
    chosen = [c.strip() for c in args.only.split(",") if c.strip()]
    unknown = sorted(set(chosen) - set(CONCERNS))
    if unknown:
        p.error(f"unknown concerns {unknown}; choose from {', '.join(CONCERNS)}")
    rows: list[Row] = []
    for concern in chosen:
        found = importlib.import_module(f"benchmarks.{concern}").rows(args.quick)
        print_rows(found)
        rows += found
    if args.json:
        args.json.write_text(json.dumps([r.json() for r in rows], indent=2))
        print(f"wrote {args.json}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
