# SPDX-License-Identifier: GPL-3.0-or-later
"""Tests of the vstree MeshLab filter plugin inside pymeshlab (2022.2.post4 and 2025.7.post1).

Runs under pytest or as a plain script:  python test_vstree_meshlab.py
The plugin is taken from $VSTREE_MESHLAB_PLUGIN (tests/meshlab/run.sh sets it).
"""
import os
import subprocess
import sys
import time

import numpy as np
import pymeshlab

PLUGIN = os.environ["VSTREE_MESHLAB_PLUGIN"]
DATA = os.environ.get("VSTREE_DATA") or os.path.realpath(
    os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..", "shared", "data"))
# Under CI (or with VSTREE_DATA set) the shared models must be there: a missing one fails.
DATA_EXPECTED = bool(os.environ.get("CI") or os.environ.get("VSTREE_DATA"))
SIMPLIFY = "vstree_clustering_simplification"
RECONSTRUCT = "vstree_surface_reconstruction"
COLOUR = "vstree_cluster_colouring"

_nplugins = getattr(pymeshlab, "plugin_number", None) or pymeshlab.number_plugins
_before = _nplugins()
pymeshlab.load_plugin(PLUGIN)
_after = _nplugins()


def nmeshes(ms):
    return (getattr(ms, "mesh_number", None) or ms.number_meshes)()


def topo(ms):
    return ms.apply_filter("get_topological_measures")


def sphere(ms):
    ms.create_sphere(subdiv=4)  # 2562 vertices, 5120 faces
    return ms.current_mesh()


def sphere_points(n=3000, normals=True):
    rng = np.random.default_rng(1)
    p = rng.normal(size=(n, 3))
    p /= np.linalg.norm(p, axis=1, keepdims=True)
    if normals:
        return pymeshlab.Mesh(vertex_matrix=p.astype(np.float64), v_normals_matrix=p.astype(np.float64))
    return pymeshlab.Mesh(vertex_matrix=p.astype(np.float64))


# pymeshlab (both versions) leaves VerbosityManager::staticLogger pointing at the MeshSet's log
# when a filter throws; destroying that MeshSet and loading a file later then crashes. Keep every
# MeshSet that saw a failing filter alive until the process ends.
_KEEP_ALIVE = []


def expect_error(ms, name, fragment, **kw):
    _KEEP_ALIVE.append(ms)
    try:
        ms.apply_filter(name, **kw)
    except pymeshlab.PyMeshLabException as e:
        msg = str(e)
        assert fragment in msg, msg
        print("  error text:", msg.replace("\n", " | "))
        return msg
    raise AssertionError(f"{name}({kw}) did not raise")


def test_plugin_loaded():
    assert _after == _before + 1, (_before, _after)
    names = pymeshlab.filter_list()
    for n in (SIMPLIFY, RECONSTRUCT, COLOUR):
        assert n in names, n


def test_simplify_sphere_new_layer():
    ms = pymeshlab.MeshSet()
    src = sphere(ms)
    src_id = ms.current_mesh_id()
    nv, nf = src.vertex_number(), src.face_number()
    out = ms.apply_filter(SIMPLIFY, error=1e-3)
    assert nmeshes(ms) == 2 and ms.current_mesh_id() != src_id
    m = ms.current_mesh()
    print(f"  sphere {nv} v / {nf} f -> {m.vertex_number()} v / {m.face_number()} f, {out}")
    assert 10 < m.vertex_number() < nv and 10 < m.face_number() < nf
    assert m.vertex_number() == out["output_vertices"] and m.face_number() == out["output_triangles"]
    assert ms.mesh(src_id).vertex_number() == nv  # source untouched
    # coarser bound -> fewer vertices
    ms.set_current_mesh(src_id)
    ms.apply_filter(SIMPLIFY, error=1e-2)
    assert ms.current_mesh().vertex_number() < m.vertex_number()


def test_simplify_options():
    ms = pymeshlab.MeshSet()
    sphere(ms)
    src_id = ms.current_mesh_id()
    for kw in (dict(tree_kind="Octree"), dict(sampling="Face centers"),
               dict(metric="L2,1 (normal deviation)", error=0.05),
               dict(metric="Density (samples)", error=20), dict(d_a=0.5, d_d=0.1)):
        ms.set_current_mesh(src_id)
        out = ms.apply_filter(SIMPLIFY, **kw)
        assert ms.current_mesh().face_number() > 0, kw
        print(f"  {kw}: {out['output_vertices']} v / {out['output_triangles']} f")


def test_simplify_to_a_size_closed_and_manifold():
    """The face count (or fraction) like the quadric filter's, the sphere kept closed and
    manifold by default, plain clustering when topology is off, and bad sizes refused."""
    ms = pymeshlab.MeshSet()
    sphere(ms)
    src_id = ms.current_mesh_id()
    for kw, want in ((dict(target_faces=500), 500), (dict(target_faces=100), 100),
                     (dict(target_perc=0.1), 512), (dict(target_faces=900, target_perc=0.02), 102)):
        ms.set_current_mesh(src_id)
        out = ms.apply_filter(SIMPLIFY, **kw)
        m = ms.current_mesh()
        t = topo(ms)
        print(f"  {kw}: {m.face_number()} faces, {t['boundary_edges']} border edges, genus {t['genus']}")
        assert abs(m.face_number() - want) <= max(2, want // 100), (kw, m.face_number())
        assert out["kept_topology"] == 1 and t["boundary_edges"] == 0 and t["genus"] == 0, (kw, t)
        assert t["non_two_manifold_edges"] == 0 and t["non_two_manifold_vertices"] == 0, (kw, t)
    ms.set_current_mesh(src_id)
    out = ms.apply_filter(SIMPLIFY, target_faces=300, keep_topology="Off")
    assert out["kept_topology"] == 0 and abs(ms.current_mesh().face_number() - 300) <= 3
    # Below what a sphere allows: a tetrahedron, not an empty layer.
    ms.set_current_mesh(src_id)
    ms.apply_filter(SIMPLIFY, target_faces=1)
    assert ms.current_mesh().face_number() == 4
    bad = pymeshlab.MeshSet()
    sphere(bad)
    expect_error(bad, SIMPLIFY, "more than the input's 5120 triangles", target_faces=6000)
    expect_error(bad, SIMPLIFY, "'Percentage reduction' is 1.5", target_perc=1.5)
    expect_error(bad, SIMPLIFY, "'Target number of faces' is -3", target_faces=-3)


def percentage(value):
    """A percentage of the bounding-box diagonal, in either pymeshlab's spelling."""
    return (getattr(pymeshlab, "PercentageValue", None) or pymeshlab.Percentage)(value)


def absolute(value):
    return (getattr(pymeshlab, "PureValue", None) or pymeshlab.AbsoluteValue)(value)


def test_distance_as_absolute_or_percentage():
    ms = pymeshlab.MeshSet()
    sphere(ms)
    src_id = ms.current_mesh_id()
    diagonal = ms.current_mesh().bounding_box().diagonal()
    counts = {}
    for name, kw in (("1%", dict(distance=percentage(1.0))), ("abs", dict(distance=absolute(0.01 * diagonal))),
                     ("e", dict(error=1e-4)), ("3%", dict(distance=percentage(3.0)))):
        ms.set_current_mesh(src_id)
        counts[name] = ms.apply_filter(SIMPLIFY, **kw)["output_vertices"]
    print(f"  distance: {counts}")
    # 1% of the diagonal is the L2 bound (0.01)^2 = 1e-4, given either way (pymeshlab passes
    # lengths as C++ floats, so the bound may differ from 1e-4 in its last digits).
    assert counts["1%"] == counts["abs"]
    assert abs(counts["1%"] - counts["e"]) <= max(2, 0.02 * counts["e"])
    assert counts["3%"] < counts["1%"]
    ms.set_current_mesh(src_id)
    expect_error(ms, SIMPLIFY, "L2 metric only", distance=percentage(1.0), metric="Density (samples)", error=20)


def test_simplify_point_cloud_with_normals():
    ms = pymeshlab.MeshSet()
    ms.add_mesh(sphere_points(3000, normals=True), "cloud")
    out = ms.apply_filter(SIMPLIFY, error=1e-3)
    m = ms.current_mesh()
    assert nmeshes(ms) == 2 and m.face_number() == 0 and 0 < m.vertex_number() < 3000, out


def test_simplify_errors():
    ms = pymeshlab.MeshSet()
    sphere(ms)
    msg = expect_error(ms, SIMPLIFY, "error", error=-1.0)
    assert "vstree simplify failed" in msg
    expect_error(ms, SIMPLIFY, "max_depth", max_depth=99)
    assert nmeshes(ms) == 1  # no layer on failure
    ms.add_mesh(sphere_points(500, normals=False), "bare")
    expect_error(ms, SIMPLIFY, "normal")


def test_reconstruct_closed_watertight():
    ms = pymeshlab.MeshSet()
    ms.add_mesh(sphere_points(4000, normals=False), "cloud")  # no normals: estimated
    out = ms.apply_filter(RECONSTRUCT, levels=3)
    m = ms.current_mesh()
    assert nmeshes(ms) == 2 and m.face_number() > 100, out
    t = topo(ms)
    print(f"  reconstruction {m.vertex_number()} v / {m.face_number()} f, {out}, topology {t}")
    assert t["boundary_edges"] == 0 and t["non_two_manifold_edges"] == 0
    assert t["is_mesh_two_manifold"] and t["genus"] == 0
    assert out["normals_estimated"] == 4000


def test_reconstruct_with_given_normals_and_trim():
    ms = pymeshlab.MeshSet()
    ms.add_mesh(sphere_points(3000, normals=True), "cloud")
    out = ms.apply_filter(RECONSTRUCT, estimate_normals=False, levels=2, trim=2.0)
    assert ms.current_mesh().face_number() > 100 and out["normals_estimated"] == 0, out


def test_reconstruct_hemisphere_open_by_default_closed_on_request():
    rng = np.random.default_rng(2)
    p = rng.normal(size=(12000, 3))
    p /= np.linalg.norm(p, axis=1, keepdims=True)
    p = p[p[:, 2] > 0]  # a scan from above: the upper half only
    for surface, closed in [(0, False), (1, True)]:
        ms = pymeshlab.MeshSet()
        ms.add_mesh(pymeshlab.Mesh(vertex_matrix=p, v_normals_matrix=p), "dome")
        ms.apply_filter(RECONSTRUCT, estimate_normals=False, levels=2, surface=surface)
        t = topo(ms)
        print(f"  surface {surface}: {ms.current_mesh().face_number()} f, topology {t}")
        assert t["non_two_manifold_edges"] == 0
        assert (t["boundary_edges"] == 0) == closed, t


def test_reconstruct_errors():
    ms = pymeshlab.MeshSet()
    ms.add_mesh(sphere_points(500, normals=False), "bare")
    expect_error(ms, RECONSTRUCT, "has no normals", estimate_normals=False)
    expect_error(ms, RECONSTRUCT, "error", error=-1.0)
    expect_error(ms, RECONSTRUCT, "levels", levels=13)
    assert nmeshes(ms) == 1


def test_bad_geometry_raises_not_crashes():
    ms = pymeshlab.MeshSet()
    v = np.array([[0, 0, 0], [0, 0, 0], [0, 0, 0]], dtype=np.float64)  # one degenerate triangle
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=v, face_matrix=np.array([[0, 1, 2]], dtype=np.int32)), "flat")
    expect_error(ms, SIMPLIFY, "vstree simplify failed")
    expect_error(ms, COLOUR, "vstree tree_build failed")
    ms.add_mesh(sphere_points(5, normals=True), "five")  # fewer than 10 points
    expect_error(ms, RECONSTRUCT, "vstree reconstruct failed")
    assert nmeshes(ms) == 2


