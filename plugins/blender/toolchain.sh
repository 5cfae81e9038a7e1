# Cross-build toolchain of the Blender extension, sourced by plugins/blender/build.sh and
# tests/platforms/run.sh. Pins every version, looks for the tools, and installs them when asked
# (toolchain_install; tests/platforms/run.sh does, and CI).
#
#   linux-x64    cargo-zigbuild + zig (PyPI ziglang), target x86_64-unknown-linux-gnu.2.28,
#                so the library runs on glibc 2.28 like Blender's own Linux builds
#   windows-x64  rustup target x86_64-pc-windows-gnu, linked by Debian's mingw-w64 gcc
#   macos-*      rustup targets aarch64/x86_64-apple-darwin, linked by rustup's rust-lld
#                (ld64.lld) against the macOS libSystem stubs (.tbd) that the ziglang package
#                carries; zig's own Mach-O linker ignores the exported-symbols list, so the
#                dylib would export every Rust symbol
#
# The Python tools live in a virtual environment under ~/.cache (named by the pinned versions,
# rebuilt when missing), never in the clone.

ZIGLANG_VERSION=0.15.2
CARGO_ZIGBUILD_VERSION=0.24.1
# Blender 4.2 needs macOS 11.2 on both architectures.
VSTREE_MACOS_DEPLOYMENT_TARGET=11.0

VSTREE_PLATFORMS_ALL="linux-x64 windows-x64 macos-arm64 macos-x64"
VSTREE_TOOLS=${VSTREE_TOOLS:-${XDG_CACHE_HOME:-$HOME/.cache}/vstree/cross-zig$ZIGLANG_VERSION-zigbuild$CARGO_ZIGBUILD_VERSION}

# Debian packages the builds and checks use: command -> package.
_vstree_debian_tools="x86_64-w64-mingw32-gcc:gcc-mingw-w64-x86-64 x86_64-w64-mingw32-g++:g++-mingw-w64-x86-64
    objdump:binutils llvm-nm:llvm llvm-objdump:llvm file:file unzip:unzip"

rust_target() {
    case $1 in
        linux-x64) echo x86_64-unknown-linux-gnu ;;
        windows-x64) echo x86_64-pc-windows-gnu ;;
        macos-arm64) echo aarch64-apple-darwin ;;
        macos-x64) echo x86_64-apple-darwin ;;
        *) echo "unknown platform '$1' (known: $VSTREE_PLATFORMS_ALL)" >&2; return 1 ;;
    esac
}

library_name() {
    case $1 in
        linux-*) echo libvstree.so ;;
        windows-*) echo vstree.dll ;;
        macos-*) echo libvstree.dylib ;;
    esac
}

_vstree_sudo() {
    if [ "$(id -u)" -eq 0 ]; then "$@"; else sudo "$@"; fi
}

