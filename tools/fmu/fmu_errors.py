"""The documented fmpy recipes for refused inputs and diverged steps, run as
they stand in the docs (run by tools/fmu/fmu_check.sh).

usage: fmu_errors.py SMALL.fmu SMALL-fmi3.fmu

1. docs/fmu-masters.md, "A rejected input: the error state and a state restore":
   the controller loop that saves the FMU state before setting its inputs
   and restores it when one is refused. Checks: exactly one input refused,
   and the outputs at the end bit for bit those of a run that got the safe
   value in the first place (an FMU2Slave loop written here).
2. docs/fmu-masters.md, "fmpy's simulate_fmu after a Discard": simulate_fmu of a
   run that diverges at 0.11 s returns a result cut there, without raising.
3. docs/fmu3.md, "A rejected input and a Discard": the FMI 3.0 loop (same
   checks as 1) and fmpy 0.3.32's simulate_fmu of an FMI 3.0 FMU raising
   on the Discard.
Exits non-zero on any problem.
"""
import math
import pathlib
import re
import sys

from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

from fmu_inputs import finish

small_fmu, small_fmu3 = sys.argv[1:3]
root = pathlib.Path(__file__).resolve().parents[2]
failures = []


def block(doc, heading):
    """The first ```python block after the line `heading` of docs/`doc`."""
    text = (root / "docs" / doc).read_text()
    at = text.index("\n" + heading + "\n")
    match = re.compile(r"```python\n(.*?)```", re.S).search(text, at)
    return match.group(1)


def run_block(doc, heading, fmu, default_path):
    """Executes the block with `fmu` in place of the path the doc names;
    returns its variables."""
    code = block(doc, heading)
    if default_path not in code:
        failures.append(f"{doc}, {heading}: the block does not name {default_path}")
    scope = {}
    exec(compile(code.replace(default_path, fmu), f"{doc}: {heading}", "exec"), scope)
    return scope


def reference_fmi2(fmu, steps, h, safe_at):
    """The doc's loop without the bad value: attractor.x 0.5 at step `safe_at`."""
    md = read_model_description(fmu)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    slave = FMU2Slave(guid=md.guid, unzipDirectory=extract(fmu),
                      modelIdentifier=md.coSimulation.modelIdentifier, instanceName="reference")
    slave.instantiate()
    slave.setupExperiment(startTime=0.0)
    slave.enterInitializationMode()
    slave.exitInitializationMode()
    t = 0.0
    for k in range(steps):
        x = 0.5 if k == safe_at else 0.5 + 0.2 * math.cos(4 * t)
        slave.setReal([vr["attractor.x"]], [x])
        slave.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        t += h
    out = slave.getReal([vr["yarn[0].left.x"], vr["kinetic_energy"]])
    slave.terminate()
    slave.freeInstance()
    return out


def check_loop(label, scope, reference):
    refused, final = scope["refused"], list(scope["final"])
    if len(refused) != 1 or not math.isclose(refused[0], 0.05):
        failures.append(f"{label}: refused at {refused}, expected once at t = 0.05")
    same = [a.hex() for a in final] == [b.hex() for b in reference]
    print(f"{label}: refused at t = {refused}; outputs at t = 0.2 {final}, "
          f"{'bit-identical to' if same else 'DIFFERENT from'} the undisturbed run {reference}")
    if not same:
        failures.append(f"{label}: outputs after the restore differ from the undisturbed run")


# 1. the FMI 2.0 controller loop of docs/fmu-masters.md
FMU_PATH = "target/fmu/YarnBundle-small.fmu"
scope = run_block("fmu-masters.md", "### A rejected input: the error state and a state restore", small_fmu, FMU_PATH)
check_loop("FMI 2.0 controller loop (docs/fmu-masters.md)", scope, reference_fmi2(small_fmu, 20, 0.01, 5))

# 2. simulate_fmu after a Discard, FMI 2.0
scope = run_block("fmu-masters.md", "### fmpy's `simulate_fmu` after a Discard", small_fmu, FMU_PATH)
result, stop, last = scope["result"], scope["stop"], scope["last"]
print(f"FMI 2.0 simulate_fmu with a Discard: no exception, {len(result)} rows, last time {last} of {stop}")
if not (last < stop and math.isclose(last, 0.11)):
    failures.append(f"simulate_fmu after a Discard: last time {last}, expected 0.11 < {stop}")

# 3. the FMI 3.0 loop and simulate_fmu of docs/fmu3.md
FMU3_PATH = "target/fmu/YarnBundle-small-fmi3.fmu"
scope = run_block("fmu3.md", "## A rejected input and a Discard", small_fmu3, FMU3_PATH)
check_loop("FMI 3.0 controller loop (docs/fmu3.md)", scope, reference_fmi2(small_fmu, 20, 0.01, 5))
raised = scope["raised"]
print(f"FMI 3.0 simulate_fmu with a Discard: raised {raised!r}")
if raised is None or "fmi3DoStep failed with status 2" not in raised:
    failures.append(f"FMI 3.0 simulate_fmu after a Discard: expected fmpy to raise, got {raised!r}")

finish("FMU error-state check", failures)
