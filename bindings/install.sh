#!/usr/bin/env bash
# Builds the C library in release mode and installs it for C/C++ applications:
#   PREFIX/lib/libvstree.so.X.Y.Z, the SONAME link libvstree.so.ABI and the link libvstree.so,
#   PREFIX/include/vstree.h and vstree.hpp,
#   PREFIX/lib/pkgconfig/vstree.pc            (pkg-config --cflags --libs vstree)
#   PREFIX/lib/cmake/vstree/vstreeConfig.cmake (find_package(vstree) -> vstree::vstree)
#
# Usage: bindings/install.sh PREFIX      e.g. bindings/install.sh /usr/local (as root)
#                                              bindings/install.sh "$HOME/.local"
# Set VSTREE_NO_BUILD=1 to install an existing target/release build.
set -euo pipefail

if [ $# -ne 1 ]; then
    echo "usage: $0 PREFIX" >&2
    exit 2
fi
mkdir -p "$1"
prefix=$(cd "$1" && pwd)
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"

version=$(sed -n 's/^version = "\([^"]*\)"$/\1/p' Cargo.toml | head -n 1)
abi=$(sed -n 's/^#define VSTREE_ABI_VERSION \([0-9][0-9]*\)$/\1/p' include/vstree.h)
if [ -z "$version" ] || [ -z "$abi" ]; then
    echo "$0: cannot read the version from Cargo.toml or include/vstree.h" >&2
    exit 1
fi

if [ "${VSTREE_NO_BUILD:-0}" != 1 ]; then
    cargo build --release --locked --lib --no-default-features
fi

libdir="$prefix/lib"
install -d "$libdir" "$prefix/include" "$libdir/pkgconfig" "$libdir/cmake/vstree"
case "$(uname -s)" in
    Darwin)
        real="libvstree.$version.dylib"
        soname="libvstree.$abi.dylib"
        link="libvstree.dylib"
        install -m 755 target/release/libvstree.dylib "$libdir/$real"
        install_name_tool -id "$libdir/$soname" "$libdir/$real"
        ;;
    *)
        real="libvstree.so.$version"
        soname="libvstree.so.$abi"
        link="libvstree.so"
        install -m 755 target/release/libvstree.so "$libdir/$real"
        ;;
esac
ln -sf "$real" "$libdir/$soname"
ln -sf "$soname" "$libdir/$link"
install -m 644 include/vstree.h bindings/cpp/vstree.hpp "$prefix/include/"

subst() {
    sed -e "s|@PREFIX@|$prefix|g" -e "s|@VERSION@|$version|g" -e "s|@ABI@|$abi|g" \
        -e "s|@LIBFILE@|$real|g" -e "s|@SONAME@|$soname|g" "$1"
}
subst bindings/pkgconfig/vstree.pc.in >"$libdir/pkgconfig/vstree.pc"
subst bindings/cmake/vstreeConfig.cmake.in >"$libdir/cmake/vstree/vstreeConfig.cmake"
subst bindings/cmake/vstreeConfigVersion.cmake.in >"$libdir/cmake/vstree/vstreeConfigVersion.cmake"

echo "installed vstree $version (ABI $abi) in $prefix"
