"""yarnsim-sweep on a 2-worker LocalCluster: rows equal serial fmpy runs bit
for bit, failures are rows, a killed worker loses no point, --resume runs
only the missing points, bad input is refused naming the field."""
import os
import signal
import socket
import time

import numpy as np
import pandas as pd
import pytest
from fmpy import simulate_fmu

from yarnsim_sweep import Sweep, SweepError, connect, run_sweep
from yarnsim_sweep.__main__ import main

from conftest import make_cluster

SMALL = """
fmu = "{fmu}"
stop_time = 0.15
output_interval = 0.01
[parameters]
"material.friction" = [0.0, 0.1, 0.3]
[inputs]
"attractor.strength" = [20.0, 60.0]
[signals]
time = [0.0, 0.05, 0.15]
"attractor.active" = [false, true, true]
"gravity.x" = [0.0, 2.0, -1.0]
[outputs]
kinetic_energy = ["final", "min", "max", "series"]
"yarn[0].left.y" = ["final", "series"]
substeps = ["final"]
[plot]
value = "kinetic_energy:final"
x = "material.friction"
"""

WIRE = """
fmu = "{fmu}"
stop_time = 1.0
output_interval = 0.05
[parameters]
integrator = ["backward-euler", "trapezoidal"]
[inputs]
"gravity.x" = {{ start = 0.0, stop = 4.0, num = 3 }}
[signals]
time = [0.0, 0.5, 1.0]
"gravity.z" = [0.0, 3.0, -2.0]
[outputs]
"particle[10].y" = ["final", "min", "max", "series"]
total_energy = ["final", "max"]
[plot]
value = "particle[10].y:final"
x = "gravity.x"
y = "integrator"
"""


def serial(fmu, sweep_values, fixed_signals, outputs, stop, h):
    """A plain fmpy run of one point, built independently of the tool."""
    names = list(fixed_signals)
    sig = np.array(list(zip(*fixed_signals.values())),
                   dtype=[(n, np.bool_ if isinstance(fixed_signals[n][0], bool) else np.float64) for n in names])
    return simulate_fmu(fmu, stop_time=stop, output_interval=h, start_values=dict(sweep_values),
                        input=sig, output=outputs)


def check_rows_equal_serial(df, series, fmu, varied, signals, outputs, stop, h):
    assert (df["status"] == "ok").all(), df[["status", "message"]]
    for _, row in df.iterrows():
        values = {n: (row[n].item() if hasattr(row[n], "item") else row[n]) for n in varied}
        ref = serial(fmu, values, signals, [n for n, _ in outputs], stop, h)
        for name, reds in outputs:
            col = ref[name].astype(np.float64)
            expect = {"final": col[-1], "min": col.min(), "max": col.max()}
            for r in reds:
                if r == "series":
                    got = series[series["point"] == row["point"]]
                    assert np.array_equal(got["time"].to_numpy(), ref["time"])
                    assert np.array_equal(got[name].to_numpy(), col), (values, name)
                else:
                    assert row[f"{name}:{r}"] == expect[r], (values, name, r, row[f"{name}:{r}"], expect[r])


def test_small_yarnbundle_3x2_equals_serial_fmpy(client, small_fmu, write_sweep, tmp_path):
    sweep = Sweep(write_sweep(SMALL.format(fmu=small_fmu)))
    assert len(sweep.points) == 6
    out = str(tmp_path / "out")
    s = run_sweep(sweep, out, client=client, quiet=True)
    assert s["ran"] == 6 and s["rows"] == 6 and s["failed"] == 0
    df = pd.read_parquet(os.path.join(out, "results.parquet"))
    csv = pd.read_csv(os.path.join(out, "results.csv"))
    series = pd.read_parquet(os.path.join(out, "series.parquet"))
    assert len(df) == len(csv) == 6 and os.path.getsize(os.path.join(out, "plot.png")) > 1000
    assert (csv["kinetic_energy:final"].to_numpy() == df["kinetic_energy:final"].to_numpy()).all()  # %.17g round trip
    assert df["worker"].nunique() == 2 and (df["wall_s"] > 0).all()
    check_rows_equal_serial(df, series, small_fmu, ["material.friction", "attractor.strength"],
                            {"time": [0.0, 0.05, 0.15], "attractor.active": [False, True, True], "gravity.x": [0.0, 2.0, -1.0]},
                            sweep.outputs, 0.15, 0.01)
    # the attractor strength had an effect, so the points differ
    assert df["kinetic_energy:max"].nunique() == 6
    # extracted once per worker, not once per task
    name = [n for n in client.run(lambda dask_worker: list(dask_worker.plugins)).popitem()[1] if n.startswith("yarnsim-sweep-fmu")]
    counts = client.run(lambda dask_worker: sorted(getattr(dask_worker.plugins[p], "extractions", 0) for p in dask_worker.plugins if p.startswith("yarnsim-sweep-fmu")))
    assert name and all(c == [1] * len(c) for c in counts.values())


