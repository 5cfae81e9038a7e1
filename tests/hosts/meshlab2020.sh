#!/usr/bin/env bash
# MeshLab 2020.09, Debian 12's desktop package, on this host (Debian 12, root): the plugin built
# from the same source for 2020.09's plugin interface (MeshFilterInterface) against the
# package's libmeshlab-common and the headers of the same version (plugins/meshlab/build.sh
# fetches and checks them), copied into the package's plugin folder, then `meshlabserver`
# applies both filters from .mlx scripts to a generated torus and, when ../shared/data exists,
# to bunny_zipper.ply and armadillo_43k.obj; each output is checked (counts, watertight).
# The plugin is removed from the plugin folder afterwards (a file there before is put back).
# Installs what it needs with apt. Each check prints ok/FAIL; the last line is
# "N passed, M failed" and the status is non-zero when anything failed. Not Debian 12: skipped.
# Run on its own or from tests/hosts/run.sh (which passes VSTREE_HOSTS_RESULTS, its results
# file, and reads the checks from there).
# env: JOBS=2, CARGO_BUILD_JOBS (libvstree's build; Rust from rustup must be on PATH).
# shellcheck disable=SC2016 # dpkg-query formats are meant literally
set -euo pipefail
cd "$(dirname "$0")/../.."
root=$PWD
T0=$SECONDS
JOBS=${JOBS:-2}
work=$root/target/hosts/meshlab2020
data=${VSTREE_DATA:-$(cd "$root/.." && pwd)/shared/data}
ml_lib=/usr/lib/x86_64-linux-gnu/meshlab
plugdir=$ml_lib/plugins
# shellcheck source=tests/hosts/meshlab_scalar.sh
source tests/hosts/meshlab_scalar.sh

rm -rf "$work"
mkdir -p "$work"
results=$work/results.txt
: >"$results"
record() { # record PASS|FAIL|SKIP TEXT: into this script's results and run.sh's, if given
    echo "$1 debian12 meshlab 2020.09: $2" >>"$results"
    [ -z "${VSTREE_HOSTS_RESULTS:-}" ] || echo "$1 debian12 meshlab 2020.09: $2" >>"$VSTREE_HOSTS_RESULTS"
}
pass() { echo "ok   $*"; record PASS "$*"; }
fail() { echo "FAIL $*" >&2; record FAIL "$*"; }
skip() { echo "SKIP $*"; record SKIP "$*"; }
step() { echo "== [$((SECONDS - T0)) s] $*"; }
summary() {
    local p f s
    p=$(grep -c '^PASS' "$results" || true)
    f=$(grep -c '^FAIL' "$results" || true)
    s=$(grep -c '^SKIP' "$results" || true)
    echo "== tests/hosts/meshlab2020.sh: done in $((SECONDS - T0)) s"
    echo "$p passed, $f failed$([ "$s" -eq 0 ] || echo ", $s skipped")"
    [ "$f" -eq 0 ]
}

if [ "$(id -u)" -ne 0 ]; then
    echo "tests/hosts/meshlab2020.sh: needs root (apt, the package's plugin folder)" >&2
    exit 1
fi
# shellcheck disable=SC1091
if [ "$(. /etc/os-release && echo "${ID:-}:${VERSION_ID:-}")" != "debian:12" ]; then
    skip "the host is not Debian 12 ($(. /etc/os-release && echo "${PRETTY_NAME:-unknown}")): MeshLab 2020.09 is Debian 12's package"
    summary
    exit $?
fi

step "host packages"
pkgs=(meshlab xvfb xauth libgl1-mesa-dri curl xz-utils ca-certificates python3 binutils
    g++ make cmake qtbase5-dev libqt5opengl5-dev libglew-dev libeigen3-dev)
missing=()
for p in "${pkgs[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
    echo "installing ${missing[*]}"
    export DEBIAN_FRONTEND=noninteractive
    timeout 600 apt-get update -qq
    timeout 1800 apt-get install -y -qq "${missing[@]}" >"$work/apt.log" 2>&1 ||
        { tail -n 20 "$work/apt.log" >&2; fail "apt-get install ${missing[*]} failed"; summary; exit 1; }
