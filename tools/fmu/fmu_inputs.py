"""Input tables and helpers shared by the fmpy checks (tools/fmu/fmu_check.py, tools/fmu/fmu3_check.py)."""
import math
import sys

import numpy as np
from fmpy.validation import validate_fmu


def write_inputs(path, cols):
    """The input table as fmu-replay reads it."""
    with open(path, "w") as fh:
        fh.write(",".join(name for name, _ in cols) + "\n")
        for row in zip(*[c for _, c in cols]):
            fh.write(",".join(repr(float(v)) for v in row) + "\n")


def input_signals(path, cols):
    """The input columns `cols` as fmpy's structured array (booleans for
    attractor.active), also written to `path` for fmu-replay."""
    write_inputs(path, cols)
    dtype = [(name, np.bool_ if name == "attractor.active" else np.double) for name, _ in cols]
    return np.array(list(zip(*[c for _, c in cols])), dtype=dtype)


def time_grid(h, stop):
    """`(n, t)`: the n communication points 0, h, ..., stop."""
    n = int(round(stop / h)) + 1
    return n, np.array([k * h for k in range(n)])


def circling_attractor(h, stop):
    """The small yarn scene's input columns: the attractor on a circle (one
    turn in 0.4 s, switched on at 0.1 s), gravity turning."""
    n, t = time_grid(h, stop)
    w = 2 * math.pi * t / 0.4
    return [
        ("time", t),
        ("attractor.x", 0.5 + 0.2 * np.cos(w)),
        ("attractor.y", 0.5 + 0.2 * np.sin(w)),
        ("attractor.strength", np.full(n, 30.0)),
        ("attractor.active", t >= 0.1 - 1e-12),
        ("gravity.x", 4.0 * np.sin(3.0 * t)),
        ("gravity.y", -9.8 * np.cos(3.0 * t)),
    ]


def validate(path, failures):
    """fmpy's validation of the FMU at `path`; its problems become failures."""
    problems = validate_fmu(path)
    if problems:
        failures.append(f"{path}: fmpy validation: {problems}")
    print(f"validate {path}: {len(problems)} problems")


def state_round_trip(step, read, get, serialize, deserialize, set_state, h, steps=5):
    """The FMU-state round trip of either FMI version: `steps` steps, get +
    serialize at t1, `steps` steps on, deserialize + set, the same steps
    again. `step(t, h)` does one communication step, `read()` gives the
    outputs after it. Returns the serialized state, the outputs after t1
    the first and the second time, and the two states (to free)."""

    def run(t):
        out = []
        for _ in range(steps):
            step(t, h)
            t += h
            out.append(read())
        return t, out

    t1, _ = run(0.0)
    state = get()
    blob = serialize(state)
    _, first = run(t1)
    restored = deserialize(blob)
    set_state(restored)
    _, second = run(t1)
    return blob, first, second, (state, restored)


def finish(title, failures):
    """Prints the failures and exits non-zero if there are any, else says the check passed."""
    if failures:
        print(f"{title} FAILED ({len(failures)} problems):")
        for f in failures[:40]:
            print("  " + f)
        sys.exit(1)
    print(f"{title} passed")
