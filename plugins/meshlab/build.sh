#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Builds the vstree MeshLab filter plugin for one pymeshlab host version, from scratch and pinned:
#   1. apt packages (only the missing ones), 2. MeshLab orig tarball (sha256-checked),
#   3. its src/common + src/vcglib headers, 4. a venv with the hash-pinned pymeshlab wheel,
#   5. libvstree (bindings/install.sh), 6. cmake build, 7. package
#   target/meshlab/<ver>/vstree-meshlab-<ver>.tar.gz (plugin .so + libvstree.so.0).
# No MeshLab source is kept in the repository; everything goes under target/meshlab/.
#
# usage: plugins/meshlab/build.sh <2022.2.post4|2025.7.post1>
#        HEADERS_ONLY=1 plugins/meshlab/build.sh 2020.09   (Debian 12's desktop MeshLab: there is
#        no pymeshlab wheel of it, only its headers; tests/hosts/meshlab2020.sh builds the plugin)
# env:   ML_FETCH=pool (default: Debian pool path) | apt (apt-get source with a temporary deb-src)
#        JOBS=2   SKIP_APT=1 (do not touch apt)   VSTREE_NO_BUILD=1 (reuse target/release)
#        HEADERS_ONLY=1: steps 2-3 only (tests/hosts builds against desktop MeshLab's own library)
# Target: Debian 12 bookworm amd64 with python3 3.11; apt needs root.
set -euo pipefail

VER="${1:-}"
HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
ROOT="$(cd "$HERE/../.." && pwd)"
JOBS="${JOBS:-2}"
ML_FETCH="${ML_FETCH:-pool}"
DEBIAN_MIRROR="${DEBIAN_MIRROR:-http://deb.debian.org/debian}"

VCGLIB_GLOB='*/src/vcglib/*'
case "$VER" in
2020.09)
	DEB_SRC_VERSION="2020.09+dfsg1-2"
	DEB_SUITE="bookworm"
	ORIG="meshlab_2020.09+dfsg1.orig.tar.xz"
	ORIG_SHA256="d6715352ff65caffdec0292858d4263eb0c3cbbf3b1e5c2e2bab218e3f234630"
	ORIG_SIZE=11594932
	ML_VERSION_FILE="2020.09"
	VCGLIB_GLOB='*/vcglib/*' # beside src/ in 2020.09
	if [ "${HEADERS_ONLY:-0}" != 1 ]; then
		echo "$0: 2020.09 is headers only (HEADERS_ONLY=1): there is no pymeshlab wheel of it" >&2
		exit 2
	fi
	;;
2022.2.post4)
	DEB_SRC_VERSION="2022.02+dfsg1-1"
	DEB_SUITE="trixie"
	ORIG="meshlab_2022.02+dfsg1.orig.tar.xz"
	ORIG_SHA256="11da26ec46c3fbbbc806d410a3221542ec21ec13fdcc55d624304600029435fd"
	ORIG_SIZE=6881132
	ML_VERSION_FILE="2022.02"
	MESHLAB_VERSION="2022.02d"
	WHEEL_SHA256="7d136ae936b0c0dc8b64abb50ad9d5adb6671985e6ef57a6b67d718fa684803f"
	NUMPY="1.26.4" # pymeshlab 2022.2.post4 segfaults with numpy 2.x
	NUMPY_SHA256="666dbfb6ec68962c033a450943ded891bed2d54e6755e35e5835d63f4f6931d5"
	;;
2025.7.post1)
	DEB_SRC_VERSION="2025.07~dfsg-4"
	DEB_SUITE="sid"
	ORIG="meshlab_2025.07~dfsg.orig.tar.xz"
	ORIG_SHA256="d22c98d362f2a284e481af8dbfc272b2222f5b9c67b3cf8bec57d1c3161886f4"
	ORIG_SIZE=5040072
	ML_VERSION_FILE="2025.07"
	MESHLAB_VERSION="2025.07d"
	WHEEL_SHA256="c3c1b01f101334b14469ace3b004382cd313b80a128f551a1da77e3053f09c30"
	NUMPY="2.4.6"
	NUMPY_SHA256="89cd468399cfd2504718f0ba50e410dca55a170b61a02ad92bb18c8a65186e93"
	;;
*)
	echo "usage: $0 <2022.2.post4|2025.7.post1>, or HEADERS_ONLY=1 $0 2020.09" >&2
	exit 2
	;;
esac

TGT="$ROOT/target/meshlab"
OUT="$TGT/$VER"
DL="$TGT/dl"
SRC="$TGT/src/meshlab-$ML_VERSION_FILE"
VENV="$OUT/venv"
BUILD="$OUT/build"
VSTREE_PREFIX="$TGT/vstree-prefix"
T0=$SECONDS
step() { echo "=== [$((SECONDS - T0))s] $*"; }

step "1/7 apt packages"
PKGS=(ca-certificates curl xz-utils g++ make cmake
	qtbase5-dev libqt5opengl5-dev libglew-dev libeigen3-dev
	python3 python3-venv libgl1 libopengl0 libx11-6 libxcb1 libfontconfig1 libfreetype6)
