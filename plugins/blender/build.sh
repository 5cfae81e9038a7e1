#!/usr/bin/env bash
# Builds the VS-Tree Blender extension zip:
#   target/blender/dist/vstree-0.1.2-linux_x64.zip
# Stages plugins/blender/vstree_blender + bindings/python/vstree + libvstree.so under
# target/blender/stage/vstree, then runs Blender's own blender_ext.py build.
#
# blender_ext.py ships inside Blender (and the PyPI bpy wheel); give its path with
# BLENDER_EXT_PY, else it is looked for in the test venvs under target/ (tests/blender/run.sh
# makes them). It is standard-library only and runs with any Python >= 3.11.
set -euo pipefail
cd "$(dirname "$0")/../.."
root=$PWD

cargo build --release --locked --lib --no-default-features
lib=$root/target/release/libvstree.so

ext_py=${BLENDER_EXT_PY:-}
if [ -z "$ext_py" ]; then
    ext_py=$(ls "$root"/target/blender-venv-*/lib/python3.11/site-packages/bpy/*/scripts/addons_core/bl_pkg/cli/blender_ext.py 2>/dev/null | sort | tail -n 1 || true)
fi
if [ -z "$ext_py" ] || [ ! -f "$ext_py" ]; then
    echo "plugins/blender/build.sh: blender_ext.py not found; set BLENDER_EXT_PY or run tests/blender/run.sh" >&2
    exit 1
fi
python=${PYTHON:-python3}

stage=$root/target/blender/stage/vstree
dist=$root/target/blender/dist
rm -rf "$stage" "$dist"
mkdir -p "$stage" "$dist"     # blender_ext.py does not create the output directory
cp plugins/blender/vstree_blender/*.py plugins/blender/vstree_blender/blender_manifest.toml "$stage/"
mkdir -p "$stage/vstree"
cp bindings/python/vstree/*.py "$stage/vstree/"
cp "$lib" "$stage/vstree/libvstree.so"

"$python" "$ext_py" build --source-dir "$stage" --output-dir "$dist" --split-platforms
"$python" "$ext_py" validate "$dist"/vstree-0.1.2-linux_x64.zip
echo "built $dist/vstree-0.1.2-linux_x64.zip"
