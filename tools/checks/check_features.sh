#!/usr/bin/env bash
# One build for both README set-up commands: fails if `cargo run --release -p
# yarnsim-cli` (command 1) and `cargo test --workspace --release` (command 2,
# tools/test.sh) resolve a different feature set for any crate they share.
# Such a crate, and every crate above it (most of Rerun), would be compiled
# twice, once per command. Fix a divergence by naming the crate with the
# missing features in cli/Cargo.toml (section "Feature unification").
# Needs no build: `cargo tree` resolves features the way the build does.
set -euo pipefail
cd "$(dirname "$0")/../.."
resolve() {
    cargo tree --locked "$@" --format '{p} [{f}]' --prefix none | sed 's/ (\*)$//' | sort -u
}
cli=$(resolve -p yarnsim-cli --edges normal,build)
workspace=$(resolve --workspace --edges normal,build,dev)
diverging=$(comm -23 <(printf '%s\n' "$cli") <(printf '%s\n' "$workspace"))
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
