"""Loads the staged add-on folder as a legacy add-on (bl_info, addon_utils) in its own process:
registration must work, and the operators must run.  Usage: python legacy_check.py STAGE_PARENT"""

import atexit
import os
import shutil
import sys
import tempfile

tmp = tempfile.mkdtemp(prefix="vstree_bpy_legacy_")
atexit.register(shutil.rmtree, tmp, ignore_errors=True)
os.environ["BLENDER_USER_RESOURCES"] = os.path.join(tmp, "user")
os.environ["XDG_CACHE_HOME"] = os.path.join(tmp, "cache")

import bpy  # noqa: E402  (first: it puts Blender's modules on sys.path)
import addon_utils  # noqa: E402

sys.path.insert(0, sys.argv[1])
mod = addon_utils.enable("vstree", default_set=True)
assert mod is not None and mod.bl_info["name"] == "VS-Tree", mod
bpy.ops.wm.read_homefile(use_empty=True)
bpy.ops.mesh.primitive_uv_sphere_add(segments=32, ring_count=16)
assert bpy.ops.vstree.simplify(error=1e-3) == {'FINISHED'}
print("legacy add-on: simplified to", len(bpy.context.active_object.data.vertices), "vertices")
addon_utils.disable("vstree")
assert not hasattr(bpy.types, "VSTREE_OT_simplify")
print("legacy add-on: OK")