# Installs what is missing: Debian packages, rustup targets, the pinned Python tools.
toolchain_install() {
    local missing=() tool
    for tool in $_vstree_debian_tools; do
        command -v "${tool%%:*}" >/dev/null || missing+=("${tool#*:}")
    done
    if ((${#missing[@]})); then
        echo "toolchain: installing ${missing[*]} from Debian"
        _vstree_sudo apt-get update -qq
        _vstree_sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
    fi
    local installed p t
    installed=$(rustup target list --installed)
    for p in $VSTREE_PLATFORMS_ALL; do
        t=$(rust_target "$p")
        echo "$installed" | grep -qx "$t" || rustup target add "$t"
    done
    if [ ! -x "$VSTREE_TOOLS/bin/cargo-zigbuild" ]; then
        echo "toolchain: ziglang $ZIGLANG_VERSION and cargo-zigbuild $CARGO_ZIGBUILD_VERSION into $VSTREE_TOOLS"
        rm -rf "$VSTREE_TOOLS"
        python3 -m venv "$VSTREE_TOOLS"
        "$VSTREE_TOOLS/bin/python" -m pip install --quiet --disable-pip-version-check \
            "ziglang==$ZIGLANG_VERSION" "cargo-zigbuild==$CARGO_ZIGBUILD_VERSION"
    fi
}

# Fails with what to install when a tool for the given platforms is missing; puts the tool
# environment on PATH (cargo-zigbuild finds zig as `python3 -m ziglang` there).
toolchain_check() {
    local problems=() p installed
    installed=$(rustup target list --installed 2>/dev/null || true)
    for p in "$@"; do
        echo "$installed" | grep -qx "$(rust_target "$p")" || problems+=("rustup target $(rust_target "$p")")
        case $p in
            windows-*) command -v x86_64-w64-mingw32-gcc >/dev/null || problems+=("Debian gcc-mingw-w64-x86-64") ;;
            *) [ -x "$VSTREE_TOOLS/bin/cargo-zigbuild" ] || problems+=("ziglang/cargo-zigbuild in $VSTREE_TOOLS") ;;
        esac
    done
    if ((${#problems[@]})); then
        printf 'missing: %s\n' "${problems[@]}" | sort -u >&2
        echo "install them with: VSTREE_INSTALL_TOOLS=1 bash plugins/blender/build.sh" >&2
        return 1
    fi
    export PATH="$VSTREE_TOOLS/bin:$PATH"
}

# A folder that rustc and ld64.lld take as the macOS SDK (SDKROOT): zig's libSystem stubs,
# libc/libm as the same file (as in Apple's SDK), and an empty libiconv stub, which Rust's
# standard library links (/usr/lib/libiconv.2.dylib is on every macOS).
macos_sdk_stub() {
    local sdk=$1 zig_dir
    zig_dir=$("$VSTREE_TOOLS/bin/python" -c 'import ziglang, os; print(os.path.dirname(ziglang.__file__))')
    rm -rf "$sdk"
    mkdir -p "$sdk/usr/lib"
    cp "$zig_dir/lib/libc/darwin/libSystem.tbd" "$sdk/usr/lib/"
    cp "$zig_dir/lib/libc/darwin/SDKSettings.json" "$sdk/"
    ln -s libSystem.tbd "$sdk/usr/lib/libc.tbd"
    ln -s libSystem.tbd "$sdk/usr/lib/libm.tbd"
    cat >"$sdk/usr/lib/libiconv.tbd" <<'EOF'
--- !tapi-tbd
tbd-version:     4
targets:         [ x86_64-macos, arm64-macos ]
install-name:    '/usr/lib/libiconv.2.dylib'
current-version: 7
compatibility-version: 7
...
EOF
}

# Builds the C library for one platform; prints the path of the result.
build_library() {
    local platform=$1 target out
    target=$(rust_target "$platform")
    local cargo_args=(--release --locked --lib --no-default-features --quiet)
    case $platform in
        linux-x64)
            cargo zigbuild "${cargo_args[@]}" --target "$target.2.28" >&2
            ;;
        windows-x64)
            cargo build "${cargo_args[@]}" --target "$target" \
                --config "target.$target.linker=\"x86_64-w64-mingw32-gcc\"" \
                --config 'profile.release.strip="symbols"' >&2  # mingw keeps a symbol table, 2 MB
            ;;
        macos-*)
            local sdk=$PWD/target/macos-sdk-stub-zig$ZIGLANG_VERSION
            [ -f "$sdk/usr/lib/libSystem.tbd" ] || macos_sdk_stub "$sdk"
            SDKROOT=$sdk MACOSX_DEPLOYMENT_TARGET=$VSTREE_MACOS_DEPLOYMENT_TARGET \
                cargo build "${cargo_args[@]}" --target "$target" \
                --config "target.$target.linker=\"rust-lld\"" \
                --config "target.$target.rustflags=[\"-Clinker-flavor=ld64.lld\", \"-Clink-arg=-install_name\", \"-Clink-arg=@rpath/libvstree.dylib\"]" >&2
            ;;
    esac
    out=$PWD/target/$target/release/$(library_name "$platform")
    [ -f "$out" ] || { echo "build_library: $out was not made" >&2; return 1; }
    echo "$out"
}
