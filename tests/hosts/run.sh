#!/usr/bin/env bash
# The plugins in the desktop applications users open, under Xvfb with Mesa's software OpenGL.
#   debian13: Blender 4.3.2 and MeshLab 2022.02, the packages of Debian 13 (trixie), pinned.
#   debian12: MeshLab 2020.09, Debian 12's package, on the host itself when it is Debian 12
#             (tests/hosts/meshlab2020.sh: the plugin built for 2020.09's interface,
#             meshlabserver applies both filters from .mlx scripts; skipped on other hosts).
#   sid:      Blender and MeshLab of Debian unstable, not pinned (the versions are printed); a
#             chroot that cannot be built (mirror churn) is reported as skipped with the reason.
# Each system is a chroot made with mmdebstrap from Debian's mirror and kept outside the clone,
# under ~/.cache/vstree/chroots/<system> (rebuilt when missing or when its recipe below changes;
# sid's also when older than a week).
#   Blender: the linux-x64 extension zip (plugins/blender/build.sh) installed with Blender's own
#     command line, the three operators in `blender -b` (tests/hosts/blender_batch.py), then the
#     GUI under Xvfb (tests/hosts/blender_gui.py): the modal operators, their progress, Esc, the
#     sidebar (screenshot).
#   MeshLab: the plugin built inside the chroot against the package's libmeshlab-common and the
#     headers of the same MeshLab version (plugins/meshlab/build.sh fetches and checks them),
#     copied into the package's plugin folder; desktop MeshLab opens a model, the Filters menu is
#     driven with xdotool, a VS-Tree filter runs and its new layer is exported and checked
#     (screenshots of the menu and the dialog).
# Installs what it needs on the host (Debian 12 or later, as root). Each check prints ok/FAIL;
# the last line is "N passed, M failed" and the status is non-zero when anything failed.
# env: DEBIAN_MIRROR (default http://deb.debian.org/debian), JOBS=2,
#      VSTREE_HOSTS_SYSTEMS="debian13 sid debian12" (the default: all three),
#      VSTREE_HOSTS_APPS="blender meshlab" (the default: both),
#      VSTREE_HOSTS_SCREENSHOTS=1 copies Debian 13's screenshots into docs/images/ (they always
#      go to target/hosts/shots/).
# shellcheck disable=SC2016 # dpkg-query formats, sed patterns and the hook are meant literally
set -euo pipefail
cd "$(dirname "$0")/../.."
root=$PWD
T0=$SECONDS
JOBS=${JOBS:-2}
mirror=${DEBIAN_MIRROR:-http://deb.debian.org/debian}
cache=${XDG_CACHE_HOME:-$HOME/.cache}/vstree/chroots
work=$root/target/hosts
data=${VSTREE_DATA:-$(cd "$root/.." && pwd)/shared/data}
systems=" ${VSTREE_HOSTS_SYSTEMS:-debian13 sid debian12} "
apps=" ${VSTREE_HOSTS_APPS:-blender meshlab} "

# Debian 13 packages under test, pinned.
D13_BLENDER=4.3.2+dfsg-2
D13_MESHLAB=2022.02+dfsg1-1
# Debian's Blender runs on the system Python and, unlike Blender's own builds, brings no numpy
# (neither Depends nor Recommends); the extension needs it. `apt install meshlab` brings its
# Recommends, which mmdebstrap leaves out: without them MeshLab opens with a dialog about the
# plugins that need lib3ds, muparser and openctm.
D13_RUN="python3-numpy chemical-mime-data lib3ds-1-3 libmpfr6 libmuparser2v5 libopenctm1 libqhull-r8.0 libxerces-c3.2t64"
# The plugin's build dependencies (the same Qt 5 the package runs on).
BUILD_DEPS="g++ make cmake qtbase5-dev libqt5opengl5-dev libglew-dev libeigen3-dev"

step() { echo "== [$((SECONDS - T0)) s] $*"; }
# shellcheck source=tests/hosts/meshlab_scalar.sh
source tests/hosts/meshlab_scalar.sh

if [ "$(id -u)" -ne 0 ]; then
    echo "tests/hosts/run.sh: needs root (mmdebstrap, chroot, mounts)" >&2
    exit 1
fi

rm -rf "$work"
mkdir -p "$work/shots"
results=$work/results.txt
: >"$results"
pass() {
    echo "ok   $*"
    echo "PASS $*" >>"$results"
}
fail() {
    echo "FAIL $*" >&2
    echo "FAIL $*" >>"$results"
}
skip() {
    echo "SKIP $*"
    echo "SKIP $*" >>"$results"
}
# Under CI (or with VSTREE_DATA set) the shared models must be there: their checks are not skipped.
if [ ! -d "$data" ] && { [ -n "${CI:-}" ] || [ -n "${VSTREE_DATA:-}" ]; }; then
    fail "no $data, and CI or VSTREE_DATA says the shared models must be there"
fi
summary() {
    local p f s
    p=$(grep -c '^PASS' "$results" || true)
    f=$(grep -c '^FAIL' "$results" || true)
    s=$(grep -c '^SKIP' "$results" || true)
    echo "== tests/hosts: done in $((SECONDS - T0)) s"
    grep '^SKIP' "$results" || true
    echo "$p passed, $f failed$([ "$s" -eq 0 ] || echo ", $s skipped")"
    [ "$f" -eq 0 ] && [ "$p" -gt 0 ]
}

step "host packages"
host_pkgs=(mmdebstrap debian-archive-keyring xvfb xauth xdotool imagemagick x11-apps x11-utils libgl1-mesa-dri
    curl xz-utils ca-certificates python3 util-linux binutils)
missing=()
for p in "${host_pkgs[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
    echo "installing ${missing[*]}"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# --- chroots --------------------------------------------------------------------------------
# make_chroot NAME SUITE PACKAGES [MAX_AGE_DAYS [APT_OPTION]]: $cache/NAME, rebuilt when
# missing, when its recipe changed or when older than MAX_AGE_DAYS.
make_chroot() {
    local name=$1 suite=$2 pkgs=$3 max_age=${4:-} aptopt=${5:-} dir recipe t
    dir=$cache/$name
    # /etc/mtab: Blender lists the mounted file systems for its file browser.
    local hook='ln -sf ../proc/self/mounts "$1/etc/mtab"'
    local opts=(--variant=apt --include="${pkgs// /,}" --customize-hook="$hook")
    [ -z "$aptopt" ] || opts+=(--aptopt="$aptopt")
    recipe="mmdebstrap ${opts[*]} $suite $mirror"
    if [ -f "$dir/.vstree-recipe" ] && [ "$(cat "$dir/.vstree-recipe")" = "$recipe" ] &&
        { [ -z "$max_age" ] || [ -z "$(find "$dir/.vstree-recipe" -mtime "+$max_age")" ]; }; then
        echo "chroot $dir: reused ($(du -sh "$dir" | cut -f1), made $(date -r "$dir/.vstree-recipe" +%F))"
        return 0
    fi
    # Mounts are only ever made in private mount namespaces (chroot_run), so none can be left
    # under $dir; check anyway before deleting.
    if grep -q " $cache/" /proc/mounts; then
        echo "something is mounted under $cache; not deleting" >&2
        return 1
    fi
    rm -rf "$dir" "$dir.new"
    mkdir -p "$cache"
    t=$SECONDS
    echo "chroot $dir: building: $recipe"
    # A mirror being updated can fail a download: three tries.
    local try ok=0
    for try in 1 2 3; do
        rm -rf "$dir.new"
        if nice -n 10 mmdebstrap "${opts[@]}" "$suite" "$dir.new" "$mirror" >"$work/mmdebstrap-$name.log" 2>&1; then
            ok=1
            break
        fi
        echo "mmdebstrap failed (try $try of 3):" >&2
        grep -E "^E:|Err:|Hash Sum|mismatch" "$work/mmdebstrap-$name.log" | head -n 10 >&2 || true
        # A mirror that serves a suite's Release after its Valid-Until date (a stale mirror or
        # snapshot: unstable's Release is valid for a week) is taken as it is, said aloud; the
        # signature is still checked.
        if grep -q "InRelease is expired" "$work/mmdebstrap-$name.log" &&
            [[ " ${opts[*]} " != *Check-Valid-Until* ]]; then
            echo "WARNING: $(grep -o "Release file for .* is expired ([^)]*)" "$work/mmdebstrap-$name.log" | head -n 1);" \
                "building from it anyway (Acquire::Check-Valid-Until false)" >&2
            opts+=(--aptopt='Acquire::Check-Valid-Until "false"')
            continue
        fi
        [ "$try" = 3 ] || sleep 20
    done
    if [ "$ok" != 1 ]; then
        tail -n 30 "$work/mmdebstrap-$name.log" >&2
        rm -rf "$dir.new"
        return 1
    fi
    echo "$recipe" >"$dir.new/.vstree-recipe"
    mv "$dir.new" "$dir"
    echo "chroot $dir: built in $((SECONDS - t)) s, $(du -sh "$dir" | cut -f1)"
}

