"""The sweep file: parsing, checks against the FMU's modelDescription, points.

Every error is a SweepError whose message names the field (as a TOML path,
for example `parameters."dt".num`) and what was expected.
"""
import hashlib
import itertools
import json
import math
import os
import tomllib

import numpy as np

from .task import REDUCTIONS

DESIGNS = ("factorial", "lhs")
TOP_KEYS = {"fmu", "start_time", "stop_time", "output_interval", "point_timeout", "design", "samples", "seed",
            "fixed", "parameters", "inputs", "signals", "outputs", "plot"}


class SweepError(Exception):
    """A bad sweep file, FMU or option; the message names the field."""


def q(name):
    return f'"{name}"' if any(c in name for c in '.[] "') else name


def _num(value, field, positive=False, allow_zero=True):
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise SweepError(f"{field}: expected a finite number, got {value!r}")
    if positive and (value < 0 or (value == 0 and not allow_zero)):
        raise SweepError(f"{field}: expected a number {'>= 0' if allow_zero else '> 0'}, got {value!r}")
    return float(value)


class Sweep:
    """A parsed, checked sweep: `points` is the list of (key, {name: value})."""

    def __init__(self, path, fmu_override=None):
        self.path = os.path.abspath(path)
        if not os.path.isfile(self.path):
            raise SweepError(f"sweep file {path}: no such file")
        try:
            with open(self.path, "rb") as fh:
                data = tomllib.load(fh)
        except tomllib.TOMLDecodeError as exc:
            raise SweepError(f"sweep file {path}: not valid TOML: {exc}") from None
        self.data = data
        unknown = sorted(set(data) - TOP_KEYS)
        if unknown:
            raise SweepError(f"{unknown[0]}: unknown key in the sweep file (expected one of {', '.join(sorted(TOP_KEYS))})")
        base = os.path.dirname(self.path)
        fmu = fmu_override or data.get("fmu")
        if not fmu:
            raise SweepError("fmu: missing: the path of the FMU to sweep (relative to the sweep file)")
        if not isinstance(fmu, str):
            raise SweepError(f"fmu: expected a path, got {fmu!r}")
        self.fmu = fmu if os.path.isabs(fmu) or fmu_override else os.path.normpath(os.path.join(base, fmu))
        if not os.path.isfile(self.fmu):
            raise SweepError(f"fmu: {self.fmu}: no such file (build it with build-fmu, see the README)")
        from fmpy import read_model_description

        try:
            self.md = read_model_description(self.fmu)
        except Exception as exc:
            raise SweepError(f"fmu: {self.fmu}: not a readable FMU: {exc}") from None
        if self.md.coSimulation is None:
            raise SweepError(f"fmu: {self.fmu}: not a Co-Simulation FMU")
        self.vars = {v.name: v for v in self.md.modelVariables}
        exp = self.md.defaultExperiment
        self.start_time = _num(data.get("start_time", 0.0), "start_time")
        stop = data.get("stop_time", exp.stopTime if exp is not None and exp.stopTime is not None else None)
        if stop is None:
            raise SweepError("stop_time: missing (the FMU has no DefaultExperiment stopTime)")
        self.stop_time = _num(float(stop), "stop_time")
        if self.stop_time <= self.start_time:
            raise SweepError(f"stop_time: expected > start_time {self.start_time}, got {self.stop_time}")
        h = data.get("output_interval", exp.stepSize if exp is not None and exp.stepSize is not None else None)
        if h is None:
            raise SweepError("output_interval: missing (the FMU has no DefaultExperiment stepSize)")
        self.output_interval = _num(float(h), "output_interval", positive=True, allow_zero=False)
        pt = data.get("point_timeout")
        self.point_timeout = None if pt is None else _num(pt, "point_timeout", positive=True, allow_zero=False)
        self.design = data.get("design", "factorial")
        if self.design not in DESIGNS:
            raise SweepError(f"design: expected one of {', '.join(DESIGNS)}, got {self.design!r}")

        self.fixed = {}
        for name, value in self._table("fixed").items():
            self._check_var(name, ("parameter", "input"), f"fixed.{q(name)}")
            self.fixed[name] = self._check_value(name, value, f"fixed.{q(name)}")
        self.varied = {}  # name -> list of values, or (min, max) for lhs
        for section, causalities in (("parameters", ("parameter",)), ("inputs", ("input",))):
            for name, spec in self._table(section).items():
                field = f"{section}.{q(name)}"
                self._check_var(name, causalities, field)
                if name in self.varied or name in self.fixed:
                    raise SweepError(f"{field}: {name} is set twice (fixed, parameters or inputs)")
                self.varied[name] = self._levels(name, spec, field)
        self.signals = self._signals()
        self.outputs = self._outputs()
        self.plot = self._table("plot")
        # the FMU's `threads` parameter (if any): one thread per instance
        threads = self.vars.get("threads")
        if threads is not None and threads.causality == "parameter" and "threads" not in self.varied and "threads" not in self.fixed:
            self.fixed["threads"] = 1
        self.points = self._points()
        if not self.points:
            raise SweepError("parameters/inputs: the sweep is empty (no points to run)")
        self._check_plot()

    # -- helpers -----------------------------------------------------------
    def _table(self, key):
        value = self.data.get(key, {})
        if not isinstance(value, dict):
            raise SweepError(f"{key}: expected a table, got {value!r}")
        return value

    def _check_var(self, name, causalities, field):
        var = self.vars.get(name)
        if var is None:
            kind = " or ".join(causalities)
            names = sorted(v.name for v in self.md.modelVariables if v.causality in causalities)
            raise SweepError(f"{field}: the FMU has no {kind} named {name!r} (its {kind}s: {', '.join(names) or 'none'})")
        if var.causality not in causalities:
            raise SweepError(f"{field}: {name!r} is a{'n' if var.causality[0] in 'aeiou' else ''} {var.causality}, expected {' or '.join(causalities)}")
        return var

    def _check_value(self, name, value, field):
        var = self.vars[name]
        t = var.type
        if t == "Real":
            v = _num(value, field)
        elif t in ("Integer", "Enumeration"):
            if isinstance(value, bool) or not isinstance(value, int):
                raise SweepError(f"{field}: {name} is an {t}, expected an integer, got {value!r}")
            v = value
        elif t == "Boolean":
            if not isinstance(value, bool):
                raise SweepError(f"{field}: {name} is a Boolean, expected true or false, got {value!r}")
            v = value
        elif t == "String":
            if not isinstance(value, str):
                raise SweepError(f"{field}: {name} is a String, expected a string, got {value!r}")
            v = value
        else:
            raise SweepError(f"{field}: {name} has type {t}, which the sweep cannot set")
        lo = getattr(var, "min", None)
        hi = getattr(var, "max", None)
        if t in ("Real", "Integer") and lo is not None and v < float(lo):
            raise SweepError(f"{field}: {v!r} is below the minimum {lo} of {name}")
        if t in ("Real", "Integer") and hi is not None and v > float(hi):
            raise SweepError(f"{field}: {v!r} is above the maximum {hi} of {name}")
        return v

    def _levels(self, name, spec, field):
        var = self.vars[name]
        if isinstance(spec, list):
            if not spec:
                raise SweepError(f"{field}: empty list of values")
            return [self._check_value(name, v, f"{field}[{k}]") for k, v in enumerate(spec)]
        if not isinstance(spec, dict):
            raise SweepError(f"{field}: expected a list of values or a range table "
                             "{ start, stop, num } / { start, stop, step } / { min, max } (lhs)")
        keys = set(spec)
        if var.type not in ("Real", "Integer"):
            raise SweepError(f"{field}: {name} is a {var.type}: give a list of values, not a range")
        if keys == {"min", "max"}:
            if self.design != "lhs":
                raise SweepError(f"{field}: a {{ min, max }} range needs design = \"lhs\"; with design = \"factorial\" give {{ start, stop, num }} or a list")
            lo = self._check_value(name, spec["min"], f"{field}.min")
            hi = self._check_value(name, spec["max"], f"{field}.max")
            if not hi > lo:
                raise SweepError(f"{field}: expected min < max, got {lo} and {hi}")
            return (lo, hi)
        if keys == {"start", "stop", "num"}:
            num = spec["num"]
            if isinstance(num, bool) or not isinstance(num, int) or num < 1:
                raise SweepError(f"{field}.num: expected an integer >= 1, got {num!r}")
            start = _num(spec["start"], f"{field}.start")
            stop = _num(spec["stop"], f"{field}.stop")
            values = np.linspace(start, stop, num).tolist()
        elif keys == {"start", "stop", "step"}:
            start = _num(spec["start"], f"{field}.start")
            stop = _num(spec["stop"], f"{field}.stop")
            step = _num(spec["step"], f"{field}.step")
            if step == 0 or (stop - start) / step < 0:
                raise SweepError(f"{field}.step: {step} does not lead from {start} to {stop}")
            n = int(math.floor((stop - start) / step * (1 + 1e-12) + 1e-9)) + 1
            values = [start + k * step for k in range(n)]
        else:
            raise SweepError(f"{field}: unknown range keys {sorted(keys)}; expected {{ start, stop, num }}, {{ start, stop, step }} or {{ min, max }} (lhs)")
        if var.type == "Integer":
            values = [int(round(v)) for v in values]
        return [self._check_value(name, v, f"{field}") for v in values]

    def _signals(self):
        table = self._table("signals")
        if not table:
            return None
        if "time" not in table:
            raise SweepError("signals.time: missing: the time column of the input table")
        cols = {}
        n = None
        for name, col in table.items():
            field = f"signals.{q(name)}"
            if not isinstance(col, list) or not col:
                raise SweepError(f"{field}: expected a non-empty list of values")
            if n is None:
                n = len(col)
            elif len(col) != n:
                raise SweepError(f"{field}: {len(col)} values, expected {n} like signals.time")
            if name == "time":
                t = [_num(v, f"{field}[{k}]") for k, v in enumerate(col)]
                if any(b < a for a, b in zip(t, t[1:])):
                    raise SweepError(f"{field}: times must not decrease")
                cols[name] = t
                continue
            self._check_var(name, ("input",), field)
            if name in self.varied or name in self.fixed:
                raise SweepError(f"{field}: {name} is also swept or fixed; an input is either a signal or a value")
            cols[name] = [self._check_value(name, v, f"{field}[{k}]") for k, v in enumerate(col)]
        names = ["time"] + [k for k in cols if k != "time"]
        dtypes = []
        for name in names:
            t = "Real" if name == "time" else self.vars[name].type
            dtypes.append({"Real": "f8", "Boolean": "?", "Integer": "i4", "Enumeration": "i4"}.get(t, "f8"))
        return (names, dtypes, [cols[k] for k in names])

    def _outputs(self):
        table = self._table("outputs")
        if not table:
            raise SweepError("outputs: missing: name at least one variable to keep, e.g. outputs = { total_energy = [\"final\"] }")
        outputs = []
        for name, reds in table.items():
            field = f"outputs.{q(name)}"
            var = self.vars.get(name)
            if var is None:
                outs = sorted(v.name for v in self.md.modelVariables if v.causality == "output")
                raise SweepError(f"{field}: the FMU has no variable named {name!r} (its outputs: {', '.join(outs[:12])}{', ...' if len(outs) > 12 else ''})")
            if var.type not in ("Real", "Integer", "Boolean", "Enumeration"):
                raise SweepError(f"{field}: {name} is a {var.type}; only numbers can be reduced")
            if isinstance(reds, str):
                reds = [reds]
            if not isinstance(reds, list) or not reds:
                raise SweepError(f"{field}: expected a list of reductions out of {', '.join(REDUCTIONS)}")
            for r in reds:
                if r not in REDUCTIONS:
                    raise SweepError(f"{field}: unknown reduction {r!r}; expected one of {', '.join(REDUCTIONS)}")
            outputs.append((name, list(dict.fromkeys(reds))))
        return outputs

    def _points(self):
        names = list(self.varied)
        if self.design == "factorial":
            combos = itertools.product(*[self.varied[n] for n in names])
            rows = [dict(zip(names, c)) for c in combos]
        else:
            samples = self.data.get("samples")
            if isinstance(samples, bool) or not isinstance(samples, int) or samples < 1:
                raise SweepError(f"samples: design = \"lhs\" needs an integer number of samples >= 1, got {samples!r}")
            seed = self.data.get("seed", 0)
            if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
                raise SweepError(f"seed: expected an integer >= 0, got {seed!r}")
            rng = np.random.default_rng(seed)
            cols = {}
            for n in names:
                u = (rng.permutation(samples) + rng.random(samples)) / samples
                lv = self.varied[n]
                if isinstance(lv, tuple):
                    lo, hi = lv
                    vals = lo + u * (hi - lo)
                    if self.vars[n].type == "Integer":
                        cols[n] = [int(round(v)) for v in vals]
                    else:
                        cols[n] = [float(v) for v in vals]
                else:
                    cols[n] = [lv[min(int(x * len(lv)), len(lv) - 1)] for x in u]
            rows = [{n: cols[n][k] for n in names} for k in range(samples)]
        if not names:
            return []
        base = self.run_config()
        base_json = json.dumps({k: v for k, v in base.items() if k != "record"}, sort_keys=True, default=str)
        out = []
        for k, values in enumerate(rows):
            h = hashlib.sha1((base_json + json.dumps(values, sort_keys=True)).encode()).hexdigest()[:16]
            out.append((h, values))
        return out

    def _check_plot(self):
        p = self.plot
        if not p:
            return
        allowed = {"value", "x", "y", "file", "title", "log_value"}
        for key in p:
            if key not in allowed:
                raise SweepError(f"plot.{key}: unknown key (expected one of {', '.join(sorted(allowed))})")
        cols = [f"{n}:{r}" for n, reds in self.outputs for r in reds if r != "series"]
        value = p.get("value")
        if value not in cols:
            raise SweepError(f"plot.value: expected one of the kept reductions {', '.join(cols)}, got {value!r}")
        for key in ("x", "y"):
            if key in p and p[key] not in self.varied:
                raise SweepError(f"plot.{key}: expected one of the varied names {', '.join(self.varied)}, got {p[key]!r}")
        if "x" not in p:
            raise SweepError("plot.x: missing: the varied parameter or input on the x axis")
        f = p.get("file", "plot.png")
        if not str(f).endswith((".png", ".svg")):
            raise SweepError(f"plot.file: expected a .png or .svg name, got {f!r}")

    def run_config(self):
        """What every task needs besides the point's values (picklable)."""
        record = [n for n, _ in self.outputs]
        return {
            "start_time": self.start_time,
            "stop_time": self.stop_time,
            "output_interval": self.output_interval,
            "point_timeout": self.point_timeout,
            "fixed": dict(self.fixed),
            "signals": self.signals,
            "record": record,
            "outputs": self.outputs,
        }

    def preflight(self):
        """Sets every value the sweep will use on one instance of the FMU
        before anything is submitted: values the FMU refuses (out of range,
        unknown strings) become a SweepError naming the field."""
        from fmpy import extract
        from fmpy.simulation import instantiate_fmu

        setters = {"Real": "setReal", "Integer": "setInteger", "Enumeration": "setInteger", "Boolean": "setBoolean", "String": "setString"}
        log = []

        def logger(env, inst, status, cat, msg):
            log.append(msg.decode("utf-8", "replace") if isinstance(msg, bytes) else str(msg))

        unzipdir = extract(self.fmu)
        fmu = instantiate_fmu(unzipdir, self.md, "CoSimulation", logger=logger)
        try:
            checks = [(f"fixed.{q(n)}", n, [v]) for n, v in self.fixed.items()]
            section = {v.name: ("parameters" if v.causality == "parameter" else "inputs") for v in self.md.modelVariables}
            for n, lv in self.varied.items():
                vals = list(lv) if not isinstance(lv, tuple) else list(lv)
                checks.append((f"{section[n]}.{q(n)}", n, sorted(set(vals), key=repr)))
            if self.signals:
                names, _, cols = self.signals
                for n, col in zip(names[1:], cols[1:]):
                    checks.append((f"signals.{q(n)}", n, sorted(set(col), key=repr)))
            for field, n, values in checks:
                var = self.vars[n]
                for v in values:
                    log.clear()
                    try:
                        getattr(fmu, setters[var.type])([var.valueReference], [v])
                    except Exception:
                        msg = log[-1] if log else "refused by the FMU"
                        raise SweepError(f"{field}: the FMU refuses {n} = {v!r}: {msg}") from None
        finally:
            try:
                fmu.freeInstance()
            except Exception:
                pass
            import shutil

            shutil.rmtree(unzipdir, ignore_errors=True)