fi
ml_version=$(dpkg-query -W -f='${Version}' meshlab)
echo "meshlab $ml_version, $(dpkg-query -W -f='${Package} ${Version}' libqt5core5a), $(dpkg-query -W -f='${Package} ${Version}' libgl1-mesa-dri)"
case $ml_version in
    2020.09*) pass "Debian 12's meshlab package is $ml_version" ;;
    *)
        fail "Debian 12's meshlab package is $ml_version, not 2020.09"
        summary
        exit 1
        ;;
esac

step "the plugin, built against the package's libmeshlab-common and MeshLab 2020.09's headers"
timeout 600 env HEADERS_ONLY=1 bash plugins/meshlab/build.sh 2020.09
ml_src=$root/target/meshlab/src/meshlab-2020.09
prefix=$work/vstree-prefix
if ! command -v cargo >/dev/null; then
    fail "no cargo on PATH: libvstree is built from source (install Rust 1.82 or later with rustup)"
    summary
    exit 1
fi
if ! CARGO_BUILD_JOBS=${CARGO_BUILD_JOBS:-$JOBS} timeout 1800 nice -n 10 bash bindings/install.sh "$prefix" >"$work/libvstree.log" 2>&1; then
    tail -n 20 "$work/libvstree.log" >&2
    fail "libvstree did not build (log: target/hosts/meshlab2020/libvstree.log)"
    summary
    exit 1
fi
if ! scalar=$(meshlab_scalar "$plugdir/libfilter_clean.so"); then
    fail "cannot tell whether MeshLab $ml_version is built with float or double"
    summary
    exit 1
fi
echo "MeshLab $ml_version: built with $scalar scalars"
build=$work/build
t=$SECONDS
if timeout 300 cmake -S plugins/meshlab -B "$build" -DCMAKE_BUILD_TYPE=Release -DMESHLAB_SRC_DIR="$ml_src" \
    -DMESHLAB_LIB_DIR="$ml_lib" -DMESHLAB_VERSION=2020.09 -DMESHLAB_SCALAR="$scalar" \
    -DVSTREE_PREFIX="$prefix" >"$work/cmake.log" 2>&1 &&
    timeout 1800 nice -n 10 cmake --build "$build" -j "$JOBS" >>"$work/cmake.log" 2>&1; then
    pass "the plugin builds for 2020.09's MeshFilterInterface against the package's libmeshlab-common ($((SECONDS - t)) s)"
else
    tail -n 30 "$work/cmake.log" >&2
    fail "the plugin does not build for MeshLab $ml_version (log: target/hosts/meshlab2020/cmake.log)"
    summary
    exit 1
fi

# Installed as a user of the package would: the plugin and libvstree.so.0 (found through the
# plugin's RUNPATH $ORIGIN) into the package's plugin folder; removed when done, and a plugin
# that was there before is put back.
backup=$work/plugin-backup
mkdir -p "$backup"
installed=
cleanup() {
    [ -n "$installed" ] || return 0
    rm -f "$plugdir/libfilter_vstree.so" "$plugdir/libvstree.so.0"
    for f in libfilter_vstree.so libvstree.so.0; do
        [ ! -f "$backup/$f" ] || cp -p "$backup/$f" "$plugdir/$f"
    done
}
trap cleanup EXIT
for f in libfilter_vstree.so libvstree.so.0; do
    [ ! -f "$plugdir/$f" ] || cp -p "$plugdir/$f" "$backup/$f"
done
installed=1
cp "$build/libfilter_vstree.so" "$plugdir/"
cp -L "$prefix/lib/libvstree.so.0" "$plugdir/"
if unresolved=$(LD_LIBRARY_PATH="$ml_lib" ldd -r "$plugdir/libfilter_vstree.so" 2>&1 | grep -E "not found|undefined symbol"); then
    fail "the plugin has unresolved libraries or symbols: $unresolved"
else
    pass "the plugin resolves every library and symbol against the package's ($plugdir)"
fi

