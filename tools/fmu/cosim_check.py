"""libcosimpy checks of the FMUs (run by tools/fmu/fmu_check.sh after the fmpy checks).

usage: cosim_check.py SMALL.fmu WIRE.fmu

libcosimpy 0.0.6 (PyPI wheel with the Open Simulation Platform's libcosim)
runs the FMUs with its fixed-step master, and every output is compared bit
for bit with fmpy's FMU2Slave driven the same way:

1. One FMU with an input changed through libcosim's override manipulator
   (the wire: gravity.x = 4 m/s2 from t = 0.5 s; yarn-small: gravity.x = 3
   m/s2 from t = 0.1 s).
2. Two FMUs connected output -> input: wire A's particle[10].x feeds wire
   B's gravity.x (times 1: a few cm read as m/s2), and wire A's
   particle[10].x feeds yarn-small's gravity.x. libcosim transfers the
   value an output had at the end of step k to the input before step k + 1
   (and the value after initialization before the first step); the fmpy
   side does the same.
Exits non-zero on any difference.
"""
import sys

from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
from libcosimpy.CosimExecution import CosimExecution
from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
from libcosimpy.CosimManipulator import CosimManipulator
from libcosimpy.CosimObserver import CosimObserver
from libcosimpy.CosimSlave import CosimLocalSlave

small_fmu, wire_fmu = sys.argv[1:3]
failures = []
log_output_level(CosimLogLevel.WARNING)


def vrs_of(path, names):
    md = read_model_description(path)
    by_name = {v.name: v.valueReference for v in md.modelVariables}
    return [by_name[n] for n in names]


def outputs_of(path):
    md = read_model_description(path)
    return [v.valueReference for v in md.modelVariables if v.causality == "output" and v.type == "Real"]


class FmpySlave:
    """fmpy's FMU2Slave with the calls a fixed-step master makes."""

    def __init__(self, path, name):
        md = read_model_description(path)
        self.fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(path),
                             modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)
        self.fmu.instantiate()
        self.fmu.setupExperiment(startTime=0.0)
        self.fmu.enterInitializationMode()
        self.fmu.exitInitializationMode()

    def free(self):
        self.fmu.terminate()
        self.fmu.freeInstance()


def compare(label, cosim, fmpy_rows):
    diffs = [(k, j) for k, (a, b) in enumerate(zip(cosim, fmpy_rows)) for j, (x, y) in enumerate(zip(a, b)) if x != y]
    n = sum(len(r) for r in cosim)
    if len(cosim) != len(fmpy_rows) or diffs:
        failures.append(f"{label}: libcosim and fmpy differ: {len(cosim)} vs {len(fmpy_rows)} rows, first differences {diffs[:3]}")
    print(f"{label}: libcosim vs fmpy: {len(cosim)} steps x {len(cosim[0])} outputs, {n} values, "
          f"{'identical bits' if not diffs and len(cosim) == len(fmpy_rows) else 'DIFFERENT'}")


def single(label, path, h, steps, change_at, input_name, value):
    """1. One FMU; the input changes through the override manipulator."""
    outs = outputs_of(path)
    [vr_in] = vrs_of(path, [input_name])
    ns = round(h * 1e9)
    ex = CosimExecution.from_step_size(ns)
    idx = ex.add_local_slave(CosimLocalSlave(fmu_path=path, instance_name="a"))
    obs = CosimObserver.create_last_value()
    ex.add_observer(obs)
    manip = CosimManipulator.create_override()
    ex.add_manipulator(manip)
    cosim = []
    for k in range(steps):
        if k == change_at:
            manip.slave_real_values(idx, [vr_in], [value])
        assert ex.step(), f"{label}: libcosim step {k} failed"
        cosim.append(obs.last_real_values(idx, outs))

    s = FmpySlave(path, "a")
    rows, t = [], 0.0
    for k in range(steps):
        if k == change_at:
            s.fmu.setReal([vr_in], [value])
        s.fmu.doStep(t, h)
        t += h
        rows.append(s.fmu.getReal(outs))
    s.free()
    compare(f"{label}: {input_name} = {value} from step {change_at} (override manipulator)", cosim, rows)


def connected(label, path_a, out_name, path_b, in_name, h, steps):
    """2. A's output feeds B's input."""
    outs_a, outs_b = outputs_of(path_a), outputs_of(path_b)
    [vr_out] = vrs_of(path_a, [out_name])
    [vr_in] = vrs_of(path_b, [in_name])
    ex = CosimExecution.from_step_size(round(h * 1e9))
    a = ex.add_local_slave(CosimLocalSlave(fmu_path=path_a, instance_name="a"))
    b = ex.add_local_slave(CosimLocalSlave(fmu_path=path_b, instance_name="b"))
    # libcosim's C functions return 0 on success.
    assert ex.connect_real_variables(a, vr_out, b, vr_in) == 0, f"{label}: connect failed"
    obs = CosimObserver.create_last_value()
    ex.add_observer(obs)
    cosim = []
    for k in range(steps):
        assert ex.step(), f"{label}: libcosim step {k} failed"
        cosim.append(obs.last_real_values(a, outs_a) + obs.last_real_values(b, outs_b))

    sa, sb = FmpySlave(path_a, "a"), FmpySlave(path_b, "b")
    rows, t = [], 0.0
    for k in range(steps):
        sb.fmu.setReal([vr_in], sa.fmu.getReal([vr_out]))
        sa.fmu.doStep(t, h)
        sb.fmu.doStep(t, h)
        t += h
        rows.append(sa.fmu.getReal(outs_a) + sb.fmu.getReal(outs_b))
    sa.free()
    sb.free()
    # The connection matters: B alone gives other outputs.
    alone, t = FmpySlave(path_b, "alone"), 0.0
    for k in range(steps):
        alone.fmu.doStep(t, h)
        t += h
    last_alone = alone.fmu.getReal(outs_b)
    alone.free()
    if last_alone == rows[-1][len(outs_a):]:
        failures.append(f"{label}: B's outputs do not depend on the connection")
    compare(f"{label}: {out_name} -> {in_name}", cosim, rows)


single("MassSpring (wire)", wire_fmu, 0.05, 20, 10, "gravity.x", 4.0)
single("YarnBundle (small)", small_fmu, 0.01, 20, 10, "gravity.x", 3.0)
connected("wire -> wire", wire_fmu, "particle[10].x", wire_fmu, "gravity.x", 0.05, 20)
connected("wire -> yarn-small", wire_fmu, "particle[10].x", small_fmu, "gravity.x", 0.01, 20)

if failures:
    print("libcosim check FAILED:")
    for f in failures:
        print("  " + f)
    sys.exit(1)
print("libcosim check passed")
