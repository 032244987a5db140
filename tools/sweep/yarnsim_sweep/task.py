"""What runs on the Dask workers: the FMU plugin and one sweep point.

This module imports only the standard library, numpy, fmpy and distributed,
and the client registers it with cloudpickle by value, so workers of an
external cluster need fmpy and dask/distributed but not this package.
"""
import contextlib
import io
import os
import time
import zipfile

import numpy as np
from distributed import WorkerPlugin, get_worker

STATUS_NAMES = {0: "ok", 1: "warning", 2: "discard", 3: "error", 4: "fatal", 5: "pending"}
REDUCTIONS = ("final", "min", "max", "series")


class FMUPlugin(WorkerPlugin):
    """Extracts the FMU once per worker process (also on workers that join
    or restart later) and pins the FMU's library to one thread."""

    def __init__(self, name, fmu_bytes):
        self.name = name
        self.fmu_bytes = fmu_bytes
        self.unzipdir = None
        self.model_description = None

    def setup(self, worker):
        # rayon reads this when its global pool starts, i.e. at the first
        # substep in this process: one FMU instance per worker thread.
        os.environ["RAYON_NUM_THREADS"] = "1"
        from fmpy import read_model_description

        unzipdir = os.path.join(worker.local_directory, self.name)
        os.makedirs(unzipdir, exist_ok=True)
        with zipfile.ZipFile(io.BytesIO(self.fmu_bytes)) as z:
            z.extractall(unzipdir)
        self.unzipdir = unzipdir
        self.model_description = read_model_description(unzipdir)
        # keep the library loaded between tasks: fmpy's freeInstance
        # dlcloses it after every point otherwise
        import ctypes

        ident = self.model_description.coSimulation.modelIdentifier
        self._lib = ctypes.CDLL(os.path.join(unzipdir, "binaries", "linux64", ident + ".so"))
        self.extractions = getattr(self, "extractions", 0) + 1


def build_input(spec_signals):
    """The structured array fmpy's Input takes, or None."""
    if not spec_signals:
        return None
    names, dtypes, cols = spec_signals
    return np.array(list(zip(*cols)), dtype=list(zip(names, dtypes)))


def simulate_point(unzipdir, model_description, run, values, logger):
    """One bare fmpy simulation of a point (also what the tests and the
    benchmark call serially): returns fmpy's result array."""
    from fmpy import simulate_fmu
    from fmpy.simulation import instantiate_fmu

    start_values = dict(run["fixed"])
    start_values.update(values)
    fmu = instantiate_fmu(unzipdir, model_description, "CoSimulation", logger=logger)
    try:
        return simulate_fmu(
            unzipdir,
            validate=False,
            start_time=run["start_time"],
            stop_time=run["stop_time"],
            output_interval=run["output_interval"],
            start_values=start_values,
            input=build_input(run["signals"]),
            output=run["record"],
            timeout=run["point_timeout"],
            model_description=model_description,
            fmu_instance=fmu,
        )
    finally:
        fmu.freeInstance()


def reduce_result(result, outputs):
    """{column: value} for the scalar reductions, {name: array} for series."""
    scalars, series = {}, {}
    for name, reds in outputs:
        col = np.asarray(result[name], dtype=np.float64)
        for red in reds:
            if red == "final":
                scalars[f"{name}:final"] = float(col[-1])
            elif red == "min":
                scalars[f"{name}:min"] = float(col.min())
            elif red == "max":
                scalars[f"{name}:max"] = float(col.max())
            elif red == "series":
                series[name] = col
    return scalars, series


def run_point(plugin_name, run, key, values):
    """One sweep point on a worker: a row (dict) and its series (or None).

    Failures are data: an FMU that returns Discard/Error, an exception in
    fmpy, a run that stops early or a non-finite kept output give a row with
    status and the FMU's messages."""
    started = time.time()
    t0 = time.perf_counter()
    worker = get_worker()
    plugin = worker.plugins[plugin_name]
    log = []

    def logger(env, instance, status, category, message):
        log.append((int(status), message.decode("utf-8", "replace") if isinstance(message, bytes) else str(message)))

    row = {"point": key, "status": "ok", "message": "", "last_message": ""}
    series = None
    try:
        # fmpy prints "missing input" warnings for inputs without a signal
        with contextlib.redirect_stdout(io.StringIO()):
            result = simulate_point(plugin.unzipdir, plugin.model_description, run, values, logger)
        t_end = float(result["time"][-1])
        row["t_end"] = t_end
        scalars, series = reduce_result(result, run["outputs"])
        row.update(scalars)
        series = {"time": np.asarray(result["time"], dtype=np.float64), **series} if series else None
        if not np.isclose(t_end, run["stop_time"], rtol=1e-9, atol=0.0):
            elapsed = time.perf_counter() - t0
            timed_out = run["point_timeout"] is not None and elapsed >= run["point_timeout"]
            row["status"] = "timeout" if timed_out else "stopped"
            row["message"] = f"the run ended at t = {t_end} s, before the stop time {run['stop_time']} s"
        elif not all(np.isfinite(v) for v in scalars.values()):
            bad = [k for k, v in scalars.items() if not np.isfinite(v)]
            row["status"] = "nonfinite"
            row["message"] = "non-finite outputs: " + ", ".join(bad)
    except Exception as exc:  # the point failed; the sweep goes on
        row["status"] = "error"
        row["message"] = f"{type(exc).__name__}: {exc}"
        row["t_end"] = float("nan")
    bad = [(s, m) for s, m in log if s >= 2]
    if bad:
        # the status of the first message above Warning is the cause
        # (a Discard is followed by an Error from fmpy's GetReal)
        row["status"] = STATUS_NAMES.get(bad[0][0], "error")
        row["message"] = bad[0][1]
    if log:
        row["last_message"] = log[-1][1]
    if row["status"] != "ok":
        series = None
    row["wall_s"] = time.perf_counter() - t0
    row["started"] = started
    row["worker"] = worker.address
    row["pid"] = os.getpid()
    return row, series
