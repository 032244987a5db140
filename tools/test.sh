#!/usr/bin/env bash
# The whole test suite: the documentation's links, every Rust test of the
# workspace in release mode (heavy physics tests run only there), then the FMU
# checks through fmpy.
set -euo pipefail
cd "$(dirname "$0")/.."
# the documentation's relative links and anchors (cheap, so first), and the
# link checker's own tests
python3 tools/check_links.py --self-test
python3 tools/check_links.py
cargo test --workspace --release
if [ -f tools/fmu_check.sh ]; then
    bash tools/fmu_check.sh
fi
# parameter sweeps of the FMUs on Dask (tools/sweep, pytest on 2-worker LocalClusters)
if [ -f tools/sweep_check.sh ]; then
    bash tools/sweep_check.sh
fi
