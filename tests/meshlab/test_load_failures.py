# SPDX-License-Identifier: GPL-3.0-or-later
"""A plugin pymeshlab cannot use is refused with a message, and the host keeps running.

usage: python test_load_failures.py OTHER_VERSION_PLUGIN LONE_PLUGIN
  OTHER_VERSION_PLUGIN: libfilter_vstree.so built for another MeshLab version;
  LONE_PLUGIN: this version's plugin copied without libvstree.so.0 beside it.
Each must raise an exception from pymeshlab.load_plugin (not crash, not load), and the MeshSet
must still work afterwards."""
import sys

import pymeshlab

failed = 0
# The lone plugin first: once the other version's plugin has been opened, its libvstree.so.0 is
# in the process and would satisfy the lone plugin's dependency.
for name, path, needle in [
    ("a plugin without libvstree.so.0", sys.argv[2], "libvstree"),
    ("another MeshLab version's plugin", sys.argv[1], "version"),
]:
    try:
        pymeshlab.load_plugin(path)
    except Exception as e:  # pymeshlab raises its own exception types
        text = str(e)
        ok = needle in text
        print(f"  {'ok' if ok else 'FAIL'}: {name}: refused: {text.strip()[:300]}")
        failed += not ok
    else:
        print(f"  FAIL: {name}: loaded")
        failed += 1
ms = pymeshlab.MeshSet()
ms.create_sphere()
assert ms.current_mesh().vertex_number() > 0
print(f"{2 - failed} passed, {failed} failed")
sys.exit(1 if failed else 0)
