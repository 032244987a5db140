"""Throughput of yarnsim-sweep at 1 and 2 workers, and its per-task overhead
against a bare fmpy run of the same point (the README's figures).

usage: tools/.venv/bin/python tools/sweep/bench.py [FMU_DIR] [--points N]

For the small YarnBundle FMU (0.3 s, 1500 substeps per point) and the wire
MassSpring FMU (2 s, backward Euler), in interleaved rounds (the machine
may be shared: the best of each figure over the rounds is reported):
  bare      simulate_fmu("X.fmu") in a loop in this process (extracts the
            FMU every call), and the same on a once-extracted folder with
            a fresh instance per point (what a task does);
  1 worker  the sweep on a LocalCluster with 1 worker (points/s), the
            median time inside a task and the median idle time of the
            worker between two tasks;
  2 workers the same on 2 workers; the ratio of the two throughputs.
RAYON_NUM_THREADS=1 here as in the workers.
"""
import os

os.environ["RAYON_NUM_THREADS"] = "1"
import argparse
import contextlib
import io
import pathlib
import sys
import tempfile
import time

import numpy as np
from fmpy import extract, read_model_description, simulate_fmu

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from yarnsim_sweep import Sweep, run_sweep  # noqa: E402
from yarnsim_sweep.task import simulate_point  # noqa: E402

CASES = {
    "YarnBundle-small": ("YarnBundle-small.fmu", 0.3, 0.01, '"material.friction" = {{ start = 0.0, stop = 0.5, num = {n} }}', "kinetic_energy"),
    "MassSpring-wire": ("MassSpring-wire.fmu", 2.0, 0.05, '"gravity.x" = {{ start = 0.0, stop = 8.0, num = {n} }}', "total_energy"),
}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("fmu_dir", nargs="?", default=str(pathlib.Path(__file__).resolve().parents[2] / "target" / "fmu"))
    ap.add_argument("--points", type=int, default=0, help="points per case (default 24 small, 80 wire)")
    ap.add_argument("--rounds", type=int, default=3, help="interleaved rounds; the best of each figure is reported")
    args = ap.parse_args()
    import logging

    from distributed import Client, LocalCluster

    logging.getLogger("distributed").setLevel(logging.ERROR)

    tmp = tempfile.mkdtemp(prefix="sweep-bench-")
    sweeps = {}
    for name, (fmu, stop, h, line, out) in CASES.items():
        n = args.points or (24 if "Yarn" in name else 80)
        section = "inputs" if "gravity" in line else "parameters"
        path = os.path.join(tmp, name + ".toml")
        with open(path, "w") as fh:
            fh.write(f'fmu = "{os.path.join(args.fmu_dir, fmu)}"\nstop_time = {stop}\noutput_interval = {h}\n'
                     f'[{section}]\n{line.format(n=n)}\n[outputs]\n{out} = ["final", "max"]\n')
        sweeps[name] = Sweep(path)

    clusters = {}
    for nw in (1, 2):
        t0 = time.perf_counter()
        cluster = LocalCluster(n_workers=nw, threads_per_worker=1, processes=True, dashboard_address=":0",
                               env={"RAYON_NUM_THREADS": "1"}, silence_logs=40)
        clusters[nw] = Client(cluster, set_as_default=False)
        print(f"LocalCluster with {nw} worker(s) up in {time.perf_counter() - t0:.2f} s", flush=True)
        for name, sw in sweeps.items():
            # warm-up: FMU extraction by the plugin, library load
            run_sweep(sw, os.path.join(tmp, f"warm-{name}-{nw}"), client=clusters[nw], quiet=True, plot=False)

    import pandas as pd

    best = {}
    for r in range(args.rounds):
        print(f"round {r + 1} (load average {os.getloadavg()[0]:.1f})", flush=True)
        for name, sw in sweeps.items():
            run = sw.run_config()
            pts = [v for _, v in sw.points]
            with contextlib.redirect_stdout(io.StringIO()):
                t0 = time.perf_counter()
                for v in pts[: max(4, len(pts) // 4)]:
                    simulate_fmu(sw.fmu, stop_time=sw.stop_time, output_interval=sw.output_interval, start_values=v, output=run["record"])
                t_file = (time.perf_counter() - t0) / max(4, len(pts) // 4)
                unzip = extract(sw.fmu)
                md = read_model_description(unzip)
                simulate_point(unzip, md, run, pts[0], None)
                t0 = time.perf_counter()
                for v in pts:
                    simulate_point(unzip, md, run, v, None)
                t_dir = (time.perf_counter() - t0) / len(pts)
            line = [f"bare {t_dir * 1e3:.1f} ms/point ({t_file * 1e3:.1f} with extraction)"]
            b = best.setdefault(name, {})
            b["file"] = min(b.get("file", 1e9), t_file)
            b["dir"] = min(b.get("dir", 1e9), t_dir)
            for nw, client in clusters.items():
                out = os.path.join(tmp, f"{name}-{nw}-{r}")
                s = run_sweep(sw, out, client=client, quiet=True, plot=False)
                df = pd.read_parquet(os.path.join(out, "results.parquet"))
                gaps = []
                for _, g in df.sort_values("started").groupby("worker"):
                    st = g["started"].to_numpy()
                    en = st + g["wall_s"].to_numpy()
                    gaps.extend(st[1:] - en[:-1])
                line.append(f"{nw} worker(s) {s['throughput']:.2f} points/s")
                if s["throughput"] > b.get(nw, {}).get("throughput", 0):
                    b[nw] = {"throughput": s["throughput"], "in_task": float(df["wall_s"].median()),
                             "gap": float(np.median(gaps)) if gaps else float("nan")}
            print(f"  {name}: " + ", ".join(line), flush=True)
    for c in clusters.values():
        cluster = c.cluster
        c.close()
        cluster.close()

    print(f"\nsummary (best of {args.rounds} rounds)")
    for name, b in best.items():
        one, two = b[1], b[2]
        per_point = 1.0 / one["throughput"]
        print(f"{name}: bare simulate_fmu {b['dir'] * 1e3:.1f} ms/point on an extracted folder, {b['file'] * 1e3:.1f} ms from the .fmu; "
              f"1 worker {one['throughput']:.2f} points/s = {per_point * 1e3:.1f} ms/point "
              f"(overhead {(per_point - b['dir']) * 1e3:+.1f} ms/point against bare; inside the task {one['in_task'] * 1e3:.1f} ms, "
              f"idle between tasks on the worker {one['gap'] * 1e3:.1f} ms); "
              f"2 workers {two['throughput']:.2f} points/s; ratio 2/1 = {two['throughput'] / one['throughput']:.2f}")

if __name__ == "__main__":
    main()
