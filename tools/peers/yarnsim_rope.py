"""yarnsim entry: the oracle scenes of `tests/yarn_oracles.rs` through the
release example `examples/peers_chain.rs` (one JSON line per run; it times
the stepping loop only), one thread (RAYON_NUM_THREADS=1)."""

import json
import os
import subprocess

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
BIN = os.path.join(ROOT, "target", "release", "examples", "peers_chain")


def build():
    subprocess.run(["cargo", "build", "--release", "--example", "peers_chain"], cwd=ROOT,
                   check=True)


def _run(*args):
    env = dict(os.environ, RAYON_NUM_THREADS="1")
    out = subprocess.run([BIN, *map(str, args)], env=env, check=True, capture_output=True,
                         text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def chain(vertices, grid, dt):
    r = _run("chain", vertices, grid, dt)
    r["sim_s"] = r["sim_s"]
    return r


def cantilever(vertices):
    return _run("cantilever", vertices)


def capstan_slides(r, l1, l2, mu):
    res = _run("capstan", r, l1, l2, mu)
    return res["slid"] or not res["ok"], res["wall_s"], res["sim_s"]


def bundle(duration):
    import numpy as np
    res = _run("bundle", duration)
    res["yarns"] = [np.array(y) for y in res["yarns"]]
    return res