# --- .mlx scripts ----------------------------------------------------------------------------
# meshlabserver 2020.09 needs every parameter of a filter in the script, in the filter's order
# (it fills missing ones by position and asserts the counts match), as MeshLab's own
# File > Save filter script writes them. The filter names are the dialog's (filterName()).
mlx_simplify() { # mlx_simplify OUT PERC: the simplification to PERC of the faces
    cat >"$1" <<EOF
<!DOCTYPE FilterScript>
<FilterScript>
 <filter name="VS-Tree Clustering Simplification">
  <Param type="RichInt" value="0" name="target_faces"/>
  <Param type="RichFloat" value="$2" name="target_perc"/>
  <Param type="RichEnum" value="0" name="keep_topology" enum_cardinality="3" enum_val0="Auto (edge-manifold inputs)" enum_val1="On" enum_val2="Off"/>
  <Param type="RichFloat" value="0.001" name="error"/>
  <Param type="RichAbsPerc" value="0" min="0" max="1" name="distance"/>
  <Param type="RichEnum" value="0" name="tree_kind" enum_cardinality="2" enum_val0="VS-Tree" enum_val1="Octree"/>
  <Param type="RichEnum" value="0" name="metric" enum_cardinality="3" enum_val0="L2 (quadric)" enum_val1="L2,1 (normal deviation)" enum_val2="Density (samples)"/>
  <Param type="RichFloat" value="0" name="d_a"/>
  <Param type="RichFloat" value="0.166667" name="d_d"/>
  <Param type="RichEnum" value="0" name="sampling" enum_cardinality="2" enum_val0="Vertices" enum_val1="Face centers"/>
  <Param type="RichInt" value="24" name="max_depth"/>
 </filter>
</FilterScript>
EOF
}
mlx_reconstruct() { # mlx_reconstruct OUT LEVELS ESTIMATE_NORMALS(true|false)
    cat >"$1" <<EOF
<!DOCTYPE FilterScript>
<FilterScript>
 <filter name="VS-Tree Surface Reconstruction">
  <Param type="RichFloat" value="1e-05" name="error"/>
  <Param type="RichAbsPerc" value="0" min="0" max="1" name="distance"/>
  <Param type="RichInt" value="$2" name="levels"/>
  <Param type="RichEnum" value="0" name="surface" enum_cardinality="3" enum_val0="Auto (open scans stay open)" enum_val1="Closed" enum_val2="Open"/>
  <Param type="RichFloat" value="0" name="trim"/>
  <Param type="RichBool" value="$3" name="estimate_normals"/>
 </filter>
</FilterScript>
EOF
}
mlx_simplify "$work/simplify.mlx" 0.1
mlx_reconstruct "$work/reconstruct.mlx" 3 true
mlx_reconstruct "$work/reconstruct-no-normals.mlx" 3 false

# server NAME IN SCRIPT: meshlabserver -i IN -o NAME.ply -s SCRIPT under Xvfb (Mesa's software
# OpenGL); its output in NAME.log, the time in $secs, the status in $status.
server() {
    local t=$SECONDS
    status=0
    timeout 600 xvfb-run -a -s "-screen 0 1024x768x24 -nolisten tcp" env LIBGL_ALWAYS_SOFTWARE=1 \
        meshlabserver -i "$2" -o "$work/$1.ply" -s "$3" >"$work/$1.log" 2>&1 || status=$?
    secs=$((SECONDS - t))
}
# stats FILE: sets v, f, closed, euler (tests/hosts/ply.py stats)
stats() {
    read -r _ v _ f _ closed _ euler <<<"$(python3 tests/hosts/ply.py stats "$1")"
}
# simplify NAME IN.ply: 10% of the faces, within the library's 1% (2 at least); a closed input
# stays closed with its Euler characteristic (Keep topology: Auto).
simplify() {
    local name=$1 in=$2 v0 f0 closed0 euler0 want slack
    stats "$in"
    v0=$v f0=$f closed0=$closed euler0=$euler
    server "$name-simplified" "$in" "$work/simplify.mlx"
    if [ "$status" -ne 0 ] || [ ! -s "$work/$name-simplified.ply" ]; then
        tail -n 15 "$work/$name-simplified.log" >&2
        fail "$name: meshlabserver with simplify.mlx exited with status $status, no output (log: target/hosts/meshlab2020/$name-simplified.log)"
        return 0
    fi
    stats "$work/$name-simplified.ply"
    want=$(((f0 + 5) / 10))
    slack=$((want / 100 > 2 ? want / 100 : 2))
    echo "   $name: $v0 vertices, $f0 faces (closed $closed0, Euler $euler0) -> $v vertices, $f faces (closed $closed, Euler $euler) in $secs s"
    if [ "$f" -ge $((want - slack)) ] && [ "$f" -le $((want + slack)) ] && [ "$v" -lt "$v0" ] &&
        [ "$closed" = "$closed0" ] && { [ "$closed0" = 0 ] || [ "$euler" = "$euler0" ]; }; then
        pass "$name: VS-Tree Clustering Simplification from an .mlx: $f0 -> $f faces (10% within $slack), closed $closed as the input$([ "$closed0" = 0 ] || echo ", Euler $euler kept") ($secs s)"
    else
        fail "$name: VS-Tree Clustering Simplification gave $v vertices, $f faces, closed $closed, Euler $euler (want $want +- $slack faces, closed $closed0$([ "$closed0" = 0 ] || echo ", Euler $euler0"))"
    fi
}
# reconstruct NAME IN MIN_FACES [EULER]: a watertight surface of at least MIN_FACES faces (and
# Euler characteristic EULER when given).
reconstruct() {
    local name=$1 in=$2 min=$3 want_euler=${4:-}
    server "$name-reconstructed" "$in" "$work/reconstruct.mlx"
    if [ "$status" -ne 0 ] || [ ! -s "$work/$name-reconstructed.ply" ]; then
        tail -n 15 "$work/$name-reconstructed.log" >&2
        fail "$name: meshlabserver with reconstruct.mlx exited with status $status, no output (log: target/hosts/meshlab2020/$name-reconstructed.log)"
        return 0
    fi
    stats "$work/$name-reconstructed.ply"
    echo "   $name: reconstructed: $v vertices, $f faces, closed $closed, Euler $euler in $secs s"
    if [ "$closed" = 1 ] && [ "$f" -ge "$min" ] && { [ -z "$want_euler" ] || [ "$euler" = "$want_euler" ]; }; then
        pass "$name: VS-Tree Surface Reconstruction from an .mlx: $v vertices, $f faces, watertight$([ -z "$want_euler" ] || echo ", Euler $euler") ($secs s)"
    else
        fail "$name: VS-Tree Surface Reconstruction gave $v vertices, $f faces, closed $closed, Euler $euler (want watertight, >= $min faces$([ -z "$want_euler" ] || echo ", Euler $want_euler"))"
    fi
}

