#!/usr/bin/env bash
# Builds the VS-Tree Blender extension, one zip per platform Blender's extension platform
# serves, into target/blender/dist:
#   vstree-<version>-linux_x64.zip     libvstree.so, glibc 2.28 and later (as Blender's builds)
#   vstree-<version>-windows_x64.zip   vstree.dll (x86_64-pc-windows-gnu, mingw-w64)
#   vstree-<version>-macos_arm64.zip   libvstree.dylib, Apple Silicon, macOS 11 and later
#   vstree-<version>-macos_x64.zip     libvstree.dylib, Intel, macOS 11 and later
# Each platform is staged under target/blender/stage/<platform>/ (the add-on, the ctypes
# binding, that platform's library, the manifest with `platforms = [<platform>]`), built with
# Blender's own `blender_ext.py build --split-platforms` and checked with `blender_ext.py
# validate`. VSTREE_PLATFORMS="linux-x64 ..." builds only those (default: all four).
#
# The cross toolchain (pinned versions) is described in plugins/blender/toolchain.sh;
# VSTREE_INSTALL_TOOLS=1 installs what is missing (Debian packages, rustup targets, a Python
# environment under ~/.cache), else a missing tool stops the build with its name.
#
# blender_ext.py ships inside Blender (and the PyPI bpy wheel); give its path with
# BLENDER_EXT_PY, else it is looked for in the test venvs under target/ (tests/blender/run.sh
# makes them). It is standard-library only and runs with any Python >= 3.11.
set -euo pipefail
cd "$(dirname "$0")/../.."
root=$PWD
# shellcheck source=plugins/blender/toolchain.sh
source plugins/blender/toolchain.sh

platforms=${VSTREE_PLATFORMS:-$VSTREE_PLATFORMS_ALL}
for p in $platforms; do rust_target "$p" >/dev/null; done
[ "${VSTREE_INSTALL_TOOLS:-0}" = 1 ] && toolchain_install
# shellcheck disable=SC2086
toolchain_check $platforms

ext_py=${BLENDER_EXT_PY:-}
if [ -z "$ext_py" ]; then
    ext_py=$(ls "$root"/target/blender-venv-*/lib/python3.11/site-packages/bpy/*/scripts/addons_core/bl_pkg/cli/blender_ext.py 2>/dev/null | sort | tail -n 1 || true)
fi
if [ -z "$ext_py" ] || [ ! -f "$ext_py" ]; then
    echo "plugins/blender/build.sh: blender_ext.py not found; set BLENDER_EXT_PY or run tests/blender/run.sh" >&2
    exit 1
fi
python=${PYTHON:-python3}

manifest=plugins/blender/vstree_blender/blender_manifest.toml
version=$(sed -n 's/^version = "\([^"]*\)"$/\1/p' "$manifest")
dist=$root/target/blender/dist
mkdir -p "$dist"     # blender_ext.py does not create the output directory

for platform in $platforms; do
    lib=$(build_library "$platform")
    stage=$root/target/blender/stage/$platform/vstree
    zip=$dist/vstree-$version-${platform/-/_}.zip
    # Zips of earlier versions for this platform go too: one zip per platform in dist.
    rm -rf "$stage" "$dist"/vstree-*-"${platform/-/_}".zip
    mkdir -p "$stage/vstree"
    cp plugins/blender/vstree_blender/*.py "$stage/"
    # This zip's manifest names its one platform: Blender refuses it on the others.
    sed "s/^platforms = .*/platforms = [\"$platform\"]/" "$manifest" >"$stage/blender_manifest.toml"
    grep -qx "platforms = \[\"$platform\"\]" "$stage/blender_manifest.toml"
    cp bindings/python/vstree/*.py "$stage/vstree/"
    cp "$lib" "$stage/vstree/$(library_name "$platform")"
    "$python" "$ext_py" build --source-dir "$stage" --output-dir "$dist" --split-platforms >/dev/null
    "$python" "$ext_py" validate "$zip"
    echo "built $zip ($(du -k "$zip" | cut -f1) KiB)"
done
