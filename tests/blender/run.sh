#!/usr/bin/env bash
# Tests of the VS-Tree Blender extension inside the PyPI `bpy` modules 4.2.23 (LTS) and 5.0.1:
# builds the extension zip (plugins/blender/build.sh), installs it into a throw-away user
# directory and runs the operators headless. Virtual environments live under target/.
# Needs Python 3.11 (the bpy wheels require it): python3.11 on PATH, or PYTHON311=/path.
set -euo pipefail
cd "$(dirname "$0")/../.."
root=$PWD

py311=${PYTHON311:-$(command -v python3.11 || true)}
if [ -z "$py311" ]; then
    echo "tests/blender: python3.11 not found (set PYTHON311)" >&2
    exit 1
fi

# Shared libraries bpy needs (X11/GL client libs, OpenMP); installed only when missing.
pkgs="libx11-6 libxrender1 libxfixes3 libxi6 libxkbcommon0 libsm6 libice6 libgl1 libxext6 libxxf86vm1 libgomp1 libegl1"
missing=""
for p in $pkgs; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
if [ -n "$missing" ]; then
    echo "tests/blender: installing$missing"
    sudo=""; [ "$(id -u)" -ne 0 ] && sudo=sudo
    $sudo apt-get update -qq
    $sudo apt-get install -y -qq --no-install-recommends $missing
fi

versions=${VSTREE_BPY_VERSIONS:-"4.2.23 5.0.1"}
for v in $versions; do
    venv=$root/target/blender-venv-$v
    [ -x "$venv/bin/python" ] || "$py311" -m venv "$venv"
    "$venv/bin/python" -m pip install --quiet --disable-pip-version-check "bpy==$v" "numpy<2" pytest==8.3.4
done

first=${versions%% *}
PYTHON=$root/target/blender-venv-$first/bin/python \
    BLENDER_EXT_PY=$(ls "$root"/target/blender-venv-"$first"/lib/python3.11/site-packages/bpy/*/scripts/addons_core/bl_pkg/cli/blender_ext.py) \
    bash plugins/blender/build.sh

for v in $versions; do
    echo "== bpy $v"
    status=0
    (cd tests/blender && "$root/target/blender-venv-$v/bin/python" -m pytest -q -p no:cacheprovider . "$@") || status=$?
    if [ "$status" -ne 0 ]; then
        echo "tests/blender: pytest in bpy $v exited with status $status" >&2
        exit "$status"
    fi
    "$root/target/blender-venv-$v/bin/python" tests/blender/legacy_check.py "$root/target/blender/stage"
done
