#!/usr/bin/env bash
# Runs every test suite of the project, after installing what the suites need.
# This is the README's test command; .ci/run calls it too.
set -euo pipefail
cd "$(dirname "$0")/.."

if ! command -v cargo >/dev/null; then
    echo "tests/run.sh: cargo is not installed. Install Rust (https://rustup.rs) and run again." >&2
    exit 1
fi
rustup component add rustfmt clippy >/dev/null 2>&1 || true

echo "== format and lints"
cargo fmt --all -- --check
cargo clippy --locked --all-targets -- -D warnings
cargo clippy --locked --lib --no-default-features -- -D warnings

echo "== Rust tests"
cargo test --locked

echo "== C API header: include/vstree.h must be what cbindgen makes of the crate"
CBINDGEN_VERSION=0.29.2
if ! cbindgen --version 2>/dev/null | grep -qx "cbindgen $CBINDGEN_VERSION"; then
    cargo install cbindgen --locked --version "$CBINDGEN_VERSION"
fi
generated=$(mktemp)
trap 'rm -f "$generated"' EXIT
cbindgen --quiet --config cbindgen.toml --output "$generated" .
if ! diff -u include/vstree.h "$generated"; then
    echo "include/vstree.h is out of date; regenerate it with" >&2
    echo "  cbindgen --config cbindgen.toml --output include/vstree.h ." >&2
    exit 1
fi

echo "== C API: C and C++ tests against the installed library, under valgrind"
bash tests/c/run.sh

echo "== C API: Python bindings (ctypes + numpy)"
bash tests/python/run.sh

echo "== C API and readers: bounded fuzzing"
bash fuzz/run.sh 10

echo "== MeshLab plugin in pymeshlab 2022.2.post4 and 2025.7.post1"
bash tests/meshlab/run.sh

echo "== Blender extension for every platform: linux-x64 (glibc 2.28), windows-x64 (C API tests under Wine), macos-arm64, macos-x64"
bash tests/platforms/run.sh

echo "== Blender extension in bpy 4.2.23 and 5.0.1"
bash tests/blender/run.sh

echo "== Desktop Blender and MeshLab under Xvfb: Debian 13 (4.3.2, 2022.02, pinned) and unstable (5.2, 2025.07), in chroots"
bash tests/hosts/run.sh
