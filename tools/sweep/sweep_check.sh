#!/usr/bin/env bash
# The tests of tools/sweep (yarnsim-sweep, parameter sweeps on Dask): installs
# the tool with its pinned dependencies (dask and distributed 2026.8.0,
# pyarrow 26.0.1, pandas 3.1.1, matplotlib 3.11.2, pytest 9.2.0) into
# tools/.venv, packs the small YarnBundle FMU and the wire's MassSpring FMU
# (if tools/fmu/fmu_check.sh has not just done so) and runs pytest on 2-worker
# LocalClusters. Exits non-zero on failure (also when no test ran).
set -euo pipefail
cd "$(dirname "$0")/../.."
venv=tools/.venv
[ -x "$venv/bin/python" ] || python3 -m venv "$venv"
if ! "$venv/bin/python" - <<'PY' 2>/dev/null
import importlib.metadata as m, yarnsim_sweep
want = {"fmpy": "0.3.32", "dask": "2026.8.0", "distributed": "2026.8.0", "pyarrow": "26.0.1",
        "pandas": "3.1.1", "matplotlib": "3.11.2", "pytest": "9.2.0"}
assert all(m.version(k) == v for k, v in want.items())
PY
then
    "$venv/bin/pip" install --quiet -e "tools/sweep[test]"
fi
target=$(cargo metadata --format-version 1 --no-deps | "$venv/bin/python" -c 'import json,sys; print(json.load(sys.stdin)["target_directory"])')
if [ ! -f "$target/fmu/YarnBundle-small.fmu" ] || [ ! -f "$target/fmu/MassSpring-wire.fmu" ]; then
    cargo build --release -p yarnsim-fmu -p yarnsim-fmu-pack --bins --lib
    "$target/release/build-fmu" --no-build --scene fmu/scenes/small.toml -o "$target/fmu/YarnBundle-small.fmu"
    "$target/release/build-fmu" --no-build --scene wire
fi
cd tools/sweep
YARNSIM_FMU_DIR="$target/fmu" "../.venv/bin/python" -m pytest -q -p no:cacheprovider -p no:logging tests
