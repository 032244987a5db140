"""fmpy checks of the YarnBundle and MassSpring FMUs (run by tools/fmu/fmu_check.sh).

usage: fmu_check.py SMALL.fmu REFERENCE_SCENE.fmu WORKDIR REPLAY_EXE SMALL_SCENE WIRE.fmu DRIVEN.fmu DRIVEN_SCENE

1. fmpy's validation of both FMUs (schema, structure, start values, units).
2. fmpy.simulate_fmu of SMALL.fmu with an input signal (attractor on a
   circle, switched on at 0.1 s; gravity turning), compared bit for bit
   with the Rust library run of the same inputs (fmu-replay); again with
   the parameter dt = 0 (adaptive substeps) against the scene with
   dt = "auto", in fewer substeps; and the stiff setting (a fibre 100
   times stiffer, time.axial = "implicit", transfer.flip_time, dt = 0) set
   through start values alone, against the scene file that says the same,
   in fewer substeps than the explicit run of the stiff fibre.
3. FMU state through fmpy: get + serialize at t1, run on, deserialize +
   set, run on again: identical outputs.
4. A short simulate_fmu of the default (reference) scene FMU.
5. The MassSpring FMU of the wire scene: fmpy validation; simulate_fmu
   with a gravity signal under two integrators (the `integrator` string
   parameter), compared bit for bit with fmu-replay; an FMU state round trip.
6. The DRIVEN.fmu (a scene with a `motion = "input"` pin and a fixed one):
   simulate_fmu with an input table that waves the driven yarn end
   (pin[0].x, .y, .vx, .vy), compared bit for bit with fmu-replay (yarn
   ends, energies, pin forces); the driven end is at
   x_in + v_in (t - t_c) after every step; the pin forces are finite and
   the held pin carries a downward force.
Exits non-zero on any problem.
"""
import csv
import math
import re
import subprocess
import sys

import numpy as np
from fmpy import read_model_description, simulate_fmu, extract
from fmpy.fmi2 import FMU2Slave

from fmu_inputs import circling_attractor, finish, input_signals, state_round_trip, time_grid, validate

small_fmu, ref_fmu, work, replay, small_scene, wire_fmu, driven_fmu, driven_scene = sys.argv[1:9]
failures = []


def compare(label, result, rust_csv, outputs):
    """Every output of the fmpy run against the Rust run, bit for bit."""
    with open(rust_csv) as fh:
        rust = list(csv.DictReader(fh))
    if len(rust) != len(result):
        failures.append(f"{label}: fmpy gave {len(result)} rows, the Rust run {len(rust)}")
    max_diff, compared = 0.0, 0
    for k, (row, ref) in enumerate(zip(result, rust)):
        if not math.isclose(float(ref["time"]), row["time"]):
            failures.append(f"{label} row {k}: time {row['time']} vs {ref['time']}")
        for name in outputs:
            a, b = float(row[name]), float(ref[name])
            compared += 1
            if not math.isfinite(a):
                failures.append(f"{label} row {k}: {name} is {a}")
            d = abs(a - b)
            max_diff = max(max_diff, d)
            if d != 0.0:
                failures.append(f"{label} row {k} (t = {row['time']}): {name}: fmpy {a!r}, Rust {b!r}")
    print(f"{label}: simulate_fmu vs Rust: {len(result)} rows x {len(outputs)} outputs, {compared} values, max |diff| = {max_diff}")


def against_replay(label, fmu, scene, in_csv, signals, outputs, h, stop, out_csv, start_values=None, replay_args=()):
    """simulate_fmu of `fmu` with the input `signals` (also in `in_csv`),
    fmu-replay of `scene` with the same inputs into `out_csv`, and every
    output compared bit for bit; returns the fmpy result."""
    result = simulate_fmu(
        fmu,
        start_time=0.0,
        stop_time=stop,
        output_interval=h,
        input=signals,
        output=outputs,
        start_values=start_values or {},
        validate=True,
    )
    subprocess.run(
        [replay, "--scene", scene, *replay_args, "--inputs", in_csv, "--step", repr(h), "--stop", repr(stop), "-o", out_csv],
        check=True,
    )
    compare(label, result, out_csv, outputs)
    return result


