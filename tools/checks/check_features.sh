#!/usr/bin/env bash
# One build for both README set-up commands: fails if `cargo run --release -p
# yarnsim-cli` (command 1) and `cargo test --workspace --release` (command 2,
# tools/test.sh) resolve a different feature set for any crate they share.
# Such a crate, and every crate above it (most of Rerun), would be compiled
# twice, once per command. Fix a divergence by naming the crate with the
# missing features in cli/Cargo.toml (section "Feature unification").
# The one exception is by design: the library `yarnsim` itself, whose
# `testing` feature (`yarnsim::testing`, the tests' helpers) the test build
# switches on and the CLI's release binary must not carry; this script fails
# if the CLI's yarnsim has it. Only the workspace's own crates (yarnsim,
# yarnsim-evidence, yarnsim-cli) are compiled again for that, no Rerun crate.
# Needs no build: `cargo tree` resolves features the way the build does.
set -euo pipefail
cd "$(dirname "$0")/../.."
resolve() {
    cargo tree --locked "$@" --format '{p} [{f}]' --prefix none | sed 's/ (\*)$//' | sort -u
}
cli=$(resolve -p yarnsim-cli --edges normal,build)
workspace=$(resolve --workspace --edges normal,build,dev)
lib=$(printf '%s\n' "$cli" | grep '^yarnsim v' || true)
if [ -z "$lib" ]; then
    echo "error: the CLI build has no yarnsim library" >&2
    exit 1
fi
if printf '%s\n' "$lib" | grep -q 'testing'; then
    echo "error: the CLI's release build compiles yarnsim::testing: $lib" >&2
    echo "(a crate the CLI depends on switches on yarnsim's 'testing' feature in [dependencies])" >&2
    exit 1
fi
echo "the CLI's yarnsim is built without 'testing': $lib"
diverging=$(comm -23 <(printf '%s\n' "$cli" | grep -v '^yarnsim v') <(printf '%s\n' "$workspace"))
if [ -n "$diverging" ]; then
    echo "error: these crates of 'cargo run -p yarnsim-cli' get other features in 'cargo test --workspace':" >&2
    printf '%s\n' "$diverging" | sed 's/^/  /' >&2
    echo "(features in the test build:)" >&2
    for name in $(printf '%s\n' "$diverging" | cut -d' ' -f1); do
        printf '%s\n' "$workspace" | grep "^$name " | sed 's/^/  /' >&2
    done
    exit 1
fi
echo "feature sets agree: $(printf '%s\n' "$cli" | wc -l) crates of the CLI build are resolved alike in the workspace test build"
