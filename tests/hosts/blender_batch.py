"""The VS-Tree extension's three operators in desktop Blender run as `blender -b` (tests/hosts/run.sh,
after `blender --command extension install-file`): generated meshes always, shared models when
the shared data folder is mounted. Every check appends "PASS name" or "FAIL name: why" to the
results file; the script itself exits 0 unless it cannot run at all.

usage: blender -b --python blender_batch.py -- RESULTS SHARED_DATA_DIR [LABEL]
(LABEL, e.g. the system's name, starts every check's name.)
"""

import os
import sys
import traceback

import bmesh
import bpy
import numpy as np

ARGS = sys.argv[sys.argv.index("--") + 1:]
RESULTS, DATA = ARGS[:2]
LABEL = (ARGS[2] + " ") if len(ARGS) > 2 else ""
MODULE = "bl_ext.user_default.vstree"


def record(ok, name, why=""):
    line = ("PASS " if ok else "FAIL ") + LABEL + "blender -b: " + name + ("" if ok else ": " + why)
    print(("ok   " if ok else "FAIL ") + line[5:], flush=True)
    with open(RESULTS, "a") as f:
        f.write(line + "\n")


def check(name):
    """Decorator: runs the check now; an AssertionError or any exception is a failure."""

    def run(fn):
        bpy.ops.wm.read_homefile(use_empty=True)
        try:
            fn()
        except Exception as e:  # noqa: BLE001 - every failure is recorded, the rest still run
            record(False, name, "%s: %s" % (type(e).__name__, e))
            traceback.print_exc()
        else:
            record(True, name)
        return fn

    return run


def counts(ob):
    return len(ob.data.vertices), len(ob.data.polygons)


def edge_faces(me):
    bm = bmesh.new()
    bm.from_mesh(me)
    try:
        return np.array([len(e.link_faces) for e in bm.edges])
    finally:
        bm.free()


def closed_euler(ob):
    """(closed and manifold: every edge on two faces, Euler characteristic V - E + F)."""
    links = edge_faces(ob.data)
    v, f = counts(ob)
    return bool(links.size) and bool(np.all(links == 2)), v - len(links) + f


def sphere_cloud(n, normals=True):
    i = np.arange(n) + 0.5
    phi = np.arccos(1 - 2 * i / n)
    theta = np.pi * (1 + 5**0.5) * i
    d = np.stack([np.cos(theta) * np.sin(phi), np.sin(theta) * np.sin(phi), np.cos(phi)], 1).astype(np.float32)
    me = bpy.data.meshes.new("cloud")
    me.vertices.add(n)
    me.vertices.foreach_set("co", d.ravel())
    if normals:
        me.attributes.new("normal", 'FLOAT_VECTOR', 'POINT').data.foreach_set("vector", d.ravel())
    me.update()
    ob = bpy.data.objects.new("cloud", me)
    bpy.context.collection.objects.link(ob)
    bpy.context.view_layer.objects.active = ob
    ob.select_set(True)
    return ob


print("Blender", bpy.app.version_string, "python", sys.version.split()[0], flush=True)


@check("the extension installed by the command line is enabled and loads libvstree")
def _():
    assert MODULE in bpy.context.preferences.addons, sorted(bpy.context.preferences.addons.keys())
    core = sys.modules[MODULE].core
    ok, msg = core.status()
    assert ok, msg
    core.binding()
    ok, msg = core.status()
    assert ok and "libvstree" in msg, msg
    print("  ", msg)
    for op in ("simplify", "reconstruct", "show_clusters"):
        assert hasattr(bpy.ops.vstree, op), op