def test_colouring():
    ms = pymeshlab.MeshSet()
    src = sphere(ms)
    out = ms.apply_filter(COLOUR, error=1e-3)
    m = ms.current_mesh()
    assert nmeshes(ms) == 1 and m.has_vertex_color()
    cols = np.unique(m.vertex_color_array() if hasattr(m, "vertex_color_array") else m.vertex_color_matrix(), axis=0)
    print(f"  {len(cols)} distinct colours, {out}")
    assert len(cols) > 10 and out["clusters"] > 10
    out_t = ms.apply_filter(COLOUR, label="T-node")
    assert out_t["t_nodes"] > 0, out_t
    expect_error(ms, COLOUR, "error", error=0.0)


VERBOSE_SCRIPT = """
import os, pymeshlab
pymeshlab.load_plugin(os.environ["VSTREE_MESHLAB_PLUGIN"])
ms = pymeshlab.MeshSet(verbose=True)
ms.create_sphere(subdiv=4)
ms.apply_filter("vstree_clustering_simplification", error=1e-3)
ms.apply_filter("vstree_surface_reconstruction", levels=1)
"""


def test_verbose_log_and_progress():
    # pymeshlab buffers the verbose log (plugin log() lines and progress) on stderr until the
    # process ends, so run it in a child process and read its stderr.
    r = subprocess.run([sys.executable, "-c", VERBOSE_SCRIPT], capture_output=True, text=True,
                       timeout=120, check=True)
    lines = [l for l in r.stderr.splitlines() if l.startswith("LOG:")]
    print("  " + "\n  ".join(lines[:3] + ["..."] + lines[-2:]))
    assert "VS-Tree simplification: 2562 -> 92 vertices, 5120 -> 180 triangles" in r.stderr, r.stderr
    assert "VS-Tree reconstruction:" in r.stderr, r.stderr
    assert "building tree    [ 0% ]" in r.stderr and "done    [ 100% ]" in r.stderr, r.stderr


