#!/usr/bin/env bash
# A second, independent co-simulation master for the FMUs: `fmusim` from the
# Modelica Association's Reference-FMUs at commit c8d4e6d (the last one that
# has it; it was removed on 2026-07-09), built here without CMake from that
# commit's own sources, then run on each FMU beside fmpy
# (tools/fmu/fmusim_check.py compares every output of every row).
#
# usage: tools/fmu/fmusim.sh [--reference-fmus DIR] [FMU ...]
#   DIR   a local clone of https://github.com/modelica/Reference-FMUs that
#         holds c8d4e6d (default: $REFERENCE_FMUS, else a fresh clone into
#         target/fmusim/Reference-FMUs, which needs the network)
#   FMU   the FMUs to run (default: the small yarn scene's and the wire's
#         FMI 2.0 FMUs, and their FMI 3.0 builds where build-fmu can make
#         them); they are built first when they are the defaults
#
# What differs from upstream's CMake build (fmusim/CMakeLists.txt), and why:
# - libraries from Debian 12 instead of the ones build/build_*.py downloads:
#   libxml2 2.9.14 (libxml2-dev), minizip (libminizip-dev, the same
#   contrib/minizip code as zlib 1.3.1's) and SUNDIALS 6.4.1 CVODE (runtime
#   packages; the headers are unpacked from libsundials-dev, whose
#   dependencies - MPI, PETSc, HDF5 - cannot be installed here);
# - `-DSUN_COMM_NULL=NULL`: SUNDIALS 6 takes a plain null communicator where
#   SUNDIALS 7 has SUN_COMM_NULL (used once, in FMICVode.c; CVODE serves
#   only Model Exchange, which these FMUs do not have);
# - no source file is changed.
set -euo pipefail
cd "$(dirname "$0")/../.."
commit=c8d4e6d
ref=${REFERENCE_FMUS:-}
if [ "${1:-}" = "--reference-fmus" ]; then
    ref=$2
    shift 2
fi
target=$(cargo metadata --format-version 1 --no-deps | python3 -c 'import json,sys; print(json.load(sys.stdin)["target_directory"])')
out=$target/fmusim
mkdir -p "$out"
if [ -z "$ref" ]; then
    ref=$out/Reference-FMUs
    [ -d "$ref" ] || git clone --quiet https://github.com/modelica/Reference-FMUs "$ref"
fi
git -C "$ref" cat-file -e "$commit^{commit}" 2>/dev/null || {
    echo "error: $ref does not hold commit $commit of Reference-FMUs" >&2
    exit 1
}

# Debian packages (installed only when missing).
need=()
for p in libxml2-dev libminizip-dev libsundials-cvode6 libsundials-nvecserial6 \
    libsundials-sunlinsol3 libsundials-sunmatrix4; do
    dpkg -s "$p" >/dev/null 2>&1 || need+=("$p")
done
if [ ${#need[@]} -gt 0 ]; then
    apt-get install -y --no-install-recommends "${need[@]}" >/dev/null
fi
if [ ! -f "$out/sundials/usr/include/cvode/cvode.h" ]; then
    (cd "$out" && rm -f libsundials-dev_*.deb && apt-get download libsundials-dev >/dev/null 2>&1 &&
        dpkg-deb -x libsundials-dev_*.deb sundials)
fi

# fmusim from the pinned commit's sources.
src=$out/src-$commit
if [ ! -x "$out/fmusim" ] || [ ! -d "$src" ]; then
    rm -rf "$src" && mkdir -p "$src"
    # file by file (a partial clone may lack blobs elsewhere in the tree)
    git -C "$ref" ls-tree -r --name-only "$commit" fmusim include src | while read -r f; do
        mkdir -p "$src/$(dirname "$f")"
        git -C "$ref" cat-file blob "$commit:$f" >"$src/$f"
    done
    lib=/usr/lib/x86_64-linux-gnu
    gcc -O2 -std=gnu11 -w "-DFMUSIM_VERSION=\"$commit\"" -DSUN_COMM_NULL=NULL \
        -I"$src/fmusim" -I"$src/include" -I/usr/include/libxml2 -I/usr/include/minizip \
        -I"$out/sundials/usr/include" \
        "$src"/src/FMI.c "$src"/src/FMI1.c "$src"/src/FMI2.c "$src"/src/FMI3.c \
        "$src"/src/structured_variable_name.yy.c "$src"/src/structured_variable_name.tab.c \
        "$src"/fmusim/*.c -o "$out/fmusim" -lxml2 -lminizip -lz \
        "$lib"/libsundials_cvode.so.6 "$lib"/libsundials_nvecserial.so.6 \
        "$lib"/libsundials_sunmatrixdense.so.4.* "$lib"/libsundials_sunlinsoldense.so.4.* -ldl -lm
fi
echo "fmusim: $("$out/fmusim" --version 2>&1 | head -1) ($out/fmusim)"

# The FMUs, and fmpy beside fmusim.
if [ $# -eq 0 ]; then
    cargo build --release -p yarnsim-fmu -p yarnsim-fmu-pack --bins --lib
    pack=$target/release/build-fmu
    "$pack" --no-build --scene fmu/scenes/small.toml -o "$target/fmu/YarnBundle-small.fmu"
    "$pack" --no-build --scene wire
    set -- "$target/fmu/YarnBundle-small.fmu" "$target/fmu/MassSpring-wire.fmu"
    if "$pack" --help 2>&1 | grep -q -- '--fmi-version'; then
        "$pack" --no-build --fmi-version 3 --scene fmu/scenes/small.toml -o "$target/fmu/YarnBundle-small-fmi3.fmu"
        "$pack" --no-build --fmi-version 3 --scene wire
        set -- "$@" "$target/fmu/YarnBundle-small-fmi3.fmu" "$target/fmu/MassSpring-wire-fmi3.fmu"
    fi
fi
venv=tools/.venv
if ! "$venv/bin/python" -c 'import fmpy; assert fmpy.__version__ == "0.3.32"' 2>/dev/null; then
    python3 -m venv "$venv"
    "$venv/bin/pip" install --quiet fmpy==0.3.32
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$venv/bin/python" tools/fmu/fmusim_check.py "$out/fmusim" "$work" "$@"