def fmi2_state_round_trip(label, path, h, vrs):
    """get + serialize at t1, run on, deserialize + set, run on again."""
    md = read_model_description(path)
    unzip = extract(path)
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzip, modelIdentifier=md.coSimulation.modelIdentifier, instanceName="state")
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    blob, first, second, states = state_round_trip(
        fmu.doStep, lambda: fmu.getReal(vrs), fmu.getFMUstate, fmu.serializeFMUstate,
        fmu.deSerializeFMUstate, fmu.setFMUstate, h,
    )
    if first != second:
        failures.append(f"{label}: FMU state round trip through fmpy: outputs differ")
    print(f"{label}: state round trip through fmpy: {len(bytes(blob))} bytes, {'identical' if first == second else 'DIFFERENT'} outputs")
    for state in states:
        fmu.freeFMUstate(state)
    fmu.terminate()
    fmu.freeInstance()


# 1. validation
for f in (small_fmu, ref_fmu, wire_fmu):
    validate(f, failures)

# 2. simulate with an input signal and compare with the Rust side
H, STOP = 0.01, 0.4
cols = circling_attractor(H, STOP)
in_csv = f"{work}/inputs.csv"
signals = input_signals(in_csv, cols)

md = read_model_description(small_fmu)
outputs = [v.name for v in md.modelVariables if v.causality == "output"]
result = against_replay("YarnBundle (small)", small_fmu, small_scene, in_csv, signals, outputs, H, STOP, f"{work}/rust.csv")
moved = max(abs(result[-1][n] - result[0][n]) for n in outputs if n.startswith("yarn"))
if not moved > 0.05:
    failures.append(f"the yarn ends moved only {moved} m: the inputs had no effect")

# 2b. the same under adaptive substeps: the FMU's dt = 0 against the Rust
# run of the scene with dt = "auto"; fewer substeps than the fixed 2e-4
with open(small_scene) as fh:
    scene_text = fh.read()
auto_text = re.sub(r"(?m)^dt\s*=.*$", 'dt = "auto"', scene_text, count=1)
if auto_text == scene_text:
    failures.append("could not set dt = \"auto\" in the small scene")
auto_scene = f"{work}/small_auto.toml"
with open(auto_scene, "w") as fh:
    fh.write(auto_text)
result_auto = against_replay(
    "YarnBundle (small, dt = 0: auto)", small_fmu, auto_scene, in_csv, signals, outputs, H, STOP,
    f"{work}/rust_auto.csv", start_values={"dt": 0.0},
)
fixed_n, auto_n = result[-1]["substeps"], result_auto[-1]["substeps"]
print(f"substeps to {STOP} s: fixed dt {fixed_n:.0f}, auto {auto_n:.0f}")
if not auto_n < fixed_n:
    failures.append(f"auto took {auto_n} substeps, the fixed dt {fixed_n}")

# 2c. the stiff setting through parameters alone: a fibre 100 times
# stiffer (material.k), its stretch by backward Euler (time.axial), FLIP
# relaxed over 2 ms (transfer.flip_time), adaptive substeps (dt = 0),
# against the Rust run of the scene file that says the same; the axial
# step lifts the fibre wave's bound, so fewer substeps than the explicit
# run of the same stiff fibre
stiff_text = re.sub(r"(?m)^k\s*=.*$", "k = 100000.0", auto_text, count=1)
stiff_text = re.sub(r'(?m)^dt = "auto"$', 'dt = "auto"\naxial = "implicit"', stiff_text, count=1)
stiff_text += "\n[transfer]\nflip_time = 0.002\n"
if stiff_text.count("100000.0") != 1 or 'axial = "implicit"' not in stiff_text:
    failures.append("could not write the stiff small scene")
stiff_scene = f"{work}/small_stiff.toml"
with open(stiff_scene, "w") as fh:
    fh.write(stiff_text)
stiff = {"material.k": 1e5, "dt": 0.0, "transfer.flip_time": 0.002}
result_stiff = against_replay(
    "YarnBundle (small, k x100, time.axial = implicit, flip_time 2 ms, dt = 0)", small_fmu, stiff_scene,
    in_csv, signals, outputs, H, STOP, f"{work}/rust_stiff.csv",
    start_values={**stiff, "time.axial": "implicit"},
)
explicit_stiff = simulate_fmu(small_fmu, stop_time=STOP, output_interval=H, input=signals,
                              output=["substeps", "max_stretch"], start_values=stiff)
axial_n, explicit_n = result_stiff[-1]["substeps"], explicit_stiff[-1]["substeps"]
stretch = max(result_stiff["max_stretch"])
print(f"k x100, substeps to {STOP} s: time.axial implicit {axial_n:.0f}, explicit {explicit_n:.0f}; "
      f"largest stretch {stretch:.6f}")
if not axial_n < explicit_n:
    failures.append(f"time.axial = implicit took {axial_n} substeps, explicit {explicit_n}")