def test_real_model():
    path = os.path.join(DATA, "bunny_zipper.ply")
    if not os.path.exists(path):
        assert not DATA_EXPECTED, "no %s, and CI or VSTREE_DATA says it must be there" % path
        print("  skipped: no", path)
        return
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(path)
    nv = ms.current_mesh().vertex_number()
    t = time.time()
    out = ms.apply_filter(SIMPLIFY, error=1e-4)
    m = ms.current_mesh()
    print(f"  bunny_zipper {nv} v -> {m.vertex_number()} v / {m.face_number()} f in {time.time() - t:.2f}s")
    assert 100 < m.vertex_number() < nv
    ms.set_current_mesh(0)
    ms.apply_filter(COLOUR, error=1e-4)
    assert ms.mesh(0).has_vertex_color()
    path = os.path.join(DATA, "armadillo_points_normals.ply")
    assert os.path.exists(path) or not DATA_EXPECTED, "no %s" % path
    if os.path.exists(path):
        ms.load_new_mesh(path)
        n = ms.current_mesh().vertex_number()
        t = time.time()
        # Closed asked for: on this cloud (inward normals, turned out) half of the closed
        # surface is unsupported, and the default (Auto) keeps it open.
        out = ms.apply_filter(RECONSTRUCT, estimate_normals=False, levels=3, surface=1)
        m = ms.current_mesh()
        print(f"  armadillo {n} points -> {m.vertex_number()} v / {m.face_number()} f in "
              f"{time.time() - t:.2f}s, {out}")
        assert m.face_number() > 1000 and topo(ms)["boundary_edges"] == 0


