#!/usr/bin/env bash
# yarnsim bench against the reference Taichi implementation of Jiang et al. 2017, alternating
# (tools/bench/taichi_bench.py; see "Against the reference Taichi implementation"
# in docs/performance/throughput.md).
# Usage: tools/bench/taichi_bench.sh REFERENCE_FILE [--yarnsim BIN] [--threads 1,2] [--rounds 3] ...
# Installs Taichi 1.7.4 into tools/bench/.venv-taichi on first use. Does not build
# yarnsim: it uses target/release/yarnsim unless --yarnsim is given.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
venv=$here/.venv-taichi
if ! "$venv/bin/python" -c 'import importlib.metadata as m; assert m.version("taichi") == "1.7.4"' 2>/dev/null; then
    python3 -m venv "$venv"
    "$venv/bin/pip" install --quiet taichi==1.7.4
fi
exec "$venv/bin/python" "$here/taichi_bench.py" "$@"
