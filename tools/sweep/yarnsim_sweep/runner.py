"""Runs a checked Sweep on Dask and writes the results.

Files in the output folder:
  results.parquet, results.csv  one row per point (parameters, reductions,
                                status, messages, wall time, worker)
  series.parquet                the kept time series, long format
                                (point, time, one column per output)
  plot.png / plot.svg           the [plot] of the sweep file, if any
They are rewritten (atomically) every few seconds while the sweep runs and
at the end, also after Ctrl-C, so `--resume` finds what was done.
"""
import hashlib
import os
import sys
import time

import numpy as np
import pandas as pd

from . import task
from .spec import SweepError

FLUSH_S = 2.0


_WORKER_TASK = None


def worker_task_module():
    """task.py loaded once more as a module that is not in sys.modules and
    cannot be imported by name: pickle then fails on its functions and
    distributed falls back to cloudpickle, which sends them by value (Dask
    pickles the task spec with plain pickle first, so
    cloudpickle.register_pickle_by_value alone does not do it)."""
    global _WORKER_TASK
    if _WORKER_TASK is None:
        import importlib.util

        spec = importlib.util.spec_from_file_location("yarnsim_sweep_worker_task", task.__file__)
        mod = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(mod)
        _WORKER_TASK = mod
    return _WORKER_TASK


def connect(scheduler=None, workers=None, timeout=10.0, quiet=False):
    """A distributed Client: an embedded LocalCluster (one single-threaded
    worker process per core, RAYON_NUM_THREADS=1) or an existing scheduler."""
    from distributed import Client, LocalCluster

    if scheduler:
        try:
            return Client(scheduler, timeout=timeout, set_as_default=False)
        except (OSError, TimeoutError) as exc:
            raise SweepError(f"--scheduler: cannot reach the Dask scheduler at {scheduler} within {timeout:g} s ({type(exc).__name__}: {exc})") from None
        except Exception as exc:  # something answered, but not a Dask scheduler
            raise SweepError(f"--scheduler: no Dask scheduler answered at {scheduler} within {timeout:g} s "
                             f"(is the address right? {type(exc).__name__}: {str(exc)[:200]})") from None
    n = workers or os.cpu_count() or 1
    cluster = LocalCluster(
        n_workers=n,
        threads_per_worker=1,
        processes=True,
        dashboard_address=":0",
        env={"RAYON_NUM_THREADS": "1"},
        silence_logs=50 if quiet else 30,
    )
    return Client(cluster, set_as_default=False)


def load_previous(out):
    """Rows and series of an earlier (possibly interrupted) run."""
    rp = os.path.join(out, "results.parquet")
    sp = os.path.join(out, "series.parquet")
    rows = pd.read_parquet(rp) if os.path.exists(rp) else None
    series = pd.read_parquet(sp) if os.path.exists(sp) else None
    return rows, series


