#!/usr/bin/env bash
# The FMU checks through fmpy 0.3.32 (installed into tools/.venv):
# builds the default FMU (target/fmu/YarnBundle.fmu), the small test
# scene's FMU and the wire's MassSpring FMU, validates them with fmpy,
# simulates the small one and the wire (two integrators) with input signals
# and compares their outputs bit for bit with the Rust library run of the
# same inputs (fmu-replay), round-trips FMU states through fmpy, and runs
# the default FMU for two frames; then runs the small and the wire FMUs in
# libcosimpy 0.0.6 (the Open Simulation Platform's libcosim: an input
# changed through its override manipulator, two FMUs connected output ->
# input) and compares them bit for bit with fmpy; then builds the FMI 3.0
# FMUs of the small, default, wire and driven scenes (build-fmu --fmi-version 3) and
# checks them in fmpy against the FMI 2.0 FMUs and the library
# (tools/fmu/fmu3_check.py); then runs the documented recipes for a refused
# input (save the FMU state, restore it after the refusal) and for a
# diverged step in simulate_fmu, as they stand in docs/fmu-masters.md and
# docs/fmu3.md (tools/fmu/fmu_errors.py). Exits non-zero on failure.
set -euo pipefail
cd "$(dirname "$0")/../.."
venv=tools/.venv
if ! "$venv/bin/python" -c 'import fmpy; assert fmpy.__version__ == "0.3.32"' 2>/dev/null; then
    python3 -m venv "$venv"
    "$venv/bin/pip" install --quiet fmpy==0.3.32
fi
if ! "$venv/bin/python" -c 'import importlib.metadata as m; assert m.version("libcosimpy") == "0.0.6"' 2>/dev/null; then
    "$venv/bin/pip" install --quiet libcosimpy==0.0.6
fi
cargo build --release -p yarnsim-fmu -p yarnsim-fmu-pack --bins --lib
target=$(cargo metadata --format-version 1 --no-deps | "$venv/bin/python" -c 'import json,sys; print(json.load(sys.stdin)["target_directory"])')
"$target/release/build-fmu" --no-build
"$target/release/build-fmu" --no-build --scene fmu/scenes/small.toml -o "$target/fmu/YarnBundle-small.fmu"
"$target/release/build-fmu" --no-build --scene wire
"$target/release/build-fmu" --no-build --scene fmu/scenes/driven.toml -o "$target/fmu/YarnBundle-driven.fmu"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$venv/bin/python" tools/fmu/fmu_check.py "$target/fmu/YarnBundle-small.fmu" "$target/fmu/YarnBundle.fmu" \
    "$work" "$target/release/fmu-replay" fmu/scenes/small.toml "$target/fmu/MassSpring-wire.fmu" \
    "$target/fmu/YarnBundle-driven.fmu" fmu/scenes/driven.toml
"$venv/bin/python" tools/fmu/cosim_check.py "$target/fmu/YarnBundle-small.fmu" "$target/fmu/MassSpring-wire.fmu"
"$target/release/build-fmu" --no-build --fmi-version 3
"$target/release/build-fmu" --no-build --fmi-version 3 --scene fmu/scenes/small.toml -o "$target/fmu/YarnBundle-small-fmi3.fmu"
"$target/release/build-fmu" --no-build --fmi-version 3 --scene wire
"$target/release/build-fmu" --no-build --fmi-version 3 --scene fmu/scenes/driven.toml -o "$target/fmu/YarnBundle-driven-fmi3.fmu"
"$venv/bin/python" tools/fmu/fmu3_check.py "$work" "$target/release/fmu-replay" fmu/scenes/small.toml \
    "$target/fmu/YarnBundle-small-fmi3.fmu" "$target/fmu/YarnBundle-small.fmu" \
    "$target/fmu/YarnBundle-fmi3.fmu" "$target/fmu/YarnBundle.fmu" \
    "$target/fmu/MassSpring-wire-fmi3.fmu" "$target/fmu/MassSpring-wire.fmu" \
    "$target/fmu/YarnBundle-driven-fmi3.fmu" "$target/fmu/YarnBundle-driven.fmu"
"$venv/bin/python" tools/fmu/fmu_errors.py "$target/fmu/YarnBundle-small.fmu" "$target/fmu/YarnBundle-small-fmi3.fmu"
