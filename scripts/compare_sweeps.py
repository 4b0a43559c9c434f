#!/usr/bin/env python3
"""Compare two ``fdm-awe sweep`` output folders point by point.

    python scripts/compare_sweeps.py A B [--json FILE] [--tolerance W]

Points are matched by their physical identity (not by worker count, cold or warm start, or
the cold check); per point both cycle-average powers and their difference are printed, every
difference beyond the tolerance (default 0.5 W) is flagged and explained from the records
(:mod:`fdm_awe.sweep.compare`). Exit 0 when every point agrees or its difference is explained,
1 otherwise, 2 on bad input.
"""

from __future__ import annotations

import argparse
import sys

from fdm_awe.errors import InputError
from fdm_awe.sweep.compare import TOLERANCE_W, run_compare


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("a", help="first sweep output folder (its --out)")
    ap.add_argument("b", help="second sweep output folder")
    ap.add_argument("--json", metavar="FILE", help="also write the comparison as JSON (atomically)")
    ap.add_argument("--tolerance", type=float, default=TOLERANCE_W, metavar="W",
                    help=f"agreement tolerance [W], >= 0 (default {TOLERANCE_W:g})")
    args = ap.parse_args(argv)
    try:
        return run_compare(args.a, args.b, args.json, args.tolerance)
    except InputError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