class Progress:
    """A one-line progress bar on stderr (the dashboard link is printed too)."""

    def __init__(self, total, quiet):
        self.total, self.done, self.failed = total, 0, 0
        self.quiet = quiet or total == 0
        self.t0 = time.perf_counter()
        self.tty = sys.stderr.isatty()

    def update(self, ok):
        self.done += 1
        self.failed += 0 if ok else 1
        if self.quiet:
            return
        el = time.perf_counter() - self.t0
        rate = self.done / el if el > 0 else 0.0
        eta = (self.total - self.done) / rate if rate > 0 else float("inf")
        n = 30 * self.done // self.total
        line = f"[{'#' * n}{'.' * (30 - n)}] {self.done}/{self.total} points, {self.failed} failed, {rate:.2f} points/s, ETA {eta:.0f} s"
        if self.tty:
            sys.stderr.write("\r" + line + ("\n" if self.done == self.total else ""))
        elif self.done == self.total or self.done % max(1, self.total // 10) == 0:
            sys.stderr.write(line + "\n")
        sys.stderr.flush()


def run_sweep(sweep, out, client=None, scheduler=None, workers=None, resume=False, connect_timeout=10.0,
              quiet=False, plot=True, on_result=None):
    """Runs the sweep's points that are not done yet; returns a summary dict
    (ran, skipped, rows, wall_s, failed, workers)."""
    os.makedirs(out, exist_ok=True)
    keys = [k for k, _ in sweep.points]
    values_of = dict(sweep.points)
    index_of = {k: i for i, k in enumerate(keys)}
    prev_rows, prev_series = (None, None)
    done_rows, done_series = [], []
    if resume:
        prev_rows, prev_series = load_previous(out)
        if prev_rows is not None:
            keep = prev_rows["point"].isin(keys)
            dropped = int((~keep).sum())
            if dropped and not quiet:
                print(f"resume: {dropped} rows of {out} belong to another sweep (other settings) and are dropped", file=sys.stderr)
            prev_rows = prev_rows[keep]
            done_rows = prev_rows.to_dict("records")
            if prev_series is not None:
                done_series = [prev_series[prev_series["point"].isin(set(prev_rows["point"]))]]
    # without --resume the files of an earlier run are replaced at the first
    # flush (after the cluster answered), not removed up front
    done = {r["point"] for r in done_rows}
    todo = [(k, v) for k, v in sweep.points if k not in done]
    own_client = client is None
    summary = {"ran": 0, "skipped": len(sweep.points) - len(todo), "rows": 0, "wall_s": 0.0}
    writer = Writer(sweep, out, values_of, index_of, done_rows, done_series)
    if todo:
        if own_client:
            client = connect(scheduler, workers, connect_timeout, quiet)
        try:
            summary.update(_run(sweep, client, todo, writer, quiet, on_result))
        finally:
            writer.flush()
            if own_client:
                cluster = client.cluster
                client.close()
                if cluster is not None:
                    cluster.close()
    writer.flush()
    summary["rows"] = len(writer.rows)
    summary["failed"] = sum(1 for r in writer.rows if r["status"] != "ok")
    if plot and sweep.plot:
        from .plot import plot_sweep

        summary["plot"] = plot_sweep(sweep, writer.frame(), out)
    return summary


def _run(sweep, client, todo, writer, quiet, on_result):
    from distributed import as_completed

    # workers of an external cluster need fmpy and distributed, not this
    # package: the worker code travels by value
    wt = worker_task_module()
    with open(sweep.fmu, "rb") as fh:
        fmu_bytes = fh.read()
    name = "yarnsim-sweep-fmu-" + hashlib.sha256(fmu_bytes).hexdigest()[:16]
    # once per cluster: a second sweep of the same FMU reuses the extraction
    has = client.run(lambda dask_worker, name=name: name in dask_worker.plugins)
    if not has or not all(has.values()):
            client.register_plugin(wt.FMUPlugin(name, fmu_bytes))
    info = client.scheduler_info()
    nworkers = len(info.get("workers", {}))
    if not quiet:
        link = getattr(client, "dashboard_link", None)
        print(f"sweep: {len(todo)} points on {nworkers} workers ({client.scheduler.address}); dashboard {link}", file=sys.stderr)
    run = sweep.run_config()
    t0 = time.perf_counter()
    futures = [
        client.submit(wt.run_point, name, run, key, values, key=f"point-{key}", pure=False, retries=0)
        for key, values in todo
    ]
    progress = Progress(len(futures), quiet)
    last = time.perf_counter()
    try:
        # with_results: the results come in batches, not one round trip each
        for fut, res in as_completed(futures, loop=client.loop, with_results=True, raise_errors=False):
            try:
                if fut.status == "error" or isinstance(res, BaseException):
                    raise res if isinstance(res, BaseException) else RuntimeError(str(res))
                row, series = res
            except Exception as exc:
                # the task itself failed (e.g. KilledWorker after repeated
                # worker deaths): still a row
                key = fut.key.removeprefix("point-") if isinstance(fut.key, str) else str(fut.key)
                row, series = {"point": key, "status": "lost", "message": f"{type(exc).__name__}: {exc}", "last_message": "",
                               "t_end": float("nan"), "wall_s": float("nan"), "worker": "", "pid": -1}, None
            writer.add(row, series)
            progress.update(row["status"] == "ok")
            if on_result is not None:
                on_result(row, client)
            if time.perf_counter() - last > FLUSH_S:
                writer.flush()
                last = time.perf_counter()
    except KeyboardInterrupt:
        client.cancel(futures)
        writer.flush()
        raise
    wall = time.perf_counter() - t0
    return {"ran": len(futures), "wall_s": wall, "workers": nworkers,
            "throughput": len(futures) / wall if wall > 0 else float("nan")}


class Writer:
    """Keeps the rows and series and writes them atomically."""

    def __init__(self, sweep, out, values_of, index_of, rows, series):
        self.sweep, self.out = sweep, out
        self.values_of, self.index_of = values_of, index_of
        self.rows = list(rows)
        self.series = list(series)
        self.pending = []
        self.columns = (["index", "point"] + list(sweep.varied)
                        + [f"{n}:{r}" for n, reds in sweep.outputs for r in reds if r != "series"]
                        + ["status", "message", "last_message", "t_end", "wall_s", "started", "worker", "pid"])
        self.series_names = [n for n, reds in sweep.outputs if "series" in reds]

    def add(self, row, series):
        key = row["point"]
        full = {"index": self.index_of.get(key, -1), **self.values_of.get(key, {}), **row}
        self.rows.append(full)
        if series is not None and self.series_names:
            n = len(series["time"])
            frame = {"point": np.full(n, key), "time": series["time"]}
            for name in self.series_names:
                frame[name] = series[name]
            self.pending.append(pd.DataFrame(frame))

    def frame(self):
        df = pd.DataFrame(self.rows)
        for c in self.columns:
            if c not in df.columns:
                df[c] = np.nan
        df = df[self.columns + [c for c in df.columns if c not in self.columns]]
        return df.sort_values("index", kind="stable").reset_index(drop=True)

    def flush(self):
        if not self.rows:
            return
        df = self.frame()
        _atomic(df.to_parquet, os.path.join(self.out, "results.parquet"), index=False)
        _atomic(lambda p: df.to_csv(p, index=False, float_format="%.17g"), os.path.join(self.out, "results.csv"))
        if self.pending:
            self.series.extend(self.pending)
            self.pending = []
        if self.series_names and self.series:
            s = pd.concat(self.series, ignore_index=True)
            order = s["point"].map(self.index_of)
            s = s.assign(_o=order).sort_values(["_o", "time"], kind="stable").drop(columns="_o").reset_index(drop=True)
            self.series = [s]
            _atomic(s.to_parquet, os.path.join(self.out, "series.parquet"), index=False)
        elif os.path.exists(os.path.join(self.out, "series.parquet")):
            os.remove(os.path.join(self.out, "series.parquet"))  # an earlier run's


def _atomic(write, path, **kw):
    tmp = path + ".tmp"
    write(tmp, **kw)
    os.replace(tmp, path)
