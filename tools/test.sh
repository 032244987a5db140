#!/usr/bin/env bash
# The whole test suite: every Rust test of the workspace in release mode
# (heavy physics tests run only there), then the FMU checks through fmpy.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo test --workspace --release
if [ -f tools/fmu_check.sh ]; then
    bash tools/fmu_check.sh
fi
# parameter sweeps of the FMUs on Dask (tools/sweep, pytest on 2-worker LocalClusters)
if [ -f tools/sweep_check.sh ]; then
    bash tools/sweep_check.sh
fi
