#!/usr/bin/env bash
# Makes (or updates) target/blender-venv-VERSION: PyPI bpy==VERSION with numpy and pytest, on
# Python 3.11 (the bpy wheels require it: python3.11 on PATH, or PYTHON311=/path), and the
# shared libraries bpy needs from Debian. Used by tests/blender/run.sh and tests/platforms/run.sh
# (whose blender_ext.py comes from the bpy wheel).
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

for v in "$@"; do
    venv=$root/target/blender-venv-$v
    [ -x "$venv/bin/python" ] || "$py311" -m venv "$venv"
    "$venv/bin/python" -m pip install --quiet --disable-pip-version-check "bpy==$v" "numpy<2" pytest==8.3.4
done