if [ "${SKIP_APT:-0}" != 1 ] && [ "${HEADERS_ONLY:-0}" != 1 ]; then
	missing=()
	for p in "${PKGS[@]}"; do
		dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
	done
	if [ ${#missing[@]} -gt 0 ]; then
		export DEBIAN_FRONTEND=noninteractive
		apt-get update
		apt-get install -y --no-install-recommends "${missing[@]}"
	fi
fi

step "2/7 MeshLab orig tarball $ORIG ($DEB_SRC_VERSION)"
mkdir -p "$DL"
have_orig() { [ -f "$DL/$ORIG" ] && echo "$ORIG_SHA256  $DL/$ORIG" | sha256sum -c --quiet - 2>/dev/null; }
if ! have_orig; then
	if [ "$ML_FETCH" = apt ]; then
		SRCLIST=/etc/apt/sources.list.d/zz-vstree-meshlab-src.sources
		cleanup_src() { rm -f "$SRCLIST"; apt-get update -qq || true; }
		trap cleanup_src EXIT
		printf 'Types: deb-src\nURIs: %s\nSuites: %s\nComponents: main\nSigned-By: /usr/share/keyrings/debian-archive-keyring.gpg\n' \
			"$DEBIAN_MIRROR" "$DEB_SUITE" >"$SRCLIST"
		apt-get update -qq
		# .dsc/.debian.tar.xz may be unavailable: the sha256 check below decides
		(cd "$DL" && apt-get source --download-only "meshlab=$DEB_SRC_VERSION") || true
		cleanup_src
		trap - EXIT
	else
		url="$DEBIAN_MIRROR/pool/main/m/meshlab/$(printf '%s' "$ORIG" | sed 's/~/%7e/g; s/+/%2b/g')"
		curl -fsSL --retry 3 -o "$DL/$ORIG.part" "$url"
		mv "$DL/$ORIG.part" "$DL/$ORIG"
	fi
fi
have_orig || { echo "sha256 mismatch or missing: $DL/$ORIG (want $ORIG_SHA256)" >&2; exit 1; }
[ "$(stat -c %s "$DL/$ORIG")" = "$ORIG_SIZE" ] || { echo "size mismatch: $DL/$ORIG" >&2; exit 1; }

step "3/7 headers -> $SRC"
if [ ! -f "$SRC/.unpacked-$ORIG_SHA256" ]; then
	rm -rf "$SRC"
	mkdir -p "$SRC"
	tar -xJf "$DL/$ORIG" -C "$SRC" --strip-components=1 --wildcards \
		'*/ML_VERSION' '*/src/common/*' "$VCGLIB_GLOB"
	touch "$SRC/.unpacked-$ORIG_SHA256"
fi
[ "$(tr -d '[:space:]' <"$SRC/ML_VERSION")" = "$ML_VERSION_FILE" ] || { echo "bad ML_VERSION in $SRC" >&2; exit 1; }
if [ "${HEADERS_ONLY:-0}" = 1 ]; then
	echo "=== headers of MeshLab $ML_VERSION_FILE ($DEB_SRC_VERSION): $SRC"
	exit 0
fi

step "4/7 venv + pymeshlab==$VER (hash-pinned)"
mkdir -p "$OUT"
[ -x "$VENV/bin/python" ] || /usr/bin/python3 -m venv "$VENV"
REQ="$OUT/requirements-pinned.txt"
printf 'pymeshlab==%s --hash=sha256:%s\nnumpy==%s --hash=sha256:%s\n' \
	"$VER" "$WHEEL_SHA256" "$NUMPY" "$NUMPY_SHA256" >"$REQ"
"$VENV/bin/pip" install --disable-pip-version-check -q --only-binary=:all: --require-hashes -r "$REQ"
MLLIB="$("$VENV/bin/python" -c 'import importlib.util,os; print(os.path.dirname(importlib.util.find_spec("pymeshlab").origin))')/lib"
[ -f "$MLLIB/libmeshlab-common.so" ] || { echo "no $MLLIB/libmeshlab-common.so" >&2; exit 1; }
grep -aq "$MESHLAB_VERSION" "$MLLIB/libmeshlab-common.so" || { echo "libmeshlab-common.so is not $MESHLAB_VERSION" >&2; exit 1; }

step "5/7 libvstree -> $VSTREE_PREFIX"
(cd "$ROOT" && bash bindings/install.sh "$VSTREE_PREFIX" >/dev/null)

step "6/7 cmake build"
cmake -S "$HERE" -B "$BUILD" -DCMAKE_BUILD_TYPE=Release \
	-DMESHLAB_SRC_DIR="$SRC" -DMESHLAB_LIB_DIR="$MLLIB" -DMESHLAB_VERSION="$MESHLAB_VERSION" \
	-DMESHLAB_SCALAR=double -DVSTREE_PREFIX="$VSTREE_PREFIX" >/dev/null
cmake --build "$BUILD" -j "$JOBS" >/dev/null

step "7/7 package"
PKG="$OUT/pkg"
rm -rf "$PKG"
mkdir -p "$PKG"
cp "$BUILD/libfilter_vstree.so" "$PKG/"
cp -L "$VSTREE_PREFIX/lib/libvstree.so.0" "$PKG/libvstree.so.0"
readelf -d "$PKG/libfilter_vstree.so" | grep -q 'RUNPATH.*\$ORIGIN' || { echo "plugin lacks RUNPATH \$ORIGIN" >&2; exit 1; }
# every undefined symbol must resolve against the wheel's libs and the bundled libvstree
if LD_LIBRARY_PATH="$MLLIB" ldd -r "$PKG/libfilter_vstree.so" 2>&1 | grep -E 'undefined symbol|not found'; then
	echo "plugin has symbols/libs not provided by the pymeshlab wheel or libvstree" >&2
	exit 1
fi
tar -C "$PKG" -czf "$OUT/vstree-meshlab-$VER.tar.gz" libfilter_vstree.so libvstree.so.0
echo "=== done in $((SECONDS - T0))s: $OUT/vstree-meshlab-$VER.tar.gz ($(stat -c %s "$OUT/vstree-meshlab-$VER.tar.gz") bytes)"
echo "plugin: $PKG/libfilter_vstree.so"