if not stretch < 1.01:
    failures.append(f"time.axial = implicit stretched a segment to {stretch}")

# 3. FMU state through fmpy's C calls
vrs = [v.valueReference for v in md.modelVariables if v.causality == "output" and v.type == "Real"]
fmi2_state_round_trip("YarnBundle (small)", small_fmu, H, vrs)

# 4. the default scene FMU runs in fmpy
ref = simulate_fmu(ref_fmu, stop_time=2 / 60, output_interval=1 / 60, validate=True)
ok = all(math.isfinite(ref[-1][name]) for name in ref.dtype.names)
print(f"default scene FMU: {len(ref)} rows, {len(ref.dtype.names) - 1} outputs, finite: {ok}")
if not ok:
    failures.append("default scene FMU gave non-finite outputs")

# 5. the MassSpring FMU of the wire
HW, STOPW = 0.05, 1.0
n, t = time_grid(HW, STOPW)
cols = [
    ("time", t),
    ("gravity.x", 3.0 * np.sin(4.0 * t)),
    ("gravity.y", np.full(n, -9.81)),
    ("gravity.z", 2.0 * np.cos(3.0 * t)),
]
in_csv = f"{work}/wire_inputs.csv"
signals = input_signals(in_csv, cols)
md = read_model_description(wire_fmu)
outputs = [v.name for v in md.modelVariables if v.causality == "output"]
for integrator in ("backward-euler", "symplectic-euler"):
    against_replay(
        f"MassSpring (wire, {integrator})", wire_fmu, "wire", in_csv, signals, outputs, HW, STOPW,
        f"{work}/wire_{integrator}.csv", start_values={"integrator": integrator},
        replay_args=("--integrator", integrator),
    )
vrs = [v.valueReference for v in md.modelVariables if v.causality == "output" and v.type == "Real"]
fmi2_state_round_trip("MassSpring (wire)", wire_fmu, HW, vrs)

# 6. a driven yarn end from an input table
validate(driven_fmu, failures)
HD, STOPD = 0.01, 0.3
n, t = time_grid(HD, STOPD)
w = 2 * math.pi / 0.3
cols = [
    ("time", t),
    ("attractor.x", np.full(n, 0.5)),
    ("attractor.y", np.full(n, 0.5)),
    ("attractor.strength", np.full(n, 20.0)),
    ("attractor.active", np.zeros(n, dtype=bool)),
    ("gravity.x", np.zeros(n)),
    ("gravity.y", np.full(n, -9.8)),
    ("pin[0].x", 0.25 + 0.05 * np.sin(w * t)),
    ("pin[0].y", 0.65 + 0.1 * t),
    ("pin[0].vx", 0.05 * w * np.cos(w * t)),
    ("pin[0].vy", np.full(n, 0.1)),
]
in_csv = f"{work}/driven_inputs.csv"
signals = input_signals(in_csv, cols)
md = read_model_description(driven_fmu)
outputs = [v.name for v in md.modelVariables if v.causality == "output"]
for name in ("pin[0].force.x", "pin[0].force.y", "pin[1].force.x", "pin[1].force.y"):
    if name not in outputs:
        failures.append(f"driven FMU: no output {name}")
result = against_replay(
    "YarnBundle (driven)", driven_fmu, driven_scene, in_csv, signals, outputs, HD, STOPD, f"{work}/driven_rust.csv"
)
follow = 0.0
for k in range(1, len(result)):
    tc, te = result[k - 1]["time"], result[k]["time"]
    i = int(round(tc / HD))
    x = cols[7][1][i] + cols[9][1][i] * (te - tc)
    y = cols[8][1][i] + cols[10][1][i] * (te - tc)
    follow = max(follow, abs(result[k]["yarn[0].left.x"] - x), abs(result[k]["yarn[0].left.y"] - y))
print(f"driven end vs x_in + v_in (t - t_c): max |diff| = {follow:.2e} m over {len(result) - 1} steps")
if not follow < 1e-9:
    failures.append(f"the driven end is {follow} m from its input")
forces = np.array([[row[name] for name in outputs if name.startswith("pin")] for row in result])
if not np.all(np.isfinite(forces)):
    failures.append("driven FMU: non-finite pin forces")
held = np.mean([row["pin[1].force.y"] for row in result[10:]])
print(f"driven FMU: mean force on the held pin (t >= 0.1 s) {held:.4f} N/m (y), on the driven one {np.mean([row['pin[0].force.y'] for row in result[10:]]):.4f} N/m")
if not held < 0.0:
    failures.append(f"the held pin is not pulled down ({held} N/m)")

finish("FMU check", failures)
