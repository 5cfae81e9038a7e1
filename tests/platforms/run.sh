#!/usr/bin/env bash
# Every platform of the Blender extension, built by plugins/blender/build.sh and checked:
#   linux-x64    needs no GLIBC symbol newer than 2.28; exports exactly the header's functions
#   windows-x64  a PE DLL exporting exactly the header's functions; the C API tests
#                (tests/c: test_api, test_bad_input, test_threads, test_cpp, the example)
#                cross-compiled with mingw-w64 and run under Wine
#   macos-*      Mach-O dylibs of the right CPU, exporting exactly the header's functions,
#                macOS 11 minimum, install name @rpath/libvstree.dylib
#   zips         one per platform, validated by blender_ext.py, with only that platform's
#                library and its platform in the manifest
# Installs the toolchain it needs (plugins/blender/toolchain.sh); the bpy venv that carries
# blender_ext.py is the one tests/blender/run.sh uses.
set -euo pipefail
cd "$(dirname "$0")/../.."
root=$PWD
source plugins/blender/toolchain.sh

fail() {
    echo "tests/platforms: $*" >&2
    exit 1
}

start=$(date +%s)
toolchain_install
# wine and wine64: the Windows test programs' runtime (64-bit only).
if ! command -v wine64 >/dev/null && [ ! -x /usr/lib/wine/wine64 ]; then
    echo "tests/platforms: installing wine from Debian"
    _vstree_sudo apt-get update -qq
    _vstree_sudo apt-get install -y -qq --no-install-recommends wine wine64 >/dev/null
fi
echo "-- toolchain ready in $(($(date +%s) - start)) s"

