#!/usr/bin/env bash
# Bounded fuzzing run of every target in fuzz/ (cargo-fuzz: libFuzzer + AddressSanitizer):
# the PLY/OBJ/OFF/XYZ readers, the PLY reader's ASCII and binary bodies behind realistic
# headers (fuzz_targets/ply_header.rs) and the C API entry points, each for a few seconds
# from the committed seeds (fuzz/seeds, made by fuzz/make_seeds.py). Any crash, sanitizer report,
# panic, or VSTREE_STATUS_INTERNAL from the C API fails the run; the input is kept under
# target/fuzz-artifacts/<target>/ for reproduction:
#   RUSTC_BOOTSTRAP=1 cargo fuzz run --fuzz-dir fuzz --target-dir target/fuzz <target> <artifact>
#
# cargo-fuzz needs nightly compiler flags (-Zsanitizer, coverage passes); the stable
# toolchain accepts them with RUSTC_BOOTSTRAP=1, which is set for these builds only.
# Usage: fuzz/run.sh [SECONDS_PER_TARGET]   (default 15; the C API targets get twice that)
set -euo pipefail
cd "$(dirname "$0")/.."

CARGO_FUZZ_VERSION=0.13.2
seconds=${1:-15}

if ! cargo fuzz --version 2>/dev/null | grep -q " $CARGO_FUZZ_VERSION\$"; then
    echo "fuzz/run.sh: installing cargo-fuzz $CARGO_FUZZ_VERSION"
    cargo install cargo-fuzz --locked --version "$CARGO_FUZZ_VERSION"
fi

export RUSTC_BOOTSTRAP=1
target_dir="$PWD/target/fuzz"
build_options=(--fuzz-dir fuzz --target-dir "$target_dir" --codegen-units 16)

echo "-- building the fuzz targets"
cargo fuzz build "${build_options[@]}"

for target in ply ply_ascii_body ply_binary_body obj off xyz capi_load capi_arrays; do
    corpus="target/fuzz-corpus/$target"
    artifacts="target/fuzz-artifacts/$target/"
    mkdir -p "$corpus" "$artifacts"
    cp fuzz/seeds/"$target"/* "$corpus"/
    time=$seconds
    case $target in capi_*) time=$((2 * seconds)) ;; esac
    echo "-- fuzzing $target for ${time}s"
    log="target/fuzz-artifacts/$target.log"
    if ! cargo fuzz run "${build_options[@]}" "$target" "$corpus" -- \
        -max_total_time="$time" -max_len=4096 -rss_limit_mb=2048 -timeout=10 \
        -artifact_prefix="$artifacts" -print_final_stats=1 >"$log" 2>&1; then
        tail -n 60 "$log" >&2
        echo "fuzz/run.sh: $target failed; the input is in $artifacts" >&2
        exit 1
    fi
    grep -E '^stat::number_of_executed_units|^Done' "$log" | tr '\n' ' '
    echo "(corpus: $(ls "$corpus" | wc -l) inputs)"
done