step "meshlabserver: generated models"
python3 tests/hosts/ply.py torus "$work/torus.ply"               # 3072 vertices, 6144 faces, genus 1
python3 tests/hosts/ply.py torus-points "$work/torus-points.ply" # its vertices, no normals
simplify torus "$work/torus.ply"
reconstruct torus-points "$work/torus-points.ply" 1000 0
# A point cloud without normals and 'Estimate normals' off: the filter fails with its message
# (2020.09 has no exceptions: errorMessage, "Problem with filter"), meshlabserver does not crash.
server torus-no-normals "$work/torus-points.ply" "$work/reconstruct-no-normals.mlx"
# (meshlabserver exits with -1, 255; 124 is timeout's, 129-254 a signal's such as an abort)
if [ "$status" -ne 0 ] && [ "$status" != 124 ] && { [ "$status" -lt 128 ] || [ "$status" = 255 ]; } &&
    grep -q "Problem with filter" "$work/torus-no-normals.log" && grep -q "has no normals" "$work/torus-no-normals.log"; then
    pass "no normals and 'Estimate normals' off: the filter fails with its message, meshlabserver exits with status $status"
else
    tail -n 10 "$work/torus-no-normals.log" >&2
    fail "no normals and 'Estimate normals' off: status $status, no 'has no normals' message (log: target/hosts/meshlab2020/torus-no-normals.log)"
fi

step "meshlabserver: shared models"
if [ -d "$data" ]; then
    simplify bunny_zipper "$data/bunny_zipper.ply"
    reconstruct bunny_zipper "$data/bunny_zipper.ply" 10000
    # MeshLab 2020.09's OBJ reader aborts on armadillo_43k.obj (an assertion in vcglib's
    # import_obj.h); it goes in as PLY.
    python3 tests/hosts/ply.py obj2ply "$data/armadillo_43k.obj" "$work/armadillo_43k.ply"
    simplify armadillo_43k "$work/armadillo_43k.ply"
    reconstruct armadillo_43k "$work/armadillo_43k.ply" 10000
elif [ -n "${CI:-}" ] || [ -n "${VSTREE_DATA:-}" ]; then
    fail "no $data, and CI or VSTREE_DATA says the shared models must be there"
else
    skip "no $data: the shared models were not run"
fi

cleanup
installed=
if [ -f "$plugdir/libfilter_vstree.so" ] && [ ! -f "$backup/libfilter_vstree.so" ]; then
    fail "the plugin is still in $plugdir after the test"
else
    pass "the plugin folder is as before the test"
fi
summary
