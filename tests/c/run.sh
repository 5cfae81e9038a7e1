#!/usr/bin/env bash
# The C and C++ tests of the C API, built the way applications build: against the library,
# header, pkg-config file and CMake package that bindings/install.sh installs (into
# target/capi-install), with -Wall -Wextra -Werror -pedantic, and run under valgrind with
# --leak-check=full (zero errors, zero leaks; see valgrind.supp for the one exception).
set -euo pipefail
cd "$(dirname "$0")/../.."

# Tools a fresh Debian machine may lack: command -> Debian package.
missing=()
for tool in valgrind:valgrind cmake:cmake pkg-config:pkg-config readelf:binutils cc:gcc c++:g++; do
    command -v "${tool%%:*}" >/dev/null || missing+=("${tool#*:}")
done
if ((${#missing[@]})); then
    echo "tests/c: installing ${missing[*]} from Debian"
    sudo=""
    [ "$(id -u)" -eq 0 ] || sudo="sudo"
    $sudo apt-get update -qq && $sudo apt-get install -y -qq "${missing[@]}" >/dev/null
fi

prefix="$PWD/target/capi-install"
build="$PWD/target/capi-tests"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
rm -rf "$prefix" "$build"
mkdir -p "$build" "$tmp/dir.ply" "$tmp/bad-input"
bash bindings/install.sh "$prefix" >/dev/null
export PKG_CONFIG_PATH="$prefix/lib/pkgconfig"
export LD_LIBRARY_PATH="$prefix/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"

echo "-- versions: Cargo.toml, header, library, SONAME"
version=$(sed -n 's/^version = "\([^"]*\)"$/\1/p' Cargo.toml | head -n 1)
abi=$(sed -n 's/^#define VSTREE_ABI_VERSION \([0-9][0-9]*\)$/\1/p' include/vstree.h)
soname=$(readelf -d "$prefix/lib/libvstree.so" | sed -n 's/.*Library soname: \[\(.*\)\]/\1/p')
if [ "$soname" != "libvstree.so.$abi" ]; then
    echo "SONAME is '$soname', the header's ABI version says libvstree.so.$abi" >&2
    exit 1
fi
if [ "$(pkg-config --modversion vstree)" != "$version" ]; then
    echo "pkg-config says $(pkg-config --modversion vstree), Cargo.toml $version" >&2
    exit 1
fi
exports=$(nm -D --defined-only "$prefix/lib/libvstree.so" | awk '$2 == "T" {print $3}')
if echo "$exports" | grep -v '^vstree_' >/dev/null; then
    echo "the library exports symbols outside the vstree_ namespace:" >&2
    echo "$exports" | grep -v '^vstree_' >&2
    exit 1
fi
declared=$(grep -o '\bvstree_[a-z0-9_]*(' include/vstree.h | tr -d '(' | sort -u)
if [ "$declared" != "$(echo "$exports" | sort -u)" ]; then
    echo "exported symbols and header declarations differ:" >&2
    diff <(echo "$declared") <(echo "$exports" | sort -u) >&2 || true
    exit 1
fi
echo "   $version, ABI $abi, $soname, $(echo "$exports" | wc -l) exported functions"

echo "-- compile (-Wall -Wextra -Werror -pedantic) against the installed header"
warn="-Wall -Wextra -Werror -pedantic -g"
cflags=$(pkg-config --cflags vstree)
libs=$(pkg-config --libs vstree)
for std in c99 c11; do
    echo '#include <vstree.h>' | cc -std=$std $warn $cflags -x c -c - -o /dev/null
done
for std in c++11 c++17; do
    echo '#include <vstree.hpp>' | c++ -std=$std $warn $cflags -x c++ -c - -o /dev/null
done
cc -std=c99 $warn -DEXPECTED_VERSION="\"$version\"" $cflags tests/c/test_api.c $libs -lm \
    -o "$build/test_api"
cc -std=c99 $warn $cflags tests/c/test_bad_input.c $libs -lm -o "$build/test_bad_input"
cc -std=c99 $warn -pthread $cflags tests/c/test_threads.c $libs -lm -o "$build/test_threads"
c++ -std=c++11 $warn $cflags tests/c/test_cpp.cpp $libs -o "$build/test_cpp"
cc -std=c99 $warn $cflags bindings/c/example.c $libs -o "$build/example"

memcheck() {
    valgrind -q --error-exitcode=1 --leak-check=full --errors-for-leak-kinds=definite,possible \
        --suppressions=tests/c/valgrind.supp "$@"
}

echo "-- run under valgrind"
memcheck "$build/test_api" "$tmp"
memcheck "$build/test_bad_input" "$tmp/bad-input"
memcheck "$build/test_threads"
memcheck "$build/test_cpp" "$tmp"
memcheck "$build/example" "$tmp/out.ply" "$tmp/example-out.obj" 5e-3 2>"$tmp/example.log" \
    || { cat "$tmp/example.log" >&2; exit 1; }
tail -n 1 "$tmp/example.log"
if memcheck "$build/example" "$tmp/missing.ply" "$tmp/x.ply" 2>"$tmp/example.log"; then
    echo "the example should fail on a missing file" >&2
    exit 1
fi
grep -q "missing.ply" "$tmp/example.log"

echo "-- a program linked against target/release runs from there (libvstree.so.$abi link)"
cc -std=c99 $warn -Iinclude bindings/c/example.c -Ltarget/release -lvstree -o "$build/example-local"
LD_LIBRARY_PATH="$PWD/target/release" "$build/example-local" "$tmp/out.ply" "$tmp/example-local.obj" 5e-3 \
    2>"$tmp/example-local.log" || { cat "$tmp/example-local.log" >&2; exit 1; }
LD_LIBRARY_PATH="$PWD/target/release" ldd "$build/example-local" | grep "libvstree.so.$abi => $PWD/target/release/libvstree.so.$abi" >/dev/null

echo "-- find_package(vstree) from CMake"
cmake -S tests/c/cmake -B "$build/cmake" -DCMAKE_PREFIX_PATH="$prefix" -DVSTREE_WANTED="${version%.*}" >/dev/null
# Before 1.0 a minor release may break the API, so the package refuses an application written
# for the previous minor version.
major=${version%%.*}
minor=$(echo "$version" | cut -d. -f2)
if [ "$major" = 0 ] && [ "$minor" -gt 0 ] && cmake -S tests/c/cmake -B "$build/cmake-previous" \
    -DCMAKE_PREFIX_PATH="$prefix" -DVSTREE_WANTED="0.$((minor - 1))" >/dev/null 2>&1; then
    echo "find_package(vstree 0.$((minor - 1))) accepted version $version" >&2
    exit 1
fi
cmake --build "$build/cmake" >/dev/null
"$build/cmake/vstree-wrapper"
"$build/cmake/vstree-example" "$tmp/out.off" "$tmp/cmake-out.ply" 2>/dev/null
echo "C API tests passed"
