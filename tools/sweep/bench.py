"""Throughput of yarnsim-sweep at 1 and 2 workers, and its per-task overhead
against a bare fmpy run of the same point (the README's figures).

usage: tools/.venv/bin/python tools/sweep/bench.py [FMU_DIR] [--points N]

For the small YarnBundle FMU (0.3 s, 1500 substeps per point) and the wire
MassSpring FMU (2 s, backward Euler), in one run:
  bare      simulate_fmu("X.fmu") in a loop in this process (extracts the
            FMU every call), and the same on a once-extracted folder with
            a fresh instance per point (what a task does);
  1 worker  the sweep on a LocalCluster with 1 worker (points/s);
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
    args = ap.parse_args()
    from distributed import Client, LocalCluster

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

    bare = {}
    for name, sw in sweeps.items():
        run = sw.run_config()
        pts = [v for _, v in sw.points]
        with contextlib.redirect_stdout(io.StringIO()):
            simulate_fmu(sw.fmu, stop_time=sw.stop_time, output_interval=sw.output_interval, start_values=pts[0], output=run["record"])
            t0 = time.perf_counter()
            for v in pts:
                simulate_fmu(sw.fmu, stop_time=sw.stop_time, output_interval=sw.output_interval, start_values=v, output=run["record"])
            t_file = (time.perf_counter() - t0) / len(pts)
            unzip = extract(sw.fmu)
            md = read_model_description(unzip)
            t0 = time.perf_counter()
            for v in pts:
                simulate_point(unzip, md, run, v, None)
            t_dir = (time.perf_counter() - t0) / len(pts)
        bare[name] = (t_file, t_dir)
        print(f"{name}: bare simulate_fmu(.fmu) {t_file * 1e3:.1f} ms/point, on an extracted folder {t_dir * 1e3:.1f} ms/point ({len(pts)} points)", flush=True)

    res = {}
    for nw in (1, 2):
        t0 = time.perf_counter()
        cluster = LocalCluster(n_workers=nw, threads_per_worker=1, processes=True, dashboard_address=":0",
                               env={"RAYON_NUM_THREADS": "1"}, silence_logs=40)
        client = Client(cluster, set_as_default=False)
        t_start = time.perf_counter() - t0
        print(f"LocalCluster with {nw} worker(s) up in {t_start:.2f} s", flush=True)
        for name, sw in sweeps.items():
            # warm-up: plugin registration (FMU extraction), library load
            run_sweep(sw, os.path.join(tmp, f"warm-{name}-{nw}"), client=client, quiet=True, plot=False)
            s = run_sweep(sw, os.path.join(tmp, f"{name}-{nw}"), client=client, quiet=True, plot=False)
            res[name, nw] = s
            print(f"{name}: {nw} worker(s): {s['ran']} points in {s['wall_s']:.2f} s = {s['throughput']:.2f} points/s", flush=True)
        client.close()
        cluster.close()

    print("\nsummary")
    for name in sweeps:
        t_file, t_dir = bare[name]
        r1, r2 = res[name, 1], res[name, 2]
        per_task_1w = r1["wall_s"] / r1["ran"]
        import pandas as pd

        in_task = pd.read_parquet(os.path.join(tmp, f"{name}-1", "results.parquet"))["wall_s"].median()
        print(f"{name}: bare {t_dir * 1e3:.1f} ms/point ({t_file * 1e3:.1f} ms with extraction); "
              f"sweep 1 worker {r1['throughput']:.2f} points/s ({per_task_1w * 1e3:.1f} ms/point, overhead {(per_task_1w - t_dir) * 1e3:+.1f} ms/point against bare; "
              f"median time inside the task {in_task * 1e3:.1f} ms, so {(per_task_1w - in_task) * 1e3:.1f} ms/point outside it); "
              f"2 workers {r2['throughput']:.2f} points/s; ratio 2/1 = {r2['throughput'] / r1['throughput']:.2f}")


if __name__ == "__main__":
    main()
