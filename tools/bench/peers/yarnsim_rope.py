"""yarnsim entry: the oracle scenes of `tests/yarn_oracles.rs` through the
release example `evidence/examples/peers_chain.rs` (one JSON line per run; it times
the stepping loop only), one thread (RAYON_NUM_THREADS=1), under the
explicit or the implicit integrator (`[time] integrator`); a scene the
implicit integrator refuses comes back as `ok` false with the refusal in
`note`."""

import json
import os
import subprocess

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
BIN = os.path.join(ROOT, "target", "release", "examples", "peers_chain")
# the CLI, whose `yarnsim materials` gives the presets (`oracles.preset`)
CLI = os.path.join(ROOT, "target", "release", "yarnsim")


def build():
    """The example and the CLI, as `setup.sh` builds them."""
    subprocess.run(["cargo", "build", "--workspace", "--release", "--example", "peers_chain",
                    "--bin", "yarnsim"], cwd=ROOT, check=True)


def _run(*args, threads=1):
    env = dict(os.environ, RAYON_NUM_THREADS=str(threads))
    out = subprocess.run([BIN, *map(str, args)], env=env, check=True, capture_output=True,
                         text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def _refused(res):
    """A run the scene validation refused (the implicit integrator outside
    its scope): the timed-case fields as NaN, `ok` false, the refusal text
    in `note`."""
    if "refused" not in res:
        return res
    nan = float("nan")
    return dict(ok=False, error=nan, wall_s=nan, sim_s=nan, note=res["refused"],
                refused=res["refused"])


def _opt(*args):
    """The trailing optional arguments up to the last one given."""
    args = list(args)
    while args and args[-1] is None:
        args.pop()
    return args


def chain(vertices, grid, dt, integrator="explicit", k=None):
    """The hanging chain; `integrator` "explicit" or "implicit"; `k`
    replaces the fibre stiffness (2000)."""
    return _refused(_run("chain", vertices, grid, dt, *_opt(integrator, k)))


def chain_preset(preset, vertices, grid, dt, oracle, integrator=None):
    """The hanging chain as one yarn of `preset` (APIC, `[time] axial =
    "implicit"`; or, with `integrator` "implicit-vertices" or
    "midpoint-vertices", on its vertices without the grid): `error`
    against the period `oracle` (s)."""
    res = _refused(_run("chain-preset", preset, vertices, grid, dt, *_opt(integrator)))
    if "period" in res:
        res["error"] = (res["period"] - oracle) / oracle
    return res


def cantilever(vertices, integrator="explicit", dt=None):
    return _refused(_run("cantilever", vertices, *_opt(integrator, dt)))


def capstan(r, l1, l2, mu, integrator="explicit", dt=None):
    """One capstan run: the example's JSON (or the refusal, see `_refused`)."""
    return _refused(_run("capstan", r, l1, l2, mu, *_opt(integrator, dt)))


class Refused(Exception):
    """The scene validation refused the run (the message is its text)."""


def _slides(res):
    """(slid, wall_s, sim_s) of one capstan run's JSON (a run that failed
    counts as slid); raises `Refused` when the scene is refused."""
    if "refused" in res:
        raise Refused(res["refused"])
    return res.get("slid", False) or not res["ok"], res["wall_s"], res["sim_s"]


def capstan_slides(r, l1, l2, mu, integrator="explicit", dt=None):
    """(slid, wall_s, sim_s) of one capstan run (`_slides`)."""
    return _slides(capstan(r, l1, l2, mu, integrator, dt))


def bundle(duration, integrator="explicit", dt=None, threads=1, options=()):
    """The built-in `yarn-reference` for `duration` s; `dt` a number or
    "auto" (default: the scene's 4e-5); `windows` in the result: [start,
    end, wall] for the fall and landing (to 0.2 s), then the rest;
    `frames`: [time, yarns] every 0.1 s. `options`: the example's
    `preset=NAME`, `apic`, `per-yarn`, `axial-implicit` (they need `dt`)."""
    args = _opt(integrator, dt) if not options else [integrator, dt or "4e-5", *options]
    res = _refused(_run("bundle", duration, *args, threads=threads))
    if "yarns" in res:
        import numpy as np
        res["yarns"] = [np.array(y) for y in res["yarns"]]
        res["frames"] = [[t, [np.array(y) for y in ys]] for t, ys in res.get("frames", [])]
    return res


def capstan_preset_slides(preset, scale, mu, integrator, dt=None):
    """(slid, wall_s, sim_s) of the capstan as one yarn of `preset`, its
    lengths times `scale` (`oracles.capstan_scaled`), on the yarn's
    vertices (`integrator` "implicit-vertices" or "midpoint-vertices"; `_slides`)."""
    return _slides(_refused(_run("capstan-preset", preset, scale, mu, *_opt(integrator, dt))))
