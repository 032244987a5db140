#!/usr/bin/env python3
"""The benchmark's CSV as the Markdown table of README.md "Measured".

    python3 tools/peers/table.py [docs/performance/peers.csv]
"""

import csv
import math
import sys


def fmt(x, pct=False):
    try:
        v = float(x)
    except ValueError:
        return "-"
    if not math.isfinite(v):
        return "-"
    return f"{100 * v:+.3f} %" if pct else f"{v:.3g}"


def main(path):
    print("| tool (integrator) | case | setting | error | wall s per simulated s | vs yarnsim | note |")
    print("|---|---|---|---|---|---|---|")
    for r in csv.DictReader(open(path)):
        print(f"| {r['tool']} ({r['integrator']}) | {r['case']} | {r['setting']} | "
              f"{fmt(r['error'], True)} | {fmt(r['wall_s_per_sim_s'])} | {fmt(r['wall_vs_yarnsim'])} | "
              f"{r['note']} |")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "docs/performance/peers.csv")