def test_defaults_are_the_librarys():
    """Every default the filter dialog shows is the C library's (vstree_*_params_default())."""
    if not hasattr(pymeshlab.MeshSet, "filter_parameter_values"):
        print("  skipped: this pymeshlab cannot list a filter's default values")
        return
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "bindings", "python"))
    os.environ["VSTREE_LIBRARY"] = os.path.join(os.path.dirname(PLUGIN), "libvstree.so.0")
    from vstree import _ffi

    simplify = _ffi.lib.vstree_simplify_params_default()
    reconstruct = _ffi.lib.vstree_reconstruct_params_default()
    ms = pymeshlab.MeshSet()
    sphere(ms)
    for name in (SIMPLIFY, COLOUR):
        got = ms.filter_parameter_values(name)
        # MeshLab keeps its float parameters in float32.
        assert abs(got["error"] - simplify.error) <= 1e-6 * simplify.error, (name, got["error"])
        assert abs(got["d_a"] - simplify.d_a) < 1e-6 and abs(got["d_d"] - simplify.d_d) < 1e-6, (name, got)
        assert got["max_depth"] == simplify.max_depth, (name, got)
    got = ms.filter_parameter_values(SIMPLIFY)
    assert got["target_faces"] == simplify.target_faces and got["target_perc"] == 0, got
    assert got["keep_topology"] == simplify.keep_topology, got
    got = ms.filter_parameter_values(RECONSTRUCT)
    assert abs(got["error"] - reconstruct.error) <= 1e-6 * reconstruct.error, got["error"]
    assert got["levels"] == reconstruct.max_levels and got["trim"] == reconstruct.trim, got
    # Every parameter the dialogs take from the library's table has the table's default (a
    # choice: the index of its default among the table's choices, which the enum lists in order).
    import vstree

    table = {(p.call, p.name): p for p in vstree.parameters()}
    simplify_rows = ["error", "tree_kind", "metric", "d_a", "d_d", "sampling", "max_depth", "target_faces", "keep_topology"]
    fields = {
        SIMPLIFY: [(f, "simplify", f) for f in simplify_rows],
        RECONSTRUCT: [("error", "reconstruct", "error"), ("levels", "reconstruct", "max_levels"),
                      ("surface", "reconstruct", "closure"), ("trim", "reconstruct", "trim")],
    }
    for name, rows in fields.items():
        got = ms.filter_parameter_values(name)
        for field, call, param in rows:
            p = table[(call, param)]
            want = [c.name for c in p.choices].index(p.default) if p.kind == "choice" else p.default
            assert abs(got[field] - want) <= 1e-6 * abs(want), (name, field, got[field], want)


if __name__ == "__main__":
    failed = 0
    for name, fn in list(globals().items()):
        if name.startswith("test_") and callable(fn):
            t = time.time()
            try:
                fn()
                print(f"PASS {name} ({time.time() - t:.2f}s)")
            except Exception as e:  # report and go on
                failed += 1
                print(f"FAIL {name}: {type(e).__name__}: {e}")
    print(f"pymeshlab {os.path.dirname(pymeshlab.__file__)}: "
          f"{'ALL PASSED' if failed == 0 else f'{failed} FAILED'}")
    sys.exit(1 if failed else 0)

