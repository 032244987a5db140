#!/usr/bin/env bash
# The FMUs through the Modelica Association's FMI Compliance Checker
# (FMUComplianceChecker, fmuCheck.linux64, FMI Library 2.0.3): builds the
# checker into tools/.fmucc if it is not there yet (cmake and a C compiler;
# about 40 s on 2 cores), builds the YarnBundle FMUs of the default scene,
# of fmu/scenes/small.toml and of fmu/scenes/driven.toml (input pins) and
# the MassSpring FMUs of the wire and the cloth, and runs on each
#   fmuCheck -k xml, fmuCheck -k cs, and fmuCheck -k cs -i INPUTS.csv
# (an input table that drives every input: attractor, gravity, the driven
# pin). Prints the checker's summary per FMU and run; exits non-zero when
# any run reports a warning or an error (from the checker or the FMU).
#
# Sources: FMUCC_GIT (default the GitHub repository; commit FMUCC_REV,
# default c704b98, the last one) and FMIL_GIT (FMI Library, tag 2.0.3,
# which the checker's CMake would download itself; here it is cloned first
# so that a local mirror works offline). FMUCC_BIN=path/to/fmuCheck.linux64
# uses an existing checker instead.
set -euo pipefail
cd "$(dirname "$0")/../.."
root=$(pwd)
dir=tools/.fmucc
FMUCC_GIT=${FMUCC_GIT:-https://github.com/modelica-tools/FMUComplianceChecker.git}
FMUCC_REV=${FMUCC_REV:-c704b98}
FMIL_GIT=${FMIL_GIT:-https://github.com/modelon-community/fmi-library.git}
FMIL_TAG=2.0.3
checker=${FMUCC_BIN:-$root/$dir/install/fmuCheck.linux64}

if [ ! -x "$checker" ]; then
    echo "building FMUComplianceChecker $FMUCC_REV with FMI Library $FMIL_TAG into $dir"
    start=$(date +%s)
    rm -rf "$dir"
    mkdir -p "$dir"
    git clone --quiet "$FMUCC_GIT" "$dir/src"
    git -C "$dir/src" -c advice.detachedHead=false checkout --quiet "$FMUCC_REV"
    case "$FMIL_GIT" in
        /*) fmil_url="file://$FMIL_GIT" ;;
        *) fmil_url=$FMIL_GIT ;;
    esac
    git -c advice.detachedHead=false clone --quiet --depth 1 --branch "$FMIL_TAG" "$fmil_url" "$dir/src/FMIL"
    # FMIL is already in place: no download step; skip FMIL's own tests.
    sed -i -e '/GIT_REPOSITORY/d' -e '/GIT_TAG/d' \
        -e 's/FMILIB_BUILD_TESTS:BOOLEAN=ON/FMILIB_BUILD_TESTS:BOOLEAN=OFF/' "$dir/src/CMakeLists.txt"
    cmake -S "$dir/src" -B "$dir/build" -DCMAKE_BUILD_TYPE=Release \
        -DFMUCHK_INSTALL_PREFIX="$root/$dir/install" >"$dir/configure.log" 2>&1 ||
        { tail -30 "$dir/configure.log"; exit 1; }
    cmake --build "$dir/build" --target install -j "${CARGO_BUILD_JOBS:-2}" >"$dir/build.log" 2>&1 ||
        { tail -30 "$dir/build.log"; exit 1; }
    echo "built $checker in $(($(date +%s) - start)) s"
fi
"$checker" -v 2>&1 | head -3 || true

cargo build --release -p yarnsim-fmu -p yarnsim-fmu-pack --bins --lib
target=$(cargo metadata --format-version 1 --no-deps | sed -n 's/.*"target_directory":"\([^"]*\)".*/\1/p')
fmus=$target/fmu
"$target/release/build-fmu" --no-build
"$target/release/build-fmu" --no-build --scene fmu/scenes/small.toml
"$target/release/build-fmu" --no-build --scene fmu/scenes/driven.toml
"$target/release/build-fmu" --no-build --scene wire
"$target/release/build-fmu" --no-build --scene cloth

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# Input tables (the checker interpolates Reals linearly, steps Booleans).
cat >"$work/yarn.csv" <<'EOF'
"time","attractor.x","attractor.y","attractor.strength","attractor.active","gravity.x","gravity.y"
0.0,0.5,0.5,0.0,0,0.0,-9.8
0.1,0.5,0.5,0.0,0,0.0,-9.8
0.12,0.4,0.6,20.0,1,0.0,-9.8
0.2,0.6,0.6,40.0,1,2.0,-9.0
0.3,0.5,0.4,10.0,0,0.0,-9.8
0.5,0.5,0.4,10.0,0,-1.0,-9.8
EOF
cat >"$work/driven.csv" <<'EOF'
"time","attractor.x","attractor.y","attractor.strength","attractor.active","gravity.x","gravity.y","pin[0].x","pin[0].y","pin[0].vx","pin[0].vy"
0.0,0.5,0.5,0.0,0,0.0,-9.8,0.25,0.65,0.0,0.0
0.05,0.5,0.5,0.0,0,0.0,-9.8,0.25,0.65,0.2,0.0
0.15,0.4,0.6,20.0,1,1.0,-9.8,0.27,0.65,0.2,0.1
0.25,0.5,0.6,20.0,1,0.0,-9.8,0.29,0.66,0.0,-0.1
0.3,0.5,0.6,0.0,0,0.0,-9.8,0.29,0.655,0.0,0.0
EOF
cat >"$work/ms.csv" <<'EOF'
"time","gravity.x","gravity.y","gravity.z"
0.0,0.0,0.0,-9.81
1.0,0.0,0.0,-9.81
2.0,3.0,0.0,-9.0
3.0,0.0,-2.0,-9.81
5.0,0.0,0.0,-9.81
EOF

failed=0
summary=()
run() { # name fmu label args...
    local name=$1 fmu=$2 label=$3
    shift 3
    local log=$work/$name-${label// /_}.log
    local rc=0
    "$checker" -l 3 -o "$work/out.csv" -e "$log" -t "$work" "$@" "$fmu" || rc=$?
    local fmu_n chk_w chk_e
    fmu_n=$(sed -n 's/^[[:space:]]*\([0-9]*\) warning(s) and error(s).*/\1/p' "$log")
    chk_w=$(sed -n 's/^[[:space:]]*\([0-9]*\) Warning(s).*/\1/p' "$log")
    chk_e=$(sed -n 's/^[[:space:]]*\([0-9]*\) Error(s).*/\1/p' "$log")
    local line
    line=$(printf '%-24s %-12s FMU reported %s warning(s) and error(s); checker %s warning(s), %s error(s)' \
        "$name" "$label" "${fmu_n:-?}" "${chk_w:-?}" "${chk_e:-?}")
    summary+=("$line")
    if [ "$rc" != 0 ] || [ "${fmu_n:-1}" != 0 ] || [ "${chk_w:-1}" != 0 ] || [ "${chk_e:-1}" != 0 ]; then
        failed=1
        echo "--- $name $label (exit $rc):"
        grep -v '^$' "$log" | head -40
    fi
}
for spec in "YarnBundle:yarn" "YarnBundle-yarn-small:yarn" "YarnBundle-yarn-driven:driven" \
    "MassSpring-wire:ms" "MassSpring-cloth:ms"; do
    name=${spec%%:*}
    inputs=$work/${spec##*:}.csv
    run "$name" "$fmus/$name.fmu" "xml" -k xml
    run "$name" "$fmus/$name.fmu" "cs" -k cs
    run "$name" "$fmus/$name.fmu" "cs inputs" -k cs -i "$inputs"
done
printf '%s\n' "${summary[@]}"
if [ "$failed" != 0 ]; then
    echo "FMUComplianceChecker reported problems (above)"
    exit 1
fi
echo "FMUComplianceChecker: 0 warnings, 0 errors on every FMU and run"
