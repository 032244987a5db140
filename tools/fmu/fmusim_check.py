"""fmusim against fmpy on the same FMUs (run by tools/fmu/fmusim.sh).

usage: fmusim_check.py FMUSIM WORKDIR FMU [FMU ...]

For every FMU (FMI 2.0 or 3.0 Co-Simulation): one input table (every Real
and Boolean input at its start value, gravity held, then switched at half
time, so both masters apply the same value over every communication step
whatever their interpolation), run by the
Reference-FMUs master `fmusim` and by fmpy 0.3.32's `simulate_fmu` with the
same stop time and output interval; every output of every row compared.
fmusim writes Float64 values with `%.16g` (16 significant digits, not
always enough to read back the same double), so two values count as equal
when they agree to that precision: |a - b| <= 1e-15 |b| (or both 0). Array
outputs (FMI 3.0) are compared element by element. Prints one line per FMU
with the rows, values and largest difference; exits non-zero on any
mismatch or failed run.
"""
import csv
import math
import pathlib
import subprocess
import sys

import numpy as np
from fmpy import read_model_description, simulate_fmu

fmusim, work = sys.argv[1], pathlib.Path(sys.argv[2])
fmus = sys.argv[3:]
H, STOP = 0.01, 0.1
failures = []


def inputs_of(md):
    """The model's Real (Float64) and Boolean inputs: (name, is_boolean,
    start value)."""
    out = []
    for v in md.modelVariables:
        if v.causality == "input" and v.type in ("Real", "Float64", "Boolean"):
            boolean = v.type == "Boolean"
            start = (v.start in ("true", "1")) if boolean else float(v.start)
            out.append((v.name, boolean, start))
    if not any(name.startswith("gravity.") for name, _, _ in out):
        raise SystemExit(f"{md.modelName}: no gravity inputs")
    return out


def input_rows(inputs):
    """Every input at its start value, gravity (0, -9.8[, 0]) to half time
    and (1.5, -6[, 0.5]) after it."""
    before = {name: start for name, _, start in inputs}
    after = dict(before)
    before.update({"gravity.x": 0.0, "gravity.y": -9.8, "gravity.z": 0.0})
    after.update({"gravity.x": 1.5, "gravity.y": -6.0, "gravity.z": 0.5})
    half = round(STOP / 2 / H) * H
    return [(0.0, before), (half, before), (half, after), (STOP, after)]


def write_input(path, rows, inputs):
    """The table as fmusim reads it (Booleans as 0 / 1)."""
    with open(path, "w") as fh:
        fh.write(",".join(["time"] + [name for name, _, _ in inputs]) + "\n")
        for t, values in rows:
            cols = [str(int(values[n])) if b else repr(float(values[n])) for n, b, _ in inputs]
            fh.write(",".join([repr(t)] + cols) + "\n")


def fmpy_input(rows, inputs):
    dtype = [("time", np.double)] + [(n, np.bool_ if b else np.double) for n, b, _ in inputs]
    return np.array([tuple([t] + [values[n] for n, _, _ in inputs]) for t, values in rows], dtype=dtype)


def read_fmusim(path):
    """fmusim's output CSV: header of quoted names, rows of numbers (an
    array's values space-separated in one cell)."""
    with open(path) as fh:
        reader = csv.reader(fh)
        header = next(reader)
        rows = [[cell for cell in row] for row in reader]
    return header, rows


def cells(text):
    return [float(x) for x in text.split()]


def agree(a, b):
    return a == b or abs(a - b) <= 1e-15 * abs(b)


for fmu in fmus:
    md = read_model_description(fmu)
    label = pathlib.Path(fmu).name
    inputs = inputs_of(md)
    rows = input_rows(inputs)
    in_csv = work / f"{label}.in.csv"
    out_csv = work / f"{label}.fmusim.csv"
    write_input(in_csv, rows, inputs)
    run = subprocess.run(
        [fmusim, "--interface-type", "cs", "--stop-time", repr(STOP), "--output-interval", repr(H),
         "--input-file", str(in_csv), "--output-file", str(out_csv), "--log-level", "warning", fmu],
        capture_output=True, text=True, timeout=600)
    if run.returncode != 0:
        failures.append(f"{label}: fmusim exited {run.returncode}: {run.stdout}{run.stderr}")
        continue
    header, got = read_fmusim(out_csv)
    ref = simulate_fmu(fmu, stop_time=STOP, output_interval=H, input=fmpy_input(rows, inputs),
                       output=header[1:])
    if len(got) != len(ref):
        failures.append(f"{label}: fmusim gave {len(got)} rows, fmpy {len(ref)}")
    values, worst = 0, 0.0
    for k, (row, r) in enumerate(zip(got, ref)):
        for name, cell in zip(header, row):
            a = cells(cell)
            b = np.atleast_1d(np.asarray(r[name], dtype=float)).ravel().tolist()
            if len(a) != len(b):
                failures.append(f"{label} row {k}: {name} has {len(a)} values in fmusim, {len(b)} in fmpy")
                continue
            for x, y in zip(a, b):
                values += 1
                if not (math.isfinite(x) and math.isfinite(y)):
                    failures.append(f"{label} row {k}: {name} is {x} (fmusim) / {y} (fmpy)")
                elif not agree(x, y):
                    failures.append(f"{label} row {k} (t = {row[0]}): {name}: fmusim {x!r}, fmpy {y!r}")
                elif y != 0.0:
                    worst = max(worst, abs(x - y) / abs(y))
    print(f"fmusim vs fmpy {label} (FMI {md.fmiVersion}): {len(got)} rows, {len(header) - 1} variables, "
          f"{values} values compared, largest relative difference {worst:.1e}")

if failures:
    print("\n".join(failures[:40]), file=sys.stderr)
    print(f"{len(failures)} problems", file=sys.stderr)
    sys.exit(1)