def test_massspring_wire_3x2_equals_serial_fmpy(client, wire_fmu, write_sweep, tmp_path):
    sweep = Sweep(write_sweep(WIRE.format(fmu=wire_fmu)))
    out = str(tmp_path / "out")
    s = run_sweep(sweep, out, client=client, quiet=True)
    assert s["rows"] == 6 and s["failed"] == 0
    df = pd.read_parquet(os.path.join(out, "results.parquet"))
    series = pd.read_parquet(os.path.join(out, "series.parquet"))
    assert list(df["gravity.x"]) == [0.0, 2.0, 4.0] * 2
    check_rows_equal_serial(df, series, wire_fmu, ["integrator", "gravity.x"],
                            {"time": [0.0, 0.5, 1.0], "gravity.z": [0.0, 3.0, -2.0]}, sweep.outputs, 1.0, 0.05)
    assert os.path.getsize(os.path.join(out, "plot.png")) > 1000  # heat map over a number and a string


def test_diverging_points_are_failed_rows(client, wire_fmu, small_fmu, write_sweep, tmp_path):
    wire = Sweep(write_sweep(f"""
fmu = "{wire_fmu}"
stop_time = 1.0
output_interval = 0.05
[fixed]
integrator = "symplectic-euler"
[parameters]
dt = [0.0, 0.01, 0.0002]
[outputs]
total_energy = ["final", "series"]
""", "wire.toml"))
    s = run_sweep(wire, str(tmp_path / "wire"), client=client, quiet=True)
    df = pd.read_parquet(str(tmp_path / "wire" / "results.parquet"))
    assert s["rows"] == 3 and s["failed"] == 1
    assert list(df["status"]) == ["ok", "discard", "ok"]
    bad = df.iloc[1]
    # the FMU returns Discard, keeps the last good state readable, and the row
    # holds the outputs up to its last successful time
    assert "diverged" in bad["message"] and bad["t_end"] < 1.0
    assert bad["last_message"]  # the FMU's last log line
    assert np.isfinite(df["total_energy:final"][[0, 2]]).all()
    series = pd.read_parquet(str(tmp_path / "wire" / "series.parquet"))
    assert set(series["point"]) == set(df["point"][[0, 2]])

    small = Sweep(write_sweep(f"""
fmu = "{small_fmu}"
stop_time = 0.1
output_interval = 0.01
[parameters]
dt = [2e-4, 2e-3]
[outputs]
kinetic_energy = ["final"]
""", "small.toml"))
    run_sweep(small, str(tmp_path / "small"), client=client, quiet=True)
    df = pd.read_parquet(str(tmp_path / "small" / "results.parquet"))
    assert list(df["status"]) == ["ok", "discard"]
    assert "more than one cell per substep" in df["message"][1]


def test_killed_worker_still_gives_every_row(small_fmu, write_sweep, tmp_path):
    sweep = Sweep(write_sweep(SMALL.format(fmu=small_fmu)))
    ref_out = str(tmp_path / "ref")
    c = make_cluster()
    killed = []

    def kill_one(row, client):
        if killed:
            return
        pids = client.run(os.getpid)
        busy = [w for w, keys in client.processing().items() if keys] or list(pids)
        victim = busy[0]
        os.kill(pids[victim], signal.SIGKILL)
        killed.append((victim, pids[victim]))

    try:
        run_sweep(sweep, ref_out, client=c, quiet=True, plot=False)
        out = str(tmp_path / "out")
        s = run_sweep(sweep, out, client=c, quiet=True, plot=False, on_result=kill_one)
    finally:
        cluster = c.cluster
        c.close()
        cluster.close()
    assert killed
    assert s["rows"] == 6 and s["failed"] == 0
    df = pd.read_parquet(os.path.join(out, "results.parquet"))
    ref = pd.read_parquet(os.path.join(ref_out, "results.parquet"))
    cols = [c for c in ref.columns if ":" in c]
    assert df["point"].tolist() == ref["point"].tolist()
    assert (df[cols].to_numpy() == ref[cols].to_numpy()).all()
    assert (df["status"] == "ok").all()


