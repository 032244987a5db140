"""fmpy checks of the FMI 3.0 YarnBundle and MassSpring FMUs (run by tools/fmu/fmu_check.sh).

usage: fmu3_check.py WORKDIR REPLAY_EXE SMALL_SCENE SMALL3.fmu SMALL2.fmu REF3.fmu REF2.fmu WIRE3.fmu WIRE2.fmu DRIVEN3.fmu DRIVEN2.fmu

1. fmpy's validation (schema, structure, start values, units) of every
   FMI 3.0 FMU.
2. fmpy.simulate_fmu of the FMI 3.0 and the FMI 2.0 FMU of the same scene
   with the same input signals: every scalar output of the FMI 2.0 FMU (yarn
   ends, energies, stretch, substeps, pin forces, particle positions) equal
   bit for bit in the FMI 3.0 run; on the driven scene with a table that
   waves the driven yarn end (pin[0].x, .y, .vx, .vy).
3. The arrays against the library: the small scene's yarn[i].positions and
   yarn[i].velocities against fmu-replay --vertices (the Rust library run of
   the same inputs, no FMU), the wire's positions against the FMI 2.0 FMU's
   particle[i].x/y/z, bit for bit.
4. An FMU state round trip through fmpy's FMI 3.0 calls: get + serialize at
   t1, run on, deserialize + set, run on again: the same bits (arrays and
   scalars).
Exits non-zero on any problem; prints the comparison counts.
"""
import csv
import math
import subprocess
import sys

import numpy as np
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi3 import FMU3Slave

from fmu_inputs import circling_attractor, finish, input_signals, state_round_trip, time_grid, validate

work, replay, small_scene = sys.argv[1:4]
small3, small2, ref3, ref2, wire3, wire2, driven3, driven2 = sys.argv[4:12]
failures = []


def outputs_of(path):
    md = read_model_description(path)
    return md, [v for v in md.modelVariables if v.causality == "output"]


def simulate(path, signals, h, stop, names):
    return simulate_fmu(
        path, start_time=0.0, stop_time=stop, output_interval=h, input=signals, output=names, validate=True
    )


def same_bits(label, a, b):
    """Counts the values of two equal-shaped float sequences; every pair must be bit-identical."""
    a = np.ascontiguousarray(a, dtype=np.float64).ravel()
    b = np.ascontiguousarray(b, dtype=np.float64).ravel()
    if a.shape != b.shape:
        failures.append(f"{label}: {a.shape} values vs {b.shape}")
        return 0
    bad = np.flatnonzero(a.view(np.uint64) != b.view(np.uint64))
    if len(bad):
        k = bad[0]
        failures.append(f"{label}: {len(bad)} of {len(a)} values differ, first at {k}: {a[k]!r} vs {b[k]!r}")
    if not np.all(np.isfinite(a)):
        failures.append(f"{label}: non-finite values")
    return len(a)


def against_fmi2(label, path3, path2, signals, h, stop):
    """FMI 3.0 and FMI 2.0 FMU of one scene under the same inputs: every
    FMI 2.0 output equal in the FMI 3.0 run; returns the FMI 3.0 result."""
    _, outs3 = outputs_of(path3)
    _, outs2 = outputs_of(path2)
    names2 = [v.name for v in outs2]
    names3 = [v.name for v in outs3]
    missing = [n for n in names2 if n not in names3]
    if missing:
        failures.append(f"{label}: the FMI 3.0 FMU lacks {missing[:5]}")
    r3 = simulate(path3, signals, h, stop, names3)
    r2 = simulate(path2, signals, h, stop, names2)
    before = len(failures)
    count = same_bits(f"{label}: time", r3["time"], r2["time"])
    for n in names2:
        if n in names3:
            count += same_bits(f"{label}: {n}", r3[n], r2[n])
    print(f"{label}: FMI 3.0 vs FMI 2.0 (fmpy): {len(r3)} rows x {len(names2)} outputs, {count} values, all bit-identical: {len(failures) == before}")
    return r3, r2


def fmi3_state_round_trip(label, path, h, names):
    """get + serialize at t1, run on, deserialize + set, run on again."""
    md = read_model_description(path)
    vrs = {v.name: v for v in md.modelVariables}
    refs = [vrs[n].valueReference for n in names]
    n_values = sum(int(np.prod(vrs[n].shape)) if vrs[n].shape else 1 for n in names)
    fmu = FMU3Slave(
        guid=md.instantiationToken, unzipDirectory=extract(path),
        modelIdentifier=md.coSimulation.modelIdentifier, instanceName="state",
    )
    fmu.instantiate()
    fmu.enterInitializationMode(startTime=0.0)
    fmu.exitInitializationMode()

    def step(t, h):
        _, terminate, early, _ = fmu.doStep(t, h)
        if terminate or early:
            failures.append(f"{label}: doStep set terminateSimulation or earlyReturn")

    blob, first, second, states = state_round_trip(
        step, lambda: fmu.getFloat64(refs, n_values), fmu.getFMUState, fmu.serializeFMUState,
        fmu.deserializeFMUState, fmu.setFMUState, h,
    )
    count = same_bits(f"{label}: state round trip", second, first)
    print(f"{label}: FMI 3.0 state round trip through fmpy: {len(bytes(blob))} bytes, {count} values after it, identical: {first == second}")
    for state in states:
        fmu.freeFMUState(state)
    fmu.terminate()
    fmu.freeInstance()