@check("simplify: a torus to 10% of its triangles, closed, manifold, genus 1, source untouched")
def _():
    bpy.ops.mesh.primitive_torus_add(major_segments=96, minor_segments=32)
    src = bpy.context.active_object
    before = counts(src)
    triangles = 2 * before[1]
    assert bpy.ops.vstree.simplify(ratio=0.1) == {'FINISHED'}
    out = bpy.context.active_object
    v, f = counts(out)
    print("   torus %d triangles -> %d vertices, %d triangles" % (triangles, v, f))
    assert out is not src and out.name == src.name + "_vstree", out.name
    assert abs(f - round(0.1 * triangles)) <= max(2, triangles // 1000), f
    closed, euler = closed_euler(out)
    assert closed and euler == 0, (closed, euler)
    assert counts(src) == before


@check("simplify: a larger error bound gives fewer vertices")
def _():
    bpy.ops.mesh.primitive_uv_sphere_add(segments=128, ring_count=64)
    src = bpy.context.active_object
    got = []
    for error in (1e-5, 1e-3):
        bpy.context.view_layer.objects.active = src
        assert bpy.ops.vstree.simplify(error=error) == {'FINISHED'}
        got.append(counts(bpy.context.active_object)[0])
    print("   sphere %d vertices -> %s" % (len(src.data.vertices), got))
    assert got[1] < got[0] < len(src.data.vertices), got


@check("reconstruct: 3000 points with normals on a sphere -> a watertight genus-0 surface of radius 1")
def _():
    cloud = sphere_cloud(3000)
    assert bpy.ops.vstree.reconstruct(max_levels=3) == {'FINISHED'}
    out = bpy.context.active_object
    v, f = counts(out)
    print("   %d vertices, %d triangles" % (v, f))
    assert out.name == "cloud_surface" and v > 100 and f > 200, (out.name, v, f)
    closed, euler = closed_euler(out)
    assert closed and euler == 2, (closed, euler)
    co = np.empty(v * 3, np.float32)
    out.data.vertices.foreach_get("co", co)
    r = np.linalg.norm(co.reshape(-1, 3), axis=1)
    assert abs(r.mean() - 1.0) < 0.05, r.mean()
    assert len(cloud.data.polygons) == 0


@check("show_clusters: a FLOAT_COLOR point attribute, more than one and fewer colours than vertices")
def _():
    bpy.ops.mesh.primitive_uv_sphere_add(segments=48, ring_count=24)
    ob = bpy.context.active_object
    n = len(ob.data.vertices)
    assert bpy.ops.vstree.show_clusters(error=1e-3) == {'FINISHED'}
    attr = ob.data.color_attributes["vstree_cluster"]
    assert attr.data_type == 'FLOAT_COLOR' and attr.domain == 'POINT' and len(attr.data) == n
    rgba = np.empty(n * 4, np.float32)
    attr.data.foreach_get("color", rgba)
    colours = len(np.unique(rgba.reshape(-1, 4), axis=0))
    print("   %d vertices, %d colours" % (n, colours))
    assert 1 < colours < n, colours


@check("a cloud given to simplify is refused with a report, nothing added")
def _():
    sphere_cloud(500)
    try:
        bpy.ops.vstree.simplify(ratio=0.5)
    except RuntimeError as e:
        assert "has no faces" in str(e), e
    else:
        raise AssertionError("no error")
    assert len(bpy.data.objects) == 1


def shared(name):
    path = os.path.join(DATA, name)
    if not os.path.isfile(path):
        print("   (no %s: shared model checks skipped)" % path)
        return None
    return path


if os.path.isdir(DATA) and os.listdir(DATA):

    @check("shared armadillo_43k.obj: simplify to 10%, closed, manifold, genus 0")
    def _():
        assert bpy.ops.wm.obj_import(filepath=shared("armadillo_43k.obj")) == {'FINISHED'}
        src = bpy.context.active_object
        v0, f0 = counts(src)
        assert (v0, f0) == (43243, 86482), (v0, f0)
        assert bpy.ops.vstree.simplify(ratio=0.1) == {'FINISHED'}
        out = bpy.context.active_object
        v, f = counts(out)
        print("   armadillo %d/%d -> %d vertices, %d triangles" % (v0, f0, v, f))
        assert abs(f - round(0.1 * f0)) <= max(2, f0 // 1000), f
        closed, euler = closed_euler(out)
        assert closed and euler == 2, (closed, euler)

    @check("shared bunny_zipper.ply: simplify at 1e-4 and cluster colours")
    def _():
        assert bpy.ops.wm.ply_import(filepath=shared("bunny_zipper.ply")) == {'FINISHED'}
        src = bpy.context.active_object
        v0, f0 = counts(src)
        assert v0 == 35947 and f0 == 69451, (v0, f0)
        assert bpy.ops.vstree.simplify(error=1e-4) == {'FINISHED'}
        v, f = counts(bpy.context.active_object)
        print("   bunny %d/%d -> %d vertices, %d triangles" % (v0, f0, v, f))
        assert 100 < v < v0 and 0 < f < f0
        bpy.context.view_layer.objects.active = src
        assert bpy.ops.vstree.show_clusters(error=1e-4) == {'FINISHED'}
        assert len(src.data.color_attributes["vstree_cluster"].data) == v0

    @check("shared ball.ply (31374 points with normals): reconstruct -> watertight, genus 0")
    def _():
        assert bpy.ops.wm.ply_import(filepath=shared("ball.ply")) == {'FINISHED'}
        src = bpy.context.active_object
        assert counts(src) == (31374, 0), counts(src)
        assert "normal" in src.data.attributes, list(src.data.attributes.keys())
        assert bpy.ops.vstree.reconstruct() == {'FINISHED'}
        out = bpy.context.active_object
        v, f = counts(out)
        print("   ball 31374 points -> %d vertices, %d triangles" % (v, f))
        closed, euler = closed_euler(out)
        assert closed and euler == 2 and f > 1000, (closed, euler, f)
else:
    print("no shared data at %s: shared model checks skipped" % DATA)