def test_resume_runs_only_the_missing_points(client, wire_fmu, write_sweep, tmp_path):
    sweep = Sweep(write_sweep(WIRE.format(fmu=wire_fmu)))
    out = str(tmp_path / "out")
    run_sweep(sweep, out, client=client, quiet=True, plot=False)
    full = pd.read_parquet(os.path.join(out, "results.parquet"))
    full_series = pd.read_parquet(os.path.join(out, "series.parquet"))
    # an interrupted sweep: two rows (and their series) are missing
    gone = full["point"].iloc[[1, 4]].tolist()
    full[~full["point"].isin(gone)].to_parquet(os.path.join(out, "results.parquet"), index=False)
    full_series[~full_series["point"].isin(gone)].to_parquet(os.path.join(out, "series.parquet"), index=False)
    s = run_sweep(sweep, out, client=client, resume=True, quiet=True, plot=False)
    assert s["ran"] == 2 and s["skipped"] == 4 and s["rows"] == 6
    again = pd.read_parquet(os.path.join(out, "results.parquet"))
    cols = [c for c in full.columns if ":" in c]
    assert again["point"].tolist() == full["point"].tolist()
    assert (again[cols].to_numpy() == full[cols].to_numpy()).all()
    assert again.set_index("point").loc[gone, "pid"].notna().all()
    series = pd.read_parquet(os.path.join(out, "series.parquet"))
    assert series.equals(full_series)
    # nothing left to do: no task, no cluster
    s = run_sweep(sweep, out, resume=True, quiet=True, plot=False)
    assert s["ran"] == 0 and s["skipped"] == 6


# -- bad input -------------------------------------------------------------

def bad(write_sweep, text, preflight=False):
    with pytest.raises(SweepError) as err:
        s = Sweep(write_sweep(text))
        if preflight:
            s.preflight()
    return str(err.value)


def refused(write_sweep, text, prefix, *parts, preflight=False):
    """Asserts that the sweep `text` is refused with a message that starts
    with `prefix` and contains every one of `parts`."""
    msg = bad(write_sweep, text, preflight=preflight)
    assert msg.startswith(prefix), msg
    for part in parts:
        assert part in msg, msg


HEAD = """
fmu = "{fmu}"
stop_time = 0.5
output_interval = 0.05
[outputs]
total_energy = ["final"]
"""


def test_unknown_names_are_refused_naming_the_field(wire_fmu, write_sweep):
    h = HEAD.format(fmu=wire_fmu)
    refused(write_sweep, h + '[parameters]\n"dtt" = [0.001]\n', "parameters.dtt:", "no parameter named 'dtt'", "integrator")
    refused(write_sweep, h + '[inputs]\n"gravity.w" = [1.0]\n', 'inputs."gravity.w":', "no input named", "gravity.x")
    refused(write_sweep, h + '[parameters]\n"gravity.x" = [1.0]\n', 'parameters."gravity.x":', "is an input, expected parameter")
    refused(write_sweep, h.replace("total_energy", "total_enrgy") + '[parameters]\ndt = [0.001]\n', "outputs.total_enrgy:", "no variable named")
    refused(write_sweep, h.replace('["final"]', '["last"]') + '[parameters]\ndt = [0.001]\n', "outputs.total_energy:", "unknown reduction 'last'")
    refused(write_sweep, h + '[signals]\ntime = [0.0, 1.0]\n"gravity.q" = [0.0, 1.0]\n[parameters]\ndt = [0.001]\n', 'signals."gravity.q":')
    refused(write_sweep, h + '[parameters]\nintegrator = [3]\n', "parameters.integrator[0]:", "String")


def test_values_outside_the_range_are_refused_before_running(wire_fmu, small_fmu, write_sweep):
    h = HEAD.format(fmu=wire_fmu)
    refused(write_sweep, h + '[inputs]\n"gravity.x" = [0.0, 2e6]\n', 'inputs."gravity.x":', "2000000.0", preflight=True)
    refused(write_sweep, h + '[parameters]\nintegrator = ["backward-euler", "rk4"]\n', "parameters.integrator:", "'rk4'", preflight=True)
    refused(write_sweep, h + '[parameters]\ndt = [0.001, -1.0]\n', "parameters.dt:", "-1.0", preflight=True)
    refused(write_sweep, HEAD.format(fmu=small_fmu).replace("total_energy", "kinetic_energy")
            + '[parameters]\n"material.friction" = [0.1, -0.5]\n', 'parameters."material.friction":', "-0.5",
            preflight=True)
    refused(write_sweep, h + '[parameters]\ndt = { start = 0.0, stop = 0.01, num = 0 }\n', "parameters.dt.num:")
    refused(write_sweep, h + '[parameters]\ndt = { min = 0.0, max = 0.01 }\n', "parameters.dt:", "lhs")


