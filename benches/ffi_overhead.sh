#!/usr/bin/env bash
# The C ABI's overhead on a 1M-triangle simplification (docs/benchmarks-ffi.md): the Rust
# call against the C-ABI functions (benches/ffi_overhead.rs), then the same work through the
# installed shared library from C (ffi_overhead.c) and from Python/ctypes with numpy
# (ffi_overhead.py). Run on an otherwise idle machine: bash benches/ffi_overhead.sh
set -euo pipefail
cd "$(dirname "$0")/.."

cargo bench --locked --bench ffi_overhead
bash bindings/install.sh target/capi-install >/dev/null
export LD_LIBRARY_PATH="$PWD/target/capi-install/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
cc -std=c99 -O2 -Wall -Wextra -Werror -pedantic -Itarget/capi-install/include \
    benches/ffi_overhead.c -Ltarget/capi-install/lib -lvstree -o target/ffi-bench/ffi_overhead_c
echo "-- from C, through libvstree.so"
target/ffi-bench/ffi_overhead_c target/ffi-bench/torus_1m.ply target/ffi-bench/rust.txt

venv="$PWD/target/py-venv"
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
fi
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check numpy==2.1.3
echo "-- from Python, through ctypes and numpy"
VSTREE_LIBRARY="$PWD/target/capi-install/lib/libvstree.so" \
    "$venv/bin/python" benches/ffi_overhead.py target/ffi-bench/torus_1m.ply target/ffi-bench/rust.txt