def read_csv(path):
    with open(path) as fh:
        return list(csv.DictReader(fh))


for f in (small3, ref3, wire3, driven3):
    validate(f, failures)

# the small scene: attractor on a circle, gravity turning (as fmu_check.py)
H, STOP = 0.01, 0.4
in_csv = f"{work}/inputs3.csv"
signals = input_signals(in_csv, circling_attractor(H, STOP))
r3, _ = against_fmi2("YarnBundle (small)", small3, small2, signals, H, STOP)

# arrays against the library run of the same inputs (fmu-replay --vertices)
out_csv = f"{work}/rust3.csv"
subprocess.run(
    [replay, "--scene", small_scene, "--inputs", in_csv, "--step", repr(H), "--stop", repr(STOP), "-o", out_csv, "--vertices"],
    check=True,
)
rust = read_csv(out_csv)
_, outs3 = outputs_of(small3)
arrays = [v for v in outs3 if v.shape]
count = 0
if len(rust) != len(r3):
    failures.append(f"arrays: fmpy {len(r3)} rows, fmu-replay {len(rust)}")
for v in arrays:
    size = int(np.prod(v.shape))
    lib = np.array([[float(row[f"{v.name}[{j}]"]) for j in range(size)] for row in rust])
    count += same_bits(f"YarnBundle (small) {v.name} vs library", np.stack(list(r3[v.name])), lib)
print(f"YarnBundle (small): {len(arrays)} arrays vs the library run (fmu-replay --vertices): {len(r3)} rows, {count} values")

# the default scene: two frames
HR = 1 / 60
against_fmi2("YarnBundle (default scene)", ref3, ref2, None, HR, 2 * HR)

# the wire: gravity signal; positions against the FMI 2.0 particle outputs
HW, STOPW = 0.05, 1.0
n, t = time_grid(HW, STOPW)
wcols = [("time", t), ("gravity.x", 3.0 * np.sin(4.0 * t)), ("gravity.y", np.full(n, -9.81)), ("gravity.z", 2.0 * np.cos(3.0 * t))]
wsignals = np.array(list(zip(*[c for _, c in wcols])), dtype=[(name, np.double) for name, _ in wcols])
w3, w2 = against_fmi2("MassSpring (wire)", wire3, wire2, wsignals, HW, STOPW)
_, outs2 = outputs_of(wire2)
particles = [v.name for v in outs2 if v.name.startswith("particle[")]
flat = np.array([[row[p] for p in particles] for row in w2])
count = same_bits("MassSpring (wire) positions vs particle[i]", np.stack(list(w3["positions"])).reshape(len(w3), -1), flat)
print(f"MassSpring (wire): positions array vs the FMI 2.0 particle outputs: {count} values")

# the driven scene: the driven end waves sideways and rises (as fmu_check.py)
HD, STOPD = 0.01, 0.3
n, t = time_grid(HD, STOPD)
w = 2 * math.pi / 0.3
dcols = [
    ("time", t),
    ("pin[0].x", 0.25 + 0.05 * np.sin(w * t)),
    ("pin[0].y", 0.65 + 0.1 * t),
    ("pin[0].vx", 0.05 * w * np.cos(w * t)),
    ("pin[0].vy", np.full(n, 0.1)),
]
dsignals = input_signals(f"{work}/driven3.csv", dcols)
d3, _ = against_fmi2("YarnBundle (driven)", driven3, driven2, dsignals, HD, STOPD)
# the driven end is the first vertex of yarn 0's positions
first = np.stack([p[0] for p in d3["yarn[0].positions"]])
same_bits("YarnBundle (driven): yarn[0].positions[0] vs yarn[0].left", first, np.stack([d3["yarn[0].left.x"], d3["yarn[0].left.y"]], axis=1))

fmi3_state_round_trip("YarnBundle (small)", small3, H, [v.name for v in outs3 if v.type == "Float64"])
_, wouts3 = outputs_of(wire3)
fmi3_state_round_trip("MassSpring (wire)", wire3, HW, [v.name for v in wouts3 if v.type == "Float64"])

finish("FMI 3.0 FMU check", failures)