def test_empty_sweep_and_missing_fmu(wire_fmu, write_sweep, tmp_path):
    h = HEAD.format(fmu=wire_fmu)
    refused(write_sweep, h, "parameters/inputs: the sweep is empty")
    refused(write_sweep, h + "[parameters]\ndt = []\n", "parameters.dt: empty list")
    refused(write_sweep, 'design = "lhs"\nsamples = 0\n' + h + "[parameters]\ndt = { min = 0.001, max = 0.002 }\n", "samples:")
    refused(write_sweep, HEAD.format(fmu=str(tmp_path / "nope.fmu")) + "[parameters]\ndt = [0.001]\n", "fmu:", "nope.fmu: no such file")
    refused(write_sweep, h.replace('fmu = "' + wire_fmu + '"', "") + "[parameters]\ndt = [0.001]\n", "fmu: missing")


def test_unreachable_scheduler_times_out_with_the_address():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    addr = f"tcp://127.0.0.1:{port}"
    t0 = time.perf_counter()
    with pytest.raises(SweepError) as err:
        connect(addr, timeout=2.0)
    assert time.perf_counter() - t0 < 20
    assert str(err.value).startswith(f"--scheduler: cannot reach the Dask scheduler at {addr} within 2 s")


def test_cli_reports_bad_input_with_exit_code_2(wire_fmu, write_sweep, capsys):
    p = write_sweep(HEAD.format(fmu=wire_fmu) + '[parameters]\n"dtt" = [0.001]\n')
    assert main([p, "-q"]) == 2
    assert "yarnsim-sweep: error: parameters.dtt:" in capsys.readouterr().err
    p = write_sweep(HEAD.format(fmu=wire_fmu) + '[parameters]\ndt = [0.001, 0.002]\n', "ok.toml")
    assert main([p, "--dry-run"]) == 0
    assert "2 points (factorial)" in capsys.readouterr().out


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_existing_cluster_whose_workers_lack_the_package(wire_fmu, write_sweep, tmp_path):
    """`dask scheduler` + `dask worker` processes as on other machines; the
    workers' Python cannot import yarnsim_sweep (site-packages on PYTHONPATH
    with -S, so the editable install's .pth is not read): the worker code
    travels by value. Same rows as the LocalCluster run."""
    import subprocess
    import sys
    import sysconfig

    port = free_port()
    addr = f"tcp://127.0.0.1:{port}"
    env = {**os.environ, "PYTHONPATH": sysconfig.get_paths()["purelib"], "RAYON_NUM_THREADS": "1"}
    sched = subprocess.Popen([sys.executable, "-S", "-c",
                              f"import sys; sys.argv=['dask-scheduler', '--port', '{port}', '--dashboard-address', ':0'];"
                              "from distributed.cli.dask_scheduler import main; main()"],
                             cwd=tmp_path, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    work = subprocess.Popen([sys.executable, "-S", "-c",
                             "import importlib.util, sys; assert importlib.util.find_spec('yarnsim_sweep') is None;"
                             f"sys.argv=['dask-worker', '{addr}', '--nworkers', '2', '--nthreads', '1'];"
                             "from distributed.cli.dask_worker import main; main()"],
                            cwd=tmp_path, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        sweep = Sweep(write_sweep(WIRE.format(fmu=wire_fmu)))
        c = connect(addr, timeout=30.0)
        try:
            c.wait_for_workers(2, timeout=60)
            s = run_sweep(sweep, str(tmp_path / "ext"), client=c, quiet=True, plot=False)
        finally:
            c.close()
        assert s["rows"] == 6 and s["failed"] == 0 and s["workers"] == 2
        df = pd.read_parquet(str(tmp_path / "ext" / "results.parquet"))
        series = pd.read_parquet(str(tmp_path / "ext" / "series.parquet"))
        check_rows_equal_serial(df, series, wire_fmu, ["integrator", "gravity.x"],
                                {"time": [0.0, 0.5, 1.0], "gravity.z": [0.0, 3.0, -2.0]}, sweep.outputs, 1.0, 0.05)
    finally:
        for p in (work, sched):
            p.terminate()
            try:
                p.wait(timeout=20)
            except subprocess.TimeoutExpired:
                p.kill()