# "${chroot_cmd[@]}" DIR HOME COMMAND...: runs COMMAND in the chroot, in a private mount
# namespace (the mounts vanish with it): /proc, /sys, /dev, a tmpfs /tmp with the X socket,
# the project at /vstree and ../shared/data read-only at /shared-data when it exists; HOME is
# a folder of the project's target/hosts. The process is the command itself (unshare, bash,
# chroot and env exec each other), so $! of a background "${chroot_cmd[@]}" ... & is its pid.
chroot_cmd=(unshare --mount --propagation private -- bash -euo pipefail -c '
    c=$1 home=$2 root=$3 data=$4
    shift 4
    mount -t proc proc "$c/proc"
    mount -t sysfs sysfs "$c/sys"
    mount --rbind /dev "$c/dev"
    mount -t tmpfs tmpfs "$c/tmp"
    mkdir -p "$c/tmp/.X11-unix" "$c/vstree" "$c/shared-data"
    mkdir -m 700 "$c/tmp/runtime"
    mount --bind /tmp/.X11-unix "$c/tmp/.X11-unix"
    mount --bind "$root" "$c/vstree"
    if [ -d "$data" ]; then
        mount --bind "$data" "$c/shared-data"
        mount -o remount,bind,ro "$c/shared-data"
    fi
    exec chroot "$c" /usr/bin/env -i PATH=/usr/local/bin:/usr/bin:/bin HOME="$home" \
        LANG=C.UTF-8 DISPLAY="${DISPLAY:-}" LIBGL_ALWAYS_SOFTWARE=1 GALLIUM_DRIVER=llvmpipe \
        LP_NUM_THREADS=2 XDG_RUNTIME_DIR=/tmp/runtime PYTHONDONTWRITEBYTECODE=1 "$@"
' chroot_run)
# in_chroot COMMAND...: runs COMMAND in the current system's chroot ($c, $sys). For a command
# in the background use "${chroot_cmd[@]}" "$c" "$chome" "$root" "$data" COMMAND... & instead:
# a function run with & is a subshell, and $! would be that subshell, not the command.
in_chroot() {
    "${chroot_cmd[@]}" "$c" "$chome" "$root" "$data" "$@"
}

# --- X server -------------------------------------------------------------------------------
display_num=99
while [ -e "/tmp/.X11-unix/X$display_num" ] || [ -e "/tmp/.X$display_num-lock" ]; do
    display_num=$((display_num + 1))
done
export DISPLAY=:$display_num
Xvfb "$DISPLAY" -screen 0 1600x1000x24 -nolisten tcp -ac -noreset >"$work/xvfb.log" 2>&1 &
xvfb_pid=$!
app_pid=
installed_plugin=
cleanup() {
    [ -z "$app_pid" ] || kill "$app_pid" 2>/dev/null || true
    [ -z "$installed_plugin" ] || rm -f "$installed_plugin/libfilter_vstree.so" "$installed_plugin/libvstree.so.0"
    kill "$xvfb_pid" 2>/dev/null || true
}
trap cleanup EXIT
for _ in $(seq 50); do
    xdpyinfo >/dev/null 2>&1 && break
    sleep 0.2
done
xdpyinfo >/dev/null 2>&1 || { echo "Xvfb did not start:" >&2; cat "$work/xvfb.log" >&2; exit 1; }
shot() { # shot FILE: the whole screen as PNG (import, not xwd -root: that misses Qt's menus)
    import -window root "$1"
}
# window NAME-REGEX SECONDS: prints the id of the visible window so named, once it is there,
# while $app_pid runs.
window() {
    local t=$((SECONDS + $2)) w
    while [ $SECONDS -lt "$t" ]; do
        w=$(xdotool search --onlyvisible --name "$1" 2>/dev/null | head -n 1 || true)
        [ -n "$w" ] && echo "$w" && return 0
        kill -0 "$app_pid" 2>/dev/null || return 1
        sleep 0.5
    done
    return 1
}
windows() { xdotool search --onlyvisible --name . 2>/dev/null | while read -r w; do xdotool getwindowname "$w"; done; }

# --- the Blender extension zip and libvstree (shared by every system) -----------------------
zip=
libvstree=target/x86_64-unknown-linux-gnu/release/libvstree.so
build_zip() { # build_zip CHROOT: the linux-x64 zip, packed by that Blender's blender_ext.py
    [ -z "$zip" ] || return 0
    step "the linux-x64 extension zip and libvstree.so"
    local ext_py version
    ext_py=$(ls "$1"/usr/share/blender/scripts/addons_core/bl_pkg/cli/blender_ext.py)
    BLENDER_EXT_PY=$ext_py PYTHON=python3 VSTREE_PLATFORMS=linux-x64 VSTREE_INSTALL_TOOLS=1 \
        CARGO_BUILD_JOBS=$JOBS nice -n 10 bash plugins/blender/build.sh
    version=$(sed -n 's/^version = "\([^"]*\)"$/\1/p' plugins/blender/vstree_blender/blender_manifest.toml)
    zip=target/blender/dist/vstree-$version-linux_x64.zip
}

# --- Blender --------------------------------------------------------------------------------
test_blender() {
    local bl_version series out status ext_dir gui blender_pid differ f win
    bl_version=$(chroot "$c" dpkg-query -W -f='${Version}' blender)
    series=$(echo "$bl_version" | cut -d. -f1,2)
    build_zip "$c"
    step "$sys: Blender $bl_version: install the zip with blender --command extension install-file"
    status=0
    out=$(in_chroot timeout 120 blender --command extension install-file -r user_default -e "/vstree/$zip" 2>&1) ||
        status=$?
    printf '   %s\n' "$out"
    # Enabling (-e) prints "Error: ..." but exits 0 when the add-on fails to import.
    if [ "$status" -eq 0 ] && grep -q '^STATUS Installed "vstree"' <<<"$out" && ! grep -q '^Error' <<<"$out"; then
        pass "$sys blender: extension install-file installs and enables the zip"
    else
        fail "$sys blender: extension install-file (status $status) did not install and enable the zip cleanly"
    fi
    ext_dir=$work/$sys/home/.config/blender/$series/extensions/user_default/vstree
    if [ -f "$ext_dir/vstree/libvstree.so" ] && [ -f "$ext_dir/blender_manifest.toml" ]; then
        pass "$sys blender: the extension is unpacked in ~/.config/blender/$series/extensions/user_default/vstree"
    else
        fail "$sys blender: no $ext_dir/vstree/libvstree.so"
    fi

    step "$sys: Blender: the operators in blender -b"
    in_chroot timeout 600 blender -b --python-exit-code 1 --python /vstree/tests/hosts/blender_batch.py \
        -- /vstree/target/hosts/results.txt /shared-data "$sys" ||
        fail "$sys blender -b: the batch script exited with status $?"

    step "$sys: Blender: the GUI under Xvfb"
    gui=$work/$sys/blender-gui
    mkdir -p "$gui"
    # wait_state WORD SECONDS: waits until the GUI script's state file holds WORD.
    wait_state() {
        local t=$((SECONDS + $2))
        while [ $SECONDS -lt "$t" ]; do
            grep -qx "$1" "$gui/state" 2>/dev/null && return 0
            grep -qx "done" "$gui/state" 2>/dev/null && return 1
            kill -0 "$blender_pid" 2>/dev/null || return 1
            sleep 0.5
        done
        return 1
    }
    "${chroot_cmd[@]}" "$c" "$chome" "$root" "$data" \
        timeout 900 blender --window-geometry 0 0 1600 1000 --python /vstree/tests/hosts/blender_gui.py \
        -- /vstree/target/hosts/results.txt "/vstree/target/hosts/$sys/blender-gui" "$sys" >"$gui/blender.log" 2>&1 &
    blender_pid=$!
    app_pid=$blender_pid
    if wait_state running 300; then
        sleep 2
        shot "$work/shots/$sys-blender-progress.png"
        # Esc, typed as a user does: pointer over the 3D view, the key through XTEST.
        win=$(xdotool search --onlyvisible --class blender | head -n 1 || true)
        xdotool mousemove 700 500
        xdotool windowfocus --sync "$win" 2>/dev/null || true
        xdotool key Escape
        echo "esc" >"$gui/host"
        if wait_state idle 60; then
            shot "$work/shots/$sys-blender-idle.png"
            # The status bar (bottom 30 rows) shows the progress while running, not after.
            for f in progress idle; do
                convert "$work/shots/$sys-blender-$f.png" -gravity south -crop 1600x30+0+0 +repage \
                    "$work/shots/$sys-blender-$f-status.png"
            done
            differ=$(compare -metric AE "$work/shots/$sys-blender-progress-status.png" \
                "$work/shots/$sys-blender-idle-status.png" null: 2>&1 || true)
            if [ "${differ%% *}" -gt 200 ] 2>/dev/null; then
                pass "$sys blender gui: the status bar shows the progress while running ($differ pixels differ)"
            else
                fail "$sys blender gui: the status bar is the same while running and after ($differ pixels differ)"
            fi
            echo "shot" >"$gui/host"
        else
            fail "$sys blender gui: no idle state after Esc"
        fi
        if wait_state sidebar 600; then
            sleep 2
            shot "$work/shots/$sys-blender-sidebar.png"
            echo "shot-done" >"$gui/host"
        else
            fail "$sys blender gui: the script never got to the sidebar screenshot"
        fi
    else
        fail "$sys blender gui: no running modal operator within 300 s"
    fi
    status=0
    wait "$blender_pid" || status=$?
    app_pid=
    [ "$status" -eq 0 ] ||
        fail "$sys blender gui: blender exited with status $status (log: target/hosts/$sys/blender-gui/blender.log)"
    # The GUI script's own checks (they are in the results file; its whole output is in the log).
    grep -E "^(ok|FAIL) " "$gui/blender.log" || true
}

# --- MeshLab --------------------------------------------------------------------------------
# test_meshlab HEADERS_KEY: HEADERS_KEY is plugins/meshlab/build.sh's name of the MeshLab
# version whose headers it fetches (2022.2.post4: 2022.02, 2025.7.post1: 2025.07).
test_meshlab() {
    local key=$1 ml_version ml_series scalar ml_src prefix ml_lib plugdir unresolved t ml
    local main others dialog save options v f closed euler
    ml_version=$(chroot "$c" dpkg-query -W -f='${Version}' meshlab)
    ml_series=${ml_version:0:7} # 2022.02
    ml_lib=/usr/lib/x86_64-linux-gnu/meshlab
    build_zip "$c"
    step "$sys: MeshLab $ml_version: the plugin, built against the package's libmeshlab-common"
    # Headers: the MeshLab source of the same version (fetched, sha256-checked).
    HEADERS_ONLY=1 bash plugins/meshlab/build.sh "$key"
    ml_src=target/meshlab/src/meshlab-$ml_series
    if [ ! -f "$ml_src/ML_VERSION" ]; then
        fail "$sys meshlab: no headers of MeshLab $ml_series ($key fetches $(ls target/meshlab/src))"
        return 0
    fi
    # libvstree: the linux-x64 build of the Blender zip (glibc 2.28, SONAME libvstree.so.0).
    prefix=$work/$sys/vstree-prefix
    mkdir -p "$prefix/lib" "$prefix/include"
    cp "$libvstree" "$prefix/lib/libvstree.so.0"
    ln -sf libvstree.so.0 "$prefix/lib/libvstree.so"
    cp include/vstree.h "$prefix/include/"
    # The scalar type MeshLab was built with, read from one of its own plugins
    # (tests/hosts/meshlab_scalar.sh).
    if ! scalar=$(meshlab_scalar "$c$ml_lib/plugins/libfilter_clean.so"); then
        fail "$sys meshlab: cannot tell whether MeshLab $ml_version is built with float or double"
        return 0
    fi
    echo "MeshLab $ml_version: built with $scalar scalars"
    in_chroot cmake -S /vstree/plugins/meshlab -B "/vstree/target/hosts/$sys/meshlab-build" \
        -DCMAKE_BUILD_TYPE=Release -DMESHLAB_SRC_DIR="/vstree/$ml_src" -DMESHLAB_LIB_DIR="$ml_lib" \
        -DMESHLAB_VERSION="$ml_series" -DMESHLAB_SCALAR="$scalar" -DVSTREE_PREFIX="/vstree/target/hosts/$sys/vstree-prefix" \
        >"$work/$sys/cmake.log" 2>&1 || { tail -n 20 "$work/$sys/cmake.log"; fail "$sys meshlab: cmake configure failed"; return 0; }
    t=$SECONDS
    if in_chroot nice -n 10 cmake --build "/vstree/target/hosts/$sys/meshlab-build" -j "$JOBS" >>"$work/$sys/cmake.log" 2>&1; then
        pass "$sys meshlab: the plugin builds against MeshLab $ml_version's headers and libmeshlab-common ($((SECONDS - t)) s)"
    else
        tail -n 30 "$work/$sys/cmake.log"
        fail "$sys meshlab: the plugin does not build against MeshLab $ml_version"
        return 0
    fi
    # Installed as a user of the package would: both files into the package's plugin folder
    # (libvstree.so.0 beside the plugin, found through its RUNPATH $ORIGIN; MeshLab loads only
    # *.so files as plugins). Removed again when done: the chroot stays as its recipe made it.
    plugdir=$c$ml_lib/plugins
    cp "$work/$sys/meshlab-build/libfilter_vstree.so" "$prefix/lib/libvstree.so.0" "$plugdir/"
    installed_plugin=$plugdir
    if unresolved=$(in_chroot env LD_LIBRARY_PATH="$ml_lib" ldd -r "$ml_lib/plugins/libfilter_vstree.so" 2>&1 |
        grep -E "not found|undefined symbol"); then
        fail "$sys meshlab: the plugin has unresolved libraries or symbols: $unresolved"
    else
        pass "$sys meshlab: the plugin resolves every library and symbol against the package's"
    fi

    step "$sys: MeshLab: the GUI under Xvfb, driven with xdotool"
    ml=$work/$sys/meshlab
    mkdir -p "$ml"
    python3 tests/hosts/ply.py torus "$ml/torus.ply" # 3072 vertices, 6144 triangles, genus 1
    "${chroot_cmd[@]}" "$c" "$chome" "$root" "$data" \
        timeout 300 meshlab "/vstree/target/hosts/$sys/meshlab/torus.ply" >"$ml/meshlab.log" 2>&1 &
    app_pid=$!
    # The main window, or first the box of plugins MeshLab refused ("Error while loading
    # plugins.": wrong version or scalar type, a missing library), which waits for OK.
    main=$(window "^(MeshLab ${ml_series//./\\.}|Error while loading plugins)" 120) || main=
    if [ -n "$main" ] && [ "$(xdotool getwindowname "$main")" = "Error while loading plugins." ]; then
        shot "$work/shots/$sys-meshlab-plugin-error.png"
        fail "$sys meshlab: MeshLab refused plugins at startup (screenshot target/hosts/shots/$sys-meshlab-plugin-error.png)"
        xdotool windowfocus --sync "$main" key Return
        main=$(window "^MeshLab ${ml_series//./\\.}" 60) || main=
    fi
    if [ -n "$main" ]; then
        pass "$sys meshlab: desktop MeshLab $ml_series opens the model given on its command line"
        sleep 3
        # A window beside the main one at startup is a message box (a plugin that did not load).
        others=$(windows | grep -v "^MeshLab ${ml_series//./\\.}" || true)
        if [ -z "$others" ]; then
            pass "$sys meshlab: no message box at startup (every plugin loaded)"
        else
            fail "$sys meshlab: startup shows other windows: $others"
            shot "$work/shots/$sys-meshlab-startup.png"
            xdotool key Return
        fi
        xdotool windowsize "$main" 1600 1000
        sleep 1
        xdotool mousemove 500 500 windowfocus --sync "$main"
        # Filters (Alt+L) > the fourth entry, "Remeshing, Simplification and Reconstruction" >
        # up from the top: Voronoi Filtering, Vertex Attribute Seam, VS-Tree Surface
        # Reconstruction, VS-Tree Clustering Simplification (MeshLab sorts them by name).
        xdotool key alt+l
        sleep 1
        xdotool key Down Down Down Down Right
        sleep 1
        xdotool key Up Up Up Up
        sleep 1
        shot "$work/shots/$sys-meshlab-filters-menu.png"
        xdotool key Return
        if dialog=$(window "^VS-Tree Clustering Simplification\$" 30); then
            pass "$sys meshlab: Filters > Remeshing, Simplification and Reconstruction > VS-Tree Clustering Simplification opens its dialog"
            sleep 1
            # "Percentage reduction (0..1)" = 0.1 (the second field from the top), then Apply
            # (bottom right; Close is bottom left). 2025.07's dialog is taller: the buttons
            # are placed from its bottom edge.
            local WIDTH HEIGHT
            eval "$(xdotool getwindowgeometry --shell "$dialog" | grep -E '^(WIDTH|HEIGHT)=')"
            xdotool mousemove --window "$dialog" 367 136 click 1
            sleep 0.3
            xdotool key ctrl+a
            xdotool type --delay 50 0.1
            sleep 0.3
            xdotool mousemove --window "$dialog" $((WIDTH - 139)) $((HEIGHT - 22)) click 1
            sleep 5
            shot "$work/shots/$sys-meshlab-filter-dialog.png"
            xdotool mousemove --window "$dialog" 137 $((HEIGHT - 22)) click 1 # Close
            sleep 1
            # Export the current layer (Ctrl+E): the dialog names the layer, the file is checked.
            xdotool mousemove 500 500 windowfocus --sync "$main"
            xdotool key ctrl+e
            if save=$(window '^Save "torus\.ply \(vstree\)" Layer$' 30); then
                pass "$sys meshlab: the new layer \"torus.ply (vstree)\" is the current one"
                xdotool windowfocus --sync "$save"
                xdotool type --delay 30 "/vstree/target/hosts/$sys/meshlab/simplified.ply"
                xdotool key Return
                if options=$(window "^Choose Saving Options" 30); then
                    xdotool windowfocus --sync "$options"
                    xdotool key Return
                fi
                for _ in $(seq 40); do
                    [ -s "$ml/simplified.ply" ] && break
                    sleep 0.5
                done
                sleep 1
            else
                fail "$sys meshlab: no Save dialog for the layer \"torus.ply (vstree)\"; windows: $(windows | tr '\n' ';')"
            fi
            if [ -s "$ml/simplified.ply" ]; then
                read -r _ v _ f _ closed _ euler <<<"$(python3 tests/hosts/ply.py stats "$ml/simplified.ply")"
                echo "   exported layer: $v vertices, $f triangles, closed $closed, Euler characteristic $euler"
                # 10% of 6144 triangles, within the library's 1%; the torus stays a torus.
                if [ "$f" -ge 608 ] && [ "$f" -le 620 ] && [ "$v" -lt 3072 ] && [ "$closed" = 1 ] && [ "$euler" = 0 ]; then
                    pass "$sys meshlab: the new layer has 10% of the triangles, closed, genus 1"
                else
                    fail "$sys meshlab: the new layer has $v vertices, $f triangles, closed $closed, Euler $euler"
                fi
            else
                fail "$sys meshlab: the new layer was not exported"
            fi
        else
            fail "$sys meshlab: the menu entry did not open the VS-Tree dialog; windows: $(windows | tr '\n' ';')"
            shot "$work/shots/$sys-meshlab-no-dialog.png"
        fi
    else
        # (a plugin MeshLab refuses shows its message box before the main window)
        shot "$work/shots/$sys-meshlab-no-window.png"
        fail "$sys meshlab: no MeshLab window within 120 s; windows: $(windows | tr '\n' ';') (screenshot" \
            "target/hosts/shots/$sys-meshlab-no-window.png, log target/hosts/$sys/meshlab/meshlab.log)"
    fi
    kill "$app_pid" 2>/dev/null || true
    wait "$app_pid" 2>/dev/null || true
    app_pid=
    rm -f "$plugdir/libfilter_vstree.so" "$plugdir/libvstree.so.0"
    installed_plugin=
}

# --- the systems ----------------------------------------------------------------------------
print_versions() {
    echo "packages under test:"
    chroot "$c" dpkg-query -W -f='   ${Package} ${Version}\n' blender meshlab libgl1-mesa-dri python3 2>/dev/null || true
    chroot "$c" dpkg-query -W -f='   ${Package} ${Version}\n' 'libqt5core5*' 'libqt6core6*' 2>/dev/null | grep -v ' $' || true
}

if [[ $systems == *" debian13 "* ]]; then
    sys=debian13
    c=$cache/$sys
    chome=/vstree/target/hosts/$sys/home
    mkdir -p "$work/$sys/home"
    step "$sys: Debian 13 chroot"
    if ! make_chroot "$sys" trixie "blender=$D13_BLENDER meshlab=$D13_MESHLAB $D13_RUN $BUILD_DEPS"; then
        fail "$sys: the Debian 13 chroot could not be built (log: target/hosts/mmdebstrap-$sys.log)"
    else
        print_versions
        [[ $apps != *" blender "* ]] || test_blender
        [[ $apps != *" meshlab "* ]] || test_meshlab 2022.2.post4
        if [ "${VSTREE_HOSTS_SCREENSHOTS:-0}" = 1 ]; then
            for f in blender-sidebar meshlab-filters-menu meshlab-filter-dialog; do
                [ ! -f "$work/shots/$sys-$f.png" ] || cp "$work/shots/$sys-$f.png" "docs/images/$f.png"
            done
        fi
    fi
fi

if [[ $systems == *" sid "* ]]; then
    sys=sid
    c=$cache/$sys
    chome=/vstree/target/hosts/$sys/home
    mkdir -p "$work/$sys/home"
    step "$sys: Debian unstable chroot (not pinned; rebuilt weekly)"
    # Recommends included, as `apt install` does (MeshLab's plugins need theirs).
    if ! make_chroot "$sys" sid "blender meshlab python3-numpy $BUILD_DEPS" 7 'APT::Install-Recommends "true"'; then
        reason=$(grep -E "^E:|Err:" "$work/mmdebstrap-$sys.log" | head -n 3 | tr '\n' ' ')
        skip "$sys: the Debian unstable chroot could not be built (mirror churn?): ${reason:-see target/hosts/mmdebstrap-$sys.log}"
    else
        print_versions
        [[ $apps != *" blender "* ]] || test_blender
        if [[ $apps == *" meshlab "* ]]; then
            case $(chroot "$c" dpkg-query -W -f='${Version}' meshlab) in
                2025.07*) test_meshlab 2025.7.post1 ;;
                *) fail "$sys meshlab: $(chroot "$c" dpkg-query -W -f='${Version}' meshlab) has no headers recipe in plugins/meshlab/build.sh" ;;
            esac
        fi
    fi
fi

if [[ $systems == *" debian12 "* ]] && [[ $apps == *" meshlab "* ]]; then
    step "debian12: MeshLab 2020.09 on the host (tests/hosts/meshlab2020.sh)"
    # Its checks go into $results; a status without a FAIL line there (it stopped early) is one.
    nfail=$(grep -c '^FAIL' "$results" || true)
    if ! VSTREE_HOSTS_RESULTS=$results JOBS=$JOBS bash tests/hosts/meshlab2020.sh; then
        [ "$(grep -c '^FAIL' "$results" || true)" -gt "$nfail" ] ||
            fail "debian12 meshlab 2020.09: tests/hosts/meshlab2020.sh failed (its output is above)"
    fi
fi

echo "screenshots: target/hosts/shots/: $(find "$work/shots" -name '*.png' -printf '%f ')"
summary
