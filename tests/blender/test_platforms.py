"""The extension on a platform it was not built for: Blender refuses a zip for another platform,
and an installation whose library is missing or for another platform tells the user which zip
to install (operator error and panel status), never crashing Blender."""

import glob
import os
import shutil
import sys
import tempfile

import bpy
import pytest

from conftest import ROOT

# Smallest headers that say which platform a library is for (what core.library_platform reads).
FAKE_LIBRARIES = {
    # PE: "MZ", e_lfanew at 0x3c -> "PE\0\0" + machine 0x8664 (x86-64)
    ("vstree.dll", "windows-x64"): b"MZ" + b"\0" * 58 + (64).to_bytes(4, "little") + b"PE\0\0" + b"\x64\x86",
    # Mach-O 64-bit, little-endian magic, CPU type arm64
    ("libvstree.dylib", "macos-arm64"): b"\xcf\xfa\xed\xfe" + (0x0100000C).to_bytes(4, "little") + b"\0" * 24,
}


def version():
    import tomllib

    with open(os.path.join(ROOT, "plugins", "blender", "vstree_blender", "blender_manifest.toml"), "rb") as f:
        return tomllib.load(f)["version"]


class Unloaded:
    """Forgets the loaded binding (the module and the add-on's cache) for the test's duration,
    so the add-on loads the library again; restores both afterwards."""

    def __init__(self, core):
        self.core = core
        self.pkg = core.__package__ + ".vstree"

    def _ours(self):
        return [k for k in sys.modules if k == self.pkg or k.startswith(self.pkg + ".")]

    def __enter__(self):
        self.saved = {k: sys.modules.pop(k) for k in self._ours()}
        self.binding = self.core._BINDING
        self.core._BINDING = None
        return self

    def __exit__(self, *exc):
        for k in self._ours():
            del sys.modules[k]
        sys.modules.update(self.saved)
        self.core._BINDING = self.binding


@pytest.mark.parametrize("name,platform", list(FAKE_LIBRARIES))
def test_library_for_another_platform_names_the_zip_to_install(scene, addon, name, platform):
    """The installed add-on's libvstree.so replaced by another platform's library (as when
    files of another zip were copied in by hand): the operator reports which platform the
    library is for and which zip to install; the scene is unchanged; putting the right library
    back works without restarting."""
    core = addon.core
    lib_dir = os.path.join(os.path.dirname(core.__file__), "vstree")
    so = os.path.join(lib_dir, "libvstree.so")
    assert os.path.exists(so)
    aside = so + ".aside"
    other = os.path.join(lib_dir, name)
    os.rename(so, aside)
    try:
        with open(other, "wb") as f:
            f.write(FAKE_LIBRARIES[name, platform])
        with Unloaded(core):
            bpy.ops.mesh.primitive_uv_sphere_add()
            expected = "holds %s for %s, but Blender runs on linux-x64. Install vstree-%s-linux_x64.zip" % (
                name, platform, version())
            with pytest.raises(RuntimeError, match="Error: VS-Tree: VS-Tree native library unavailable: .*" + expected):
                bpy.ops.vstree.simplify()
            assert len(bpy.data.objects) == 1
            ok, msg = core.status()
            assert not ok and expected in msg
            assert core.library_platform(other) == platform
    finally:
        os.remove(other)
        os.rename(aside, so)
    with Unloaded(core):
        assert bpy.ops.vstree.simplify() == {'FINISHED'}
        assert core.status()[0]


def test_missing_library_names_the_zip_to_install(scene, addon):
    """No library at all in the installed add-on: the message names this platform's zip."""
    core = addon.core
    so = os.path.join(os.path.dirname(core.__file__), "vstree", "libvstree.so")
    os.rename(so, so + ".aside")
    try:
        with Unloaded(core):
            bpy.ops.mesh.primitive_uv_sphere_add()
            with pytest.raises(RuntimeError, match=r"unavailable: Reinstall the extension built for this platform \(linux-x64\)\. "
                               r"Install vstree-%s-linux_x64\.zip .*libvstree\.so \(not found\)" % version()):
                bpy.ops.vstree.simplify()
            assert len(bpy.data.objects) == 1
    finally:
        os.rename(so + ".aside", so)
    assert core.library_platform(so) == "linux-x64"


def test_library_is_for_this_platform(addon):
    assert addon.core.this_platform() == "linux-x64"
    ok, msg = addon.core.status()
    assert ok, msg
    assert addon.core.library_platform(addon.core.binding().library_path) == "linux-x64"


OTHER_ZIPS = sorted(glob.glob(os.path.join(ROOT, "target", "blender", "dist", "vstree-*.zip")))
OTHER_ZIPS = [z for z in OTHER_ZIPS if not z.endswith("-linux_x64.zip")]


@pytest.mark.skipif(not OTHER_ZIPS, reason="only the linux-x64 zip was built (tests/platforms/run.sh builds all)")
@pytest.mark.parametrize("zip_path", OTHER_ZIPS, ids=os.path.basename)
def test_zip_for_another_platform_is_refused(addon, zip_path, capfd):
    """Blender itself refuses a zip whose manifest names another platform, with a message
    naming it, and installs nothing (tried in a repository of its own, so the installed
    linux-x64 add-on stays)."""
    platform = zip_path.rsplit("-", 1)[1][: -len(".zip")].replace("_", "-")
    directory = tempfile.mkdtemp(prefix="vstree_other_repo_")
    repos = bpy.context.preferences.extensions.repos
    bpy.ops.preferences.extension_repo_add(name="other", type='LOCAL', use_custom_directory=True,
                                           custom_directory=directory)
    module = repos[-1].module
    try:
        capfd.readouterr()
        bpy.ops.extensions.package_install_files(filepath=zip_path, repo=module, enable_on_install=True)
        out, err = capfd.readouterr()
        assert "This platform (linux-x64) isn't one of (%s)" % platform in out + err
        assert "bl_ext.%s.vstree" % module not in bpy.context.preferences.addons
        assert not os.path.exists(os.path.join(directory, "vstree"))
        assert "bl_ext.user_default.vstree" in bpy.context.preferences.addons
    finally:
        bpy.ops.preferences.extension_repo_remove(index=len(repos) - 1)
        shutil.rmtree(directory, ignore_errors=True)


def test_missing_numpy_says_what_to_install(scene, addon):
    """A Blender on a system Python without numpy (Debian's): enabling worked, and the
    operators say to install numpy instead of failing on an import."""
    core = addon.core
    numpy = core.np
    core.np = None
    try:
        with Unloaded(core):
            bpy.ops.mesh.primitive_uv_sphere_add()
            with pytest.raises(RuntimeError, match=r"needs numpy.*apt install python3-numpy"):
                bpy.ops.vstree.simplify()
            assert len(bpy.data.objects) == 1
            assert not core.status()[0] and "python3-numpy" in core.status()[1]
    finally:
        core.np = numpy
    assert core.status()[0]