bpy_version=${VSTREE_BPY_VERSIONS:-4.2.23}
bpy_version=${bpy_version%% *}
venv=$root/target/blender-venv-$bpy_version
bash tests/blender/venv.sh "$bpy_version"
export PYTHON=$venv/bin/python
BLENDER_EXT_PY=$(ls "$venv"/lib/python3.11/site-packages/bpy/*/scripts/addons_core/bl_pkg/cli/blender_ext.py)
export BLENDER_EXT_PY

start=$(date +%s)
VSTREE_PLATFORMS=$VSTREE_PLATFORMS_ALL bash plugins/blender/build.sh
echo "-- four platforms built in $(($(date +%s) - start)) s"

declared=$(grep -o '\bvstree_[a-z0-9_]*(' include/vstree.h | tr -d '(' | sort -u)
same_as_header() { # $1 platform, stdin: exported names
    local exported
    exported=$(sort -u)
    if [ "$exported" != "$declared" ]; then
        echo "$1: exported symbols and header declarations differ (< header, > library):" >&2
        diff <(echo "$declared") <(echo "$exported") >&2 || true
        exit 1
    fi
    echo "   $1: exports the header's $(echo "$exported" | wc -l) vstree_* functions and nothing else"
}

echo "-- clippy for windows-x64 (the code behind cfg(not(unix)))"
cargo clippy --quiet --locked --lib --no-default-features --target x86_64-pc-windows-gnu -- -D warnings

echo "-- linux-x64: glibc 2.28"
so=target/x86_64-unknown-linux-gnu/release/libvstree.so
file -L "$so" | grep -q "ELF 64-bit LSB shared object, x86-64" || fail "$so: $(file -L "$so")"
glibc_max=$(objdump -T "$so" | grep -o 'GLIBC_[0-9][0-9.]*' | sed 's/GLIBC_//' | sort -uV | tail -n 1)
if [ "$(printf '%s\n2.28\n' "$glibc_max" | sort -V | tail -n 1)" != 2.28 ]; then
    echo "$so needs GLIBC_$glibc_max, newer than Blender's 2.28:" >&2
    objdump -T "$so" | grep -E "GLIBC_(2\.(29|[3-9][0-9])|[3-9])" >&2
    exit 1
fi
echo "   newest GLIBC symbol version needed: $glibc_max"
nm -D --defined-only "$so" | awk '$2 == "T" {print $3}' | same_as_header linux-x64

echo "-- windows-x64: PE DLL"
dll=target/x86_64-pc-windows-gnu/release/vstree.dll
file "$dll" | grep -q "PE32+ executable (DLL).*x86-64" || fail "$dll: $(file "$dll")"
x86_64-w64-mingw32-objdump -p "$dll" | sed -n '/^\[Ordinal\/Name Pointer\] Table/,/^$/p' \
    | sed -n 's/^\s*\[ *[0-9]*\] //p' | same_as_header windows-x64
echo "   imports: $(x86_64-w64-mingw32-objdump -p "$dll" | sed -n 's/^\s*DLL Name: //p' | sort | tr '\n' ' ')"

for platform in macos-arm64 macos-x64; do
    echo "-- $platform: Mach-O dylib"
    dylib=target/$(rust_target "$platform")/release/libvstree.dylib
    case $platform in
        macos-arm64) cpu=arm64 ;;
        macos-x64) cpu=x86_64 ;;
    esac
    file "$dylib" | grep -q "Mach-O 64-bit $cpu dynamically linked shared library" || fail "$dylib: $(file "$dylib")"
    llvm-nm --extern-only --defined-only --format=just-symbols "$dylib" | sed 's/^_//' | same_as_header "$platform"
    headers=$(llvm-objdump --macho --private-headers "$dylib")
    echo "$headers" | grep -A4 LC_BUILD_VERSION | grep -q "minos $VSTREE_MACOS_DEPLOYMENT_TARGET" \
        || fail "$dylib: minimum macOS is not $VSTREE_MACOS_DEPLOYMENT_TARGET"
    echo "$headers" | grep -A3 LC_ID_DYLIB | grep -q "name @rpath/libvstree.dylib " \
        || fail "$dylib: install name is not @rpath/libvstree.dylib"
    # Apple Silicon runs only signed code; the linker signs ad hoc.
    [ "$cpu" != arm64 ] || echo "$headers" | grep -q "cmd LC_CODE_SIGNATURE" || fail "$dylib: not signed"
    used=$(llvm-objdump --macho --dylibs-used "$dylib" | tail -n +3 | awk '{print $1}' | tr '\n' ' ')
    [ "$used" = "/usr/lib/libiconv.2.dylib /usr/lib/libSystem.B.dylib " ] \
        || fail "$dylib: links $used, not only macOS's libSystem and libiconv"
    echo "   macOS $VSTREE_MACOS_DEPLOYMENT_TARGET+, install name @rpath/libvstree.dylib, links $used"
done

echo "-- zips: one per platform, each with its own library"
version=$(sed -n 's/^version = "\([^"]*\)"$/\1/p' plugins/blender/vstree_blender/blender_manifest.toml)
for platform in $VSTREE_PLATFORMS_ALL; do
    zip=target/blender/dist/vstree-$version-${platform/-/_}.zip
    [ -f "$zip" ] || fail "$zip is missing"
    "$PYTHON" "$BLENDER_EXT_PY" validate "$zip" >/dev/null
    libs=$(unzip -Z1 "$zip" | grep -E '(\.so|\.dll|\.dylib)$' | tr '\n' ' ')
    [ "$libs" = "vstree/$(library_name "$platform") " ] || fail "$zip holds libraries '$libs'"
    unzip -p "$zip" blender_manifest.toml | grep -qx "platforms = \[\"$platform\"\]" \
        || fail "$zip: its manifest does not name $platform alone"
    echo "   $(basename "$zip"): $(du -k "$zip" | cut -f1) KiB, vstree/$(library_name "$platform") $(($(unzip -Z -l "$zip" "vstree/$(library_name "$platform")" | awk 'NR==1 {print $4}') / 1024)) KiB"
done

echo "-- windows-x64: the C API tests under Wine"
start=$(date +%s)
build=$root/target/windows-capi-tests
rm -rf "$build"
mkdir -p "$build/tmp/dir.ply" "$build/bad-input"
cp "$dll" "$build/"
warn="-Wall -Wextra -Werror -pedantic"
cargo_version=$(sed -n 's/^version = "\([^"]*\)"$/\1/p' Cargo.toml | head -n 1)
link=(-Iinclude -Ibindings/cpp -L"$(dirname "$dll")" -lvstree)
x86_64-w64-mingw32-gcc -std=c99 $warn -DEXPECTED_VERSION="\"$cargo_version\"" tests/c/test_api.c "${link[@]}" -lm \
    -o "$build/test_api.exe"
x86_64-w64-mingw32-gcc -std=c99 $warn tests/c/test_bad_input.c "${link[@]}" -lm -o "$build/test_bad_input.exe"
# winpthreads linked in, so the program needs no DLL beside vstree.dll and the system's.
x86_64-w64-mingw32-gcc -std=c99 $warn -pthread tests/c/test_threads.c "${link[@]}" -lm \
    -Wl,-Bstatic -lpthread -Wl,-Bdynamic -o "$build/test_threads.exe"
x86_64-w64-mingw32-g++ -std=c++11 $warn tests/c/test_cpp.cpp "${link[@]}" -static-libgcc -static-libstdc++ \
    -o "$build/test_cpp.exe"
x86_64-w64-mingw32-gcc -std=c99 $warn bindings/c/example.c "${link[@]}" -o "$build/example.exe"
# Wine 8.0 (Debian 12) lacks bcryptprimitives.dll, which Rust's standard library imports.
x86_64-w64-mingw32-gcc -shared -O2 $warn tests/platforms/wine_bcryptprimitives.c -ladvapi32 \
    -o "$build/bcryptprimitives.dll"

export WINEPREFIX=${VSTREE_WINEPREFIX:-${XDG_CACHE_HOME:-$HOME/.cache}/vstree/wine64}
export WINEDEBUG=-all WINEDLLOVERRIDES="mscoree,mshtml=" WINEARCH=win64
wine=$(command -v wine64 || echo /usr/lib/wine/wine64)
if [ ! -f "$WINEPREFIX/system.reg" ]; then
    mkdir -p "$WINEPREFIX"
    "$wine" wineboot --init </dev/null >/dev/null 2>&1 || true
fi
winpath() { echo "Z:${1//\//\\}"; }
win() { # runs a test program under Wine; its output goes to stdout, the status is returned
    (cd "$build" && "$wine" "$@" </dev/null 2>&1 | tr -d '\r')
    return "${PIPESTATUS[0]}"
}
output=$(win ./test_api.exe "$(winpath "$build/tmp")") || { echo "$output" >&2; fail "test_api.exe failed under Wine"; }
echo "$output" | tail -n 1
output=$(win ./test_bad_input.exe "$(winpath "$build/bad-input")") \
    || { echo "$output" >&2; fail "test_bad_input.exe failed under Wine"; }
echo "$output" | tail -n 1
output=$(win ./test_threads.exe) || { echo "$output" >&2; fail "test_threads.exe failed under Wine"; }
echo "$output" | tail -n 1
output=$(win ./test_cpp.exe "$(winpath "$build/tmp")") || { echo "$output" >&2; fail "test_cpp.exe failed under Wine"; }
echo "$output" | tail -n 1
output=$(win ./example.exe "$(winpath "$build/tmp/out.ply")" "$(winpath "$build/tmp/example-out.obj")" 5e-3) \
    || { echo "$output" >&2; fail "example.exe failed under Wine"; }
echo "$output" | tail -n 1
[ -s "$build/tmp/example-out.obj" ] || fail "example.exe wrote no OBJ"
if output=$(win ./example.exe "$(winpath "$build/tmp/missing.ply")" "$(winpath "$build/tmp/x.ply")"); then
    fail "example.exe should fail on a missing file"
fi
echo "$output" | grep -q "missing.ply" || fail "example.exe's error does not name the file: $output"
echo "   Wine $("$wine" --version 2>/dev/null | tr -d '\r'): 5 programs passed in $(($(date +%s) - start)) s"
echo "tests/platforms: every platform built and checked"
