#!/usr/bin/env bash
# Creates tools/bench/peers/.venv with the pinned peers of the rod benchmark
# (MuJoCo 4.0.0, PyElastica 1.0.0, numpy) and builds yarnsim's entry
# (evidence/examples/peers_chain.rs). Idempotent: does nothing when the pinned
# versions are installed (then it needs no network).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
venv=$here/.venv
want='import importlib.metadata as m
assert m.version("mujoco") == "4.0.0", "mujoco"
assert m.version("pyelastica") == "1.0.0", "pyelastica"
import numpy, mujoco, elastica'
if ! "$venv/bin/python" -c "$want" 2>/dev/null; then
    python3 -m venv "$venv"
    "$venv/bin/pip" install --quiet mujoco==4.0.0 pyelastica==1.0.0 numpy
    "$venv/bin/python" -c "$want"
fi
# the CLI gives the presets (`yarnsim materials`, oracles.preset); the
# example is yarnsim's side of every case
(cd "$here/../../.." && cargo build --workspace --release --example peers_chain --bin yarnsim)
echo "peers ready: $venv/bin/python $here/bench.py"
