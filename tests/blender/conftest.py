"""pytest setup for the VS-Tree Blender extension, run inside the PyPI `bpy` module (headless).
The environment must be set before `import bpy`, and bpy is imported once per process."""

import atexit
import glob
import os
import shutil
import sys
import tempfile

import pytest

_TMP = tempfile.mkdtemp(prefix="vstree_bpy_")
atexit.register(shutil.rmtree, _TMP, ignore_errors=True)
os.environ["BLENDER_USER_RESOURCES"] = os.path.join(_TMP, "user")  # prefs, extensions
os.environ["XDG_CACHE_HOME"] = os.path.join(_TMP, "cache")  # shader caches, thumbnails

import bpy  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
PKG_ID = "vstree"
MODULE = "bl_ext.user_default." + PKG_ID


@pytest.fixture(scope="session")
def addon():
    """Installs the zip made by plugins/blender/build.sh; yields the add-on module."""
    zips = glob.glob(os.path.join(ROOT, "target", "blender", "dist", "vstree-*-linux_x64.zip"))
    assert len(zips) == 1, zips
    bpy.ops.extensions.package_install_files(filepath=zips[0], repo="user_default", enable_on_install=True)
    # The operator returns FINISHED even when it refuses a package: check it is enabled.
    assert MODULE in bpy.context.preferences.addons
    module = sys.modules[MODULE]
    yield module
    repo_dir = bpy.context.preferences.extensions.repos["User Default"].directory
    bpy.ops.extensions.package_uninstall(repo_directory=repo_dir, pkg_id=PKG_ID)


@pytest.fixture
def scene(addon):
    bpy.ops.wm.read_homefile(use_empty=True)  # the add-on stays enabled
    addon.progress_hook = None
    yield bpy.context.scene
    addon.progress_hook = None
