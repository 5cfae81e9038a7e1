# SPDX-License-Identifier: GPL-3.0-or-later
"""Makes the picture in plugins/meshlab/README.md: the plugin's VS-Tree simplification of a
mesh, run through pymeshlab, saved as ASCII PLY, then drawn by docs/render.py.

Usage (in the venv build.sh made, e.g. target/meshlab/2025.7.post1/venv):
    python plugins/meshlab/render_example.py PLUGIN.so INPUT.ply OUTPUT.ply
    python docs/render.py OUTPUT.ply picture.png 20 10 wire
"""

import sys

import pymeshlab

plugin, source, output = sys.argv[1:4]
pymeshlab.load_plugin(plugin)
ms = pymeshlab.MeshSet()
ms.load_new_mesh(source)
ms.apply_filter("vstree_clustering_simplification", error=1e-4)
ms.save_current_mesh(output, binary=False, save_vertex_normal=False, save_vertex_color=False)
print(f"{ms.current_mesh().vertex_number()} vertices, {ms.current_mesh().face_number()} faces")
