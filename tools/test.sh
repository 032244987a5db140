#!/usr/bin/env bash
# The whole test suite: the documentation's links, the module graph, every Rust test of the
# workspace in release mode (heavy physics tests run only there), then the FMU
# checks through fmpy.
set -euo pipefail
cd "$(dirname "$0")/.."
# the documentation's relative links and anchors (cheap, so first), and the
# link checker's own tests
python3 tools/checks/check_links.py --self-test
python3 tools/checks/check_links.py
# no import circle between the modules of any folder of any crate
python3 tools/checks/check_modules.py --self-test
python3 tools/checks/check_modules.py
cargo test --workspace --release
if [ -f tools/fmu/fmu_check.sh ]; then
    bash tools/fmu/fmu_check.sh
fi
# parameter sweeps of the FMUs on Dask (tools/sweep, pytest on 2-worker LocalClusters)
if [ -f tools/sweep/sweep_check.sh ]; then
    bash tools/sweep/sweep_check.sh
fi
