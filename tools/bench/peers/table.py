#!/usr/bin/env python3
"""The benchmark's CSV as Markdown tables.

    python3 tools/bench/peers/table.py [docs/performance/peers.csv]          # docs/performance/peers.md, "Run of 2026-12-05"
    python3 tools/bench/peers/table.py --at-peer-error [CSV]                 # the goals' comparison

`--at-peer-error`: for every peer row of a single-yarn case (chain,
cantilever, capstan, and the nylon monofilament's `chain-nylon` and
`capstan-nylon`), the cheapest row of yarnsim's implicit integrators
(the goal is theirs: every integrator but `mpm-explicit`) of the same case
whose |error| is at or below the peer's (the capstan: the threshold
bracket's midpoint; `chain-nylon`: the grid with the axial solve and the
yarn's vertices without the grid), and the ratio of their wall times per
simulated second;
for the bundles (no oracle; `bundle`, `bundle-preset` per preset,
`bundle-converged`), every yarnsim row against every MuJoCo row over
the same simulated time.
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


def rows_of(path):
    out = []
    for r in csv.DictReader(open(path)):
        r["error"] = float(r["error"])
        r["wall_s_per_sim_s"] = float(r["wall_s_per_sim_s"])
        out.append(r)
    return out


def measured(path):
    print("| tool (integrator) | case | setting | error | wall s per simulated s | vs yarnsim | note |")
    print("|---|---|---|---|---|---|---|")
    for r in csv.DictReader(open(path)):
        print(f"| {r['tool']} ({r['integrator']}) | {r['case']} | {r['setting']} | "
              f"{fmt(r['error'], True)} | {fmt(r['wall_s_per_sim_s'])} | {fmt(r['wall_vs_yarnsim'])} | "
              f"{r['note']} |")


def name(r):
    return f"{r['tool']} {r['integrator']}, {r['setting']}"


def at_peer_error(path):
    rows = [r for r in rows_of(path) if r["ok"] == "True" and math.isfinite(r["wall_s_per_sim_s"])]
    print("| case | peer at its error (wall s per simulated s) | yarnsim cheapest at or below "
          "that error | yarnsim / peer |")
    print("|---|---|---|---|")
    for case in ("chain", "cantilever", "capstan", "chain-nylon", "capstan-nylon"):
        ours = [r for r in rows if r["tool"] == "yarnsim" and r["case"] == case
                and r["integrator"] != "mpm-explicit" and math.isfinite(r["error"])]
        for p in (r for r in rows if r["tool"] != "yarnsim" and r["case"] == case):
            # 1e-12: the capstan's brackets are the same bisection points
            fit = [r for r in ours if abs(r["error"]) <= abs(p["error"]) + 1e-12]
            if not fit:
                print(f"| {case} | {name(p)}: {fmt(p['error'], True)}, "
                      f"{fmt(p['wall_s_per_sim_s'])} | none | - |")
                continue
            best = min(fit, key=lambda r: r["wall_s_per_sim_s"])
            print(f"| {case} | {name(p)}: {fmt(p['error'], True)}, {fmt(p['wall_s_per_sim_s'])} | "
                  f"{name(best)}: {fmt(best['error'], True)}, {fmt(best['wall_s_per_sim_s'])} | "
                  f"{best['wall_s_per_sim_s'] / p['wall_s_per_sim_s']:.3g} |")
    for case in ("bundle", "bundle-preset", "bundle-converged"):
        ours = [r for r in rows if r["tool"] == "yarnsim" and r["case"] == case]
        for p in (r for r in rows if r["tool"] == "mujoco" and r["case"] == case):
            # only runs over the same simulated time (the grid implicit row
            # covers the first 0.2 s only) and, with a preset, of the same
            # preset (the setting's first word)
            for r in (r for r in ours if abs(float(r["sim_s"]) - float(p["sim_s"]))
                      <= 0.01 * float(p["sim_s"]) and (case != "bundle-preset" or
                      r["setting"].split(",")[0] == p["setting"].split(",")[0])):
                ratio = r["wall_s_per_sim_s"] / p["wall_s_per_sim_s"]
                how = f"{1 / ratio:.3g}x faster" if ratio < 1 else f"{ratio:.3g}x slower"
                print(f"| {case} | {name(p)}: {fmt(p['wall_s_per_sim_s'])} | {name(r)}: "
                      f"{fmt(r['wall_s_per_sim_s'])} | {ratio:.3g} ({how}) |")


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    path = args[0] if args else "docs/performance/peers.csv"
    if "--at-peer-error" in sys.argv:
        at_peer_error(path)
    else:
        measured(path)
