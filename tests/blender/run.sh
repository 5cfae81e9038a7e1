#!/usr/bin/env bash
# Tests of the VS-Tree Blender extension inside the PyPI `bpy` modules 4.2.23 (LTS) and 5.0.1:
# builds the linux-x64 extension zip (plugins/blender/build.sh, installing its toolchain when
# missing; tests/platforms/run.sh builds and checks all four platforms), installs it into a
# throw-away user directory and runs the operators headless. Virtual environments live under
# target/.
# Needs Python 3.11 (the bpy wheels require it): python3.11 on PATH, or PYTHON311=/path.
set -euo pipefail
cd "$(dirname "$0")/../.."
root=$PWD

versions=${VSTREE_BPY_VERSIONS:-"4.2.23 5.0.1"}
# shellcheck disable=SC2086
bash tests/blender/venv.sh $versions

first=${versions%% *}
PYTHON=$root/target/blender-venv-$first/bin/python \
    BLENDER_EXT_PY=$(ls "$root"/target/blender-venv-"$first"/lib/python3.11/site-packages/bpy/*/scripts/addons_core/bl_pkg/cli/blender_ext.py) \
    VSTREE_PLATFORMS=linux-x64 VSTREE_INSTALL_TOOLS=1 bash plugins/blender/build.sh

for v in $versions; do
    echo "== bpy $v"
    status=0
    (cd tests/blender && "$root/target/blender-venv-$v/bin/python" -m pytest -q -p no:cacheprovider . "$@") || status=$?
    if [ "$status" -ne 0 ]; then
        echo "tests/blender: pytest in bpy $v exited with status $status" >&2
        exit "$status"
    fi
    "$root/target/blender-venv-$v/bin/python" tests/blender/legacy_check.py "$root/target/blender/stage/linux-x64"
done
