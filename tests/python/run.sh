#!/usr/bin/env bash
# Python tests of the ctypes bindings, in a virtual environment under target/ with pinned
# numpy and pytest (nothing is installed system-wide). Uses the release library.
set -euo pipefail
cd "$(dirname "$0")/../.."

venv="$PWD/target/py-venv"
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
fi
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check \
    numpy==2.1.3 pytest==8.3.4

cargo build --release --locked --lib --no-default-features
export VSTREE_LIBRARY="$PWD/target/release/libvstree.so"

# pytest exit codes: 0 all passed, 1 failures, 2 interrupted, 3 internal error, 4 usage error,
# 5 no tests collected. Anything but 0 fails the suite.
status=0
"$venv/bin/python" -m pytest -q -p no:cacheprovider tests/python "$@" || status=$?
if [ "$status" -ne 0 ]; then
    echo "tests/python: pytest exited with status $status" >&2
    exit "$status"
fi
