"""Input tables shared by the fmpy checks (tools/fmu_check.py, tools/fmu3_check.py)."""
import math

import numpy as np


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
