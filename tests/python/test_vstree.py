"""The ctypes module (bindings/python/vstree): numpy in and out, errors as VstreeError with the
status and message, progress that cancels, exceptions through callbacks, the tree for viewers,
threads, library lookup and the ABI check."""

import copy
import os
import pickle
import re
import subprocess
import sys
import threading

import numpy as np
import pytest

import vstree
from conftest import ROOT


def torus(rings=64, segments=32, bump=0.2):
    u = np.linspace(0, 2 * np.pi, rings, endpoint=False)[:, None]
    v = np.linspace(0, 2 * np.pi, segments, endpoint=False)[None, :]
    r = 0.3 * (1 + bump * np.sin(5 * u) * np.sin(3 * v))
    p = np.stack(
        [(1 + r * np.cos(v)) * np.cos(u), (1 + r * np.cos(v)) * np.sin(u), r * np.sin(v) + 0 * u],
        axis=-1,
    ).reshape(-1, 3)
    n = np.stack(
        [np.cos(v) * np.cos(u), np.cos(v) * np.sin(u), np.sin(v) + 0 * u], axis=-1
    ).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(rings), np.arange(segments), indexing="ij")
    a = i * segments + j
    b = (i + 1) % rings * segments + j
    c = (i + 1) % rings * segments + (j + 1) % segments
    d = i * segments + (j + 1) % segments
    t = np.concatenate([np.stack([a, b, c], -1), np.stack([a, c, d], -1)]).reshape(-1, 3)
    return p.astype(np.float32), t.astype(np.uint32), n.astype(np.float32)


@pytest.fixture(scope="module")
def shape():
    return torus()


def test_version_and_abi_agree_with_cargo_toml():
    cargo = open(os.path.join(ROOT, "Cargo.toml")).read()
    assert vstree.version == re.search(r'^version = "([^"]+)"', cargo, re.M).group(1)
    header = open(os.path.join(ROOT, "include", "vstree.h")).read()
    abi = int(re.search(r"#define VSTREE_ABI_VERSION (\d+)", header).group(1))
    assert vstree.ABI_VERSION == abi


def test_arrays_round_trip(shape):
    p, t, n = shape
    m = vstree.Mesh(p, t, n)
    assert (m.vertex_count, m.triangle_count, m.has_normals) == (len(p), len(t), True)
    np.testing.assert_array_equal(m.positions, p)
    np.testing.assert_array_equal(m.triangles, t)
    np.testing.assert_array_equal(m.normals, n)
    # Other dtypes and flat arrays are converted; a cloud has no triangles.
    cloud = vstree.Mesh(p.astype(np.float64).ravel(), None, n)
    assert cloud.triangle_count == 0 and cloud.triangles.shape == (0, 3)
    assert vstree.Mesh(p, t.astype(np.int64)).triangle_count == len(t)
    assert vstree.Mesh(p).normals is None


def test_simplify_gives_a_smaller_mesh_and_statistics(shape):
    p, t, _ = shape
    result = vstree.simplify(vstree.Mesh(p, t), error=2e-3, keep_topology="off")
    out, s = result.mesh, result.stats
    assert 10 < out.vertex_count < len(p)
    assert s["output_vertices"] == out.vertex_count and s["output_triangles"] == out.triangle_count
    assert s["input_triangles"] == len(t) and s["clusters"] >= out.vertex_count
    assert s["t_nodes"] > 0 and s["nodes"] == s["v_nodes"] + s["t_nodes"] + s["s_nodes"]
    assert s["seconds_total"] >= s["seconds_tree"] >= 0
    assert out.triangles.max() < out.vertex_count
    coarser = vstree.simplify(vstree.Mesh(p, t), error=2e-2).mesh
    assert coarser.vertex_count < out.vertex_count
    octree = vstree.simplify(vstree.Mesh(p, t), error=2e-3, tree_kind="octree").stats
    assert octree["t_nodes"] == 0


def test_every_metric_has_a_valid_default_and_a_size_ignores_the_bound(shape):
    # The density metric counts samples per cell: the struct's default 1e-3 is read as its own
    # default (16), and with a size the bound is neither used nor checked (issue 26, item 9).
    p, t, _ = shape
    mesh = vstree.Mesh(p, t)
    for metric in ("l2", "l21", "density"):
        out, s = vstree.simplify(mesh, metric=metric, keep_topology="off")
        assert 0 < out.triangle_count < len(t), metric
        out, s = vstree.simplify(mesh, metric=metric, error=float("nan"), target_faces=300)
        assert abs(out.triangle_count - 300) <= 3, (metric, out.triangle_count)


def test_simplify_to_a_size_keeps_a_closed_torus_closed(shape):
    p, t, _ = shape
    mesh = vstree.Mesh(p, t)
    for target in (len(t) // 10, len(t) // 50, 100):
        for keep in ("auto", "on", True):
            out, s = vstree.simplify(mesh, target_faces=target, keep_topology=keep)
            assert abs(out.triangle_count - target) <= max(2, target // 100), (target, out.triangle_count)
            assert s["kept_topology"] == 1 and s["target_faces"] == target
            assert euler_genus(out) == (1, True)
        out, s = vstree.simplify(mesh, target_faces=target, keep_topology=False)
        assert s["kept_topology"] == 0 and abs(out.triangle_count - target) <= max(2, target // 100)
    out, s = vstree.simplify(mesh, ratio=0.05)
    assert s["target_faces"] == round(0.05 * len(t)) and euler_genus(out) == (1, True)
    assert s["size_missed"] is None
    # Below what a torus allows: the smallest closed torus the collapses reach, never empty.
    out, s = vstree.simplify(mesh, target_faces=1)
    assert 14 <= out.triangle_count <= 60 and euler_genus(out) == (1, True)
    assert "topology" in s["size_missed"]


def test_parameters_are_the_library_table():
    """Keywords, defaults and choices come from the library's table: the C structs' fields in
    order, the _default() functions' values, and every choice name accepted by its keyword."""
    import vstree._ffi as ffi

    structs = {
        "simplify": (ffi.SimplifyParams, vstree.lib.vstree_simplify_params_default()),
        "reconstruct": (ffi.ReconstructParams, vstree.lib.vstree_reconstruct_params_default()),
        "normals": (ffi.NormalParams, vstree.lib.vstree_normal_params_default()),
    }
    for call, (struct, defaults) in structs.items():
        table = vstree.parameters(call)
        assert [p.name for p in table] == [name for name, _ in struct._fields_ if name != "struct_size"]
        for p in table:
            value = getattr(defaults, p.name)
            if p.kind == "choice":
                assert [c.value for c in p.choices] == list(range(len(p.choices))), p.name
                assert p.choices[value].name == p.default, p.name
                for c in p.choices:
                    assert vstree._ENUMS[p.name][c.name] == c.value
            else:
                assert value == pytest.approx(p.default, rel=1e-7), p.name
            assert p.min <= (value if p.kind != "choice" else 0) <= p.max, p.name
            assert p.label and p.help, p.name
    assert {p.call for p in vstree.parameters()} == {"simplify", "reconstruct", "normals"}
    levels = next(p for p in vstree.parameters("reconstruct") if p.name == "max_levels")
    assert (levels.min, levels.max, levels.default, levels.flag) == (0, 12, 6, "levels")
    with pytest.raises(ValueError, match="is not one of"):
        vstree.parameters("decimate")


def test_a_ply_file_is_simplified_streaming_without_being_loaded(shape, tmp_path):
    p, t, _ = shape
    path = str(tmp_path / "torus.ply")
    vstree.Mesh(p, t).save(path)
    out, s = vstree.simplify_ply_file(path, target_faces=400)
    assert abs(out.triangle_count - 400) <= 1 and s["kept_topology"] == 0
    assert s["input_triangles"] == len(t) and s["target_faces"] == 400
    stages = []
    vstree.simplify_ply_file(path, target_faces=400, progress=lambda f, stage: stages.append(stage) or True)
    assert "reading the faces" in stages and "clustering" in stages
    with pytest.raises(vstree.VstreeError, match="keeping the topology needs the whole mesh"):
        vstree.simplify_ply_file(path, target_faces=400, keep_topology="on")
    with pytest.raises(vstree.VstreeError, match="needs a target size"):
        vstree.simplify_ply_file(path)
    with pytest.raises(vstree.VstreeError, match="No such file"):
        vstree.simplify_ply_file(str(tmp_path / "missing.ply"), target_faces=10)
    with pytest.raises(vstree.CancelledError):
        vstree.simplify_ply_file(path, target_faces=400, progress=lambda f, stage: False)


def test_point_clouds_with_normals_simplify_to_points(shape):
    p, _, n = shape
    result = vstree.simplify(vstree.Mesh(p, None, n), metric="density", error=16)
    assert result.mesh.triangle_count == 0 and result.mesh.has_normals
    assert result.stats["output_vertices"] == result.stats["clusters"]


@pytest.mark.parametrize(
    "field, value",
    [
        ("error", 0.0),
        ("error", float("nan")),
        ("error", -1.0),
        ("d_a", 2.0),
        ("d_d", float("nan")),
        ("max_depth", 0),
        ("max_depth", 99),
        ("threads", 5000),
        ("min_cell_size", 1.0),
        ("tree_kind", 7),
        ("metric", -1),
        ("sampling", 2**40),
        ("max_depth", -1),
    ],
)
def test_bad_parameters_name_the_field(shape, field, value):
    p, t, _ = shape
    with pytest.raises(vstree.VstreeError) as e:
        vstree.simplify(vstree.Mesh(p, t), **{field: value})
    assert e.value.status == vstree.Status.INVALID_PARAMETER
    assert "`%s`" % field in e.value.message


def test_bad_arrays(shape):
    p, t, n = shape
    bad = p.copy()
    bad[5, 1] = np.nan
    with pytest.raises(vstree.VstreeError) as e:
        vstree.Mesh(bad, t)
    assert e.value.status == vstree.Status.INVALID_INPUT and "vertex 5" in e.value.message
    wrong = t.copy()
    wrong[3, 2] = len(p)
    with pytest.raises(vstree.VstreeError, match="triangle 3 uses vertex"):
        vstree.Mesh(p, wrong)
    with pytest.raises(vstree.VstreeError) as e:
        vstree.Mesh(np.zeros((0, 3)))
    assert e.value.status == vstree.Status.INVALID_INPUT
    with pytest.raises(ValueError):
        vstree.Mesh(p[:, :2])
    with pytest.raises(ValueError):
        vstree.Mesh(p, t.astype(np.int64) - 1)
    with pytest.raises(TypeError):
        vstree.Mesh(p, t.astype(np.float32))
    with pytest.raises(ValueError):
        vstree.Mesh(p, t, n[:-1])
    with pytest.raises(TypeError):
        vstree.simplify(vstree.Mesh(p, t), eror=1e-3)
    with pytest.raises(vstree.VstreeError, match="normals") as e:
        vstree.simplify(vstree.Mesh(p))
    assert e.value.status == vstree.Status.INVALID_INPUT


def test_progress_reports_and_cancels(shape):
    p, t, _ = shape
    mesh = vstree.Mesh(p, t)
    seen = []
    vstree.simplify(mesh, progress=lambda f, stage: seen.append((f, stage)))
    fractions = [f for f, _ in seen]
    assert len(seen) >= 3 and fractions == sorted(fractions) and fractions[-1] == 1.0
    assert seen[-1][1] == "done"
    for k in range(len(seen)):
        calls = []

        def stop_at_k(f, stage, k=k):
            calls.append(f)
            return len(calls) <= k

        with pytest.raises(vstree.CancelledError) as e:
            vstree.simplify(mesh, progress=stop_at_k)
        assert e.value.status == vstree.Status.CANCELLED and len(calls) == k + 1


def test_an_exception_in_the_callback_comes_out_of_the_call(shape):
    p, t, _ = shape

    def boom(f, stage):
        if f > 0.5:
            raise KeyError("host gave up")

    with pytest.raises(KeyError, match="host gave up"):
        vstree.Tree(vstree.Mesh(p, t), progress=boom)


def test_files_and_memory(tmp_path, shape):
    p, t, n = shape
    mesh = vstree.Mesh(p, t, n)
    for name, ascii in [("a.ply", False), ("b.ply", True), ("c.off", False), ("d.obj", False)]:
        path = tmp_path / name
        mesh.save(path, ascii=ascii)
        back = vstree.load(str(path))
        assert (back.vertex_count, back.triangle_count) == (len(p), len(t))
        same = vstree.Mesh.from_bytes(path.read_bytes(), name)
        np.testing.assert_array_equal(same.positions, back.positions)
    np.testing.assert_allclose(vstree.load(tmp_path / "a.ply").positions, p)
    with pytest.raises(vstree.VstreeError) as e:
        vstree.load(tmp_path / "missing.ply")
    assert e.value.status == vstree.Status.IO and "missing.ply" in e.value.message
    with pytest.raises(vstree.VstreeError) as e:
        vstree.Mesh.from_bytes(b"OFF\n3 1 0\n0 0 0\n", "broken.off")
    assert e.value.status == vstree.Status.PARSE and "broken.off" in e.value.message
    with pytest.raises(vstree.VstreeError) as e:
        mesh.save(tmp_path / "x.stl")
    assert e.value.status == vstree.Status.UNSUPPORTED_FORMAT


def test_tree_arrays_and_labels(shape):
    p, t, _ = shape
    mesh = vstree.Mesh(p, t)
    tree = vstree.Tree(mesh, error=2e-3)
    s = tree.stats
    nodes, layer, levels = tree.nodes, tree.t_nodes, tree.levels
    assert len(nodes) == s["nodes"] and len(layer) == s["t_nodes"] > 0
    assert len(levels) == s["max_depth"] + 1
    assert levels["leaves"].sum() == s["clusters"] and levels["t_nodes"].sum() == s["t_nodes"]
    assert (nodes["kind"][layer["node"]] == 1).all()
    np.testing.assert_allclose(np.linalg.norm(layer["normal"], axis=1), 1, atol=1e-5)
    assert s["max_cluster_error"] <= 2e-3 * 1.0001
    clusters = tree.vertex_labels()
    t_labels = tree.vertex_labels("t_node")
    assert clusters.shape == (len(p),) and clusters.max() < s["clusters"]
    assert ((t_labels < s["t_nodes"]) | (t_labels == vstree.Tree.NO_INDEX)).all()
    leaves = nodes[nodes["child_count"] == 0]
    np.testing.assert_array_equal(leaves["cluster"], np.arange(s["clusters"]))
    np.testing.assert_array_equal(leaves["t_node"][clusters], t_labels)
    with pytest.raises(ValueError):
        tree.vertex_labels("depth")
    tree.close()
    with pytest.raises(ValueError):
        tree.nodes


def test_threads_simplifying_different_meshes_match_one_thread():
    meshes = [vstree.Mesh(*torus(48 + 16 * i, 24 + 4 * i, 0.1 * (i + 1))[:2]) for i in range(4)]
    expected = [vstree.simplify(m, threads=1).mesh.positions for m in meshes]
    results = [None] * 8
    errors = []

    def work(k):
        try:
            results[k] = vstree.simplify(meshes[k % 4], threads=k % 3).mesh.positions
        except Exception as e:  # pragma: no cover - reported below
            errors.append(e)

    threads = [threading.Thread(target=work, args=(k,)) for k in range(8)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    assert not errors
    for k, out in enumerate(results):
        np.testing.assert_array_equal(out, expected[k % 4])


def _import_in_subprocess(env, path):
    code = "import vstree, sys; print(vstree.library_path)"
    return subprocess.run(
        [sys.executable, "-c", code], env=env, cwd=path, capture_output=True, text=True
    )


def test_library_next_to_the_module_and_bad_paths(tmp_path):
    lib = os.environ["VSTREE_LIBRARY"]
    package = tmp_path / "vstree"
    package.mkdir()
    for name in ("__init__.py", "_ffi.py"):
        src = os.path.join(ROOT, "bindings", "python", "vstree", name)
        (package / name).write_text(open(src).read())
    (package / "libvstree.so").write_bytes(open(lib, "rb").read())
    env = {k: v for k, v in os.environ.items() if k != "VSTREE_LIBRARY"}
    env["PYTHONPATH"] = str(tmp_path)
    found = _import_in_subprocess(env, tmp_path)
    assert found.returncode == 0, found.stderr
    assert found.stdout.strip() == str(package / "libvstree.so")
    env["VSTREE_LIBRARY"] = str(tmp_path / "nowhere.so")
    missing = _import_in_subprocess(env, tmp_path)
    assert missing.returncode != 0 and "VSTREE_LIBRARY" in missing.stderr
    assert "nowhere.so" in missing.stderr


# ---- reconstruction and normal estimation ----------------------------------------------------


def fibonacci_sphere(count=3000, radius=1.0):
    """Evenly spread points on a sphere (no normals)."""
    i = np.arange(count) + 0.5
    z = 1 - 2 * i / count
    r = np.sqrt(1 - z * z)
    phi = np.pi * (3 - np.sqrt(5)) * i
    return (radius * np.stack([r * np.cos(phi), r * np.sin(phi), z], -1)).astype(np.float32)


def torus_cloud(count=6000, seed=3):
    """Random points on a torus (R 1, r 0.35) and their outward normals."""
    rng = np.random.default_rng(seed)
    u, v = rng.uniform(0, 2 * np.pi, (2, count))
    n = np.stack([np.cos(v) * np.cos(u), np.cos(v) * np.sin(u), np.sin(v)], -1)
    p = np.stack([np.cos(u), np.sin(u), 0 * u], -1) + 0.35 * n
    return p.astype(np.float32), n.astype(np.float32)


def euler_genus(mesh):
    """Genus from V - E + F of a closed mesh, and whether every edge has exactly two faces."""
    t = mesh.triangles.astype(np.int64)
    edges = np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1)
    unique, counts = np.unique(edges, axis=0, return_counts=True)
    chi = mesh.vertex_count - len(unique) + len(t)
    return (2 - chi) // 2, bool(np.all(counts == 2))


def test_reconstruct_a_sphere_from_numpy_points():
    points = fibonacci_sphere()
    reports = []
    result = vstree.reconstruct(points, max_levels=2, progress=lambda f, s: reports.append(f))
    mesh, s = result.mesh, result.stats
    assert len(reports) >= 3 and reports[-1] == 1.0 and reports == sorted(reports)
    assert mesh.vertex_count > 100 and mesh.has_normals
    assert s["output_vertices"] == mesh.vertex_count and s["output_triangles"] == mesh.triangle_count
    assert s["input_points"] == len(points) and s["normals_estimated"] == len(points)
    assert s["base_genus"] == 0 and euler_genus(mesh) == (0, True)
    assert 0 < s["final_error"] <= s["final_max_error"] < 0.05
    # A sphere has no handles to thicken; two levels asked, two done, unless detail ran out.
    assert s["thickened"] is False
    assert s["stopped"] == ("max_levels" if s["levels"] == 2 else "no_detail"), s
    radii = np.linalg.norm(mesh.positions, axis=1)
    assert np.all(np.abs(radii - 1) < 0.05), (radii.min(), radii.max())
    # Outward normals; triangles counter-clockwise seen from outside (all but the few that
    # displacement folds: 95% measured on this cloud).
    p = mesh.positions[mesh.triangles]
    face_normals = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    assert np.mean(np.einsum("ij,ij->i", face_normals, p.mean(axis=1)) > 0) > 0.9
    assert np.mean(np.einsum("ij,ij->i", mesh.normals, mesh.positions) > 0) > 0.99


def test_reconstruct_leaves_out_a_stray_point_and_counts_it():
    # One point 1000 diameters away made the base mesh empty (issue 26, item 8).
    points = np.vstack([fibonacci_sphere(), [[2000.0, 0.0, 0.0]]]).astype(np.float32)
    mesh, s = vstree.reconstruct(points, max_levels=1)
    assert s["input_points"] - s["samples"] == 1
    assert euler_genus(mesh) == (0, True)
    assert np.abs(np.linalg.norm(mesh.positions, axis=1) - 1).max() < 0.02


def test_reconstruct_a_torus_with_and_without_normals():
    p, n = torus_cloud()
    with_normals = vstree.reconstruct(p, n, max_levels=2, max_grid_depth=7)
    assert with_normals.stats["normals_estimated"] == 0
    without = vstree.reconstruct(vstree.Mesh(p), max_levels=2, max_grid_depth=7)
    assert without.stats["normals_estimated"] == len(p)
    for r in (with_normals, without):
        assert r.stats["base_genus"] == 1 and euler_genus(r.mesh) == (1, True)
        assert r.stats["levels"] <= 2 and r.stats["t_nodes"] > 0
    # Same cloud, same parameters: the same mesh (results do not depend on threads either).
    again = vstree.reconstruct(p, n, max_levels=2, max_grid_depth=7, threads=1)
    np.testing.assert_array_equal(again.mesh.positions, with_normals.mesh.positions)
    np.testing.assert_array_equal(again.mesh.triangles, with_normals.mesh.triangles)


def test_refinement_stops_are_named_by_the_library():
    # The names the statistics' "stopped" takes come from vstree_refinement_stopped_str().
    def name(value):
        return vstree._ffi.lib.vstree_refinement_stopped_str(value).decode()

    assert [name(v) for v in range(4)] == ["target", "no_detail", "max_levels", "triangle_budget"]
    assert name(4) == name(2**32 - 1) == "unknown"


def test_reconstruct_bad_input_and_parameters():
    p, n = torus_cloud(500)
    with pytest.raises(vstree.VstreeError) as e:
        vstree.reconstruct(p[:5])
    assert e.value.status == vstree.Status.INVALID_INPUT and "5 points" in e.value.message
    for key, value in [
        ("max_levels", 13),
        ("max_grid_depth", 3),
        ("error", float("nan")),
        ("target_distance", -1.0),
        ("min_displaced", 2.0),
        ("trim", float("inf")),
        ("neighbours", 1),
        ("orient", 9),
        ("max_triangles", 0),
        ("threads", 5000),
        ("max_levels", -1),
    ]:
        with pytest.raises(vstree.VstreeError) as e:
            vstree.reconstruct(p, n, **{key: value})
        assert e.value.status == vstree.Status.INVALID_PARAMETER, key
        assert "`%s`" % key in e.value.message, e.value.message
    with pytest.raises(TypeError):
        vstree.reconstruct(p, n, metric="l2")
    with pytest.raises(ValueError):
        vstree.reconstruct(p, orient="inward")
    with pytest.raises(vstree.CancelledError):
        vstree.reconstruct(p, n, progress=lambda f, s: f < 0.5)

    class Stop(Exception):
        pass

    def boom(f, s):
        raise Stop()

    with pytest.raises(Stop):
        vstree.reconstruct(p, n, progress=boom)


def test_estimate_normals_on_points_without_normals():
    points = fibonacci_sphere(2000)
    result = vstree.estimate_normals(points)
    normals, report = result.mesh.normals, result.report
    assert normals.shape == points.shape and normals.dtype == np.float32
    np.testing.assert_allclose(np.linalg.norm(normals, axis=1), 1, atol=1e-5)
    assert np.all(np.einsum("ij,ij->i", normals, points) > 0.99)  # outward, accurate
    assert report["estimated"] == len(points) and report["oriented"] == 1
    assert report["neighbours"] == 16 and report["components"] >= 1
    np.testing.assert_array_equal(result.mesh.positions, points)

    # Torus: inward orientation fixed on request; kept as given otherwise.
    p, n = torus_cloud(4000)
    flipped = n.copy()
    flipped[::2] *= -1
    kept = vstree.estimate_normals(p, flipped)
    np.testing.assert_array_equal(kept.mesh.normals, flipped)
    assert kept.report["estimated"] == 0 and kept.report["oriented"] == 0
    fixed = vstree.estimate_normals(vstree.Mesh(p, None, flipped), reorient_given=True, neighbours=12)
    assert np.mean(np.einsum("ij,ij->i", fixed.mesh.normals, n) > 0) > 0.99
    assert fixed.report["flipped"] > 0 and fixed.report["neighbours"] == 12
    up = vstree.estimate_normals(p, orient="propagate")
    assert up.report["oriented"] == 1
    # A mesh keeps its triangles.
    tp, tt, _ = torus()
    assert vstree.estimate_normals(vstree.Mesh(tp, tt)).mesh.triangle_count == len(tt)


def test_estimate_normals_errors():
    points = fibonacci_sphere(200)
    with pytest.raises(vstree.VstreeError) as e:
        vstree.estimate_normals(points[:2])
    assert e.value.status == vstree.Status.INVALID_INPUT
    line = np.stack([np.arange(20), 2 * np.arange(20), np.zeros(20)], -1)
    with pytest.raises(vstree.VstreeError) as e:
        vstree.estimate_normals(line)
    assert e.value.status == vstree.Status.INVALID_INPUT
    for key, value in [("neighbours", 300), ("orient", -1), ("reorient_given", 2), ("threads", 2000)]:
        with pytest.raises(vstree.VstreeError) as e:
            vstree.estimate_normals(points, **{key: value})
        assert e.value.status == vstree.Status.INVALID_PARAMETER and "`%s`" % key in e.value.message
    with pytest.raises(vstree.CancelledError):
        vstree.estimate_normals(points, progress=lambda f, s: False)
    with pytest.raises(TypeError):
        vstree.estimate_normals(points, error=1e-3)


def test_a_model_far_from_the_origin_keeps_its_detail(tmp_path):
    # A unit sphere 1e8 away, as text: float32 alone would round it to a grid of 8 units.
    p, t, n = torus()
    # Jittered, so that no point lies exactly on a cell border (the grid's points do), where
    # rounding at 1e-8 could move it to the neighbouring cell.
    p = (p + np.random.default_rng(0).normal(0, 1e-3, p.shape)).astype(np.float32)
    far = p.astype(np.float64) + 1e8
    path = tmp_path / "far.xyz"
    path.write_text("".join("%r %r %r %r %r %r\n" % tuple(map(float, (*q, *m))) for q, m in zip(far, n)))
    cloud = vstree.Mesh.load(str(path))
    np.testing.assert_allclose(cloud.positions_f64, far, rtol=0, atol=1e-6)
    assert np.abs(cloud.positions.astype(np.float64) - far).max() > 0.1
    simplified = vstree.simplify(cloud, error=2e-3).mesh
    reference = vstree.simplify(vstree.Mesh(p, None, n), error=2e-3).mesh
    assert simplified.vertex_count == reference.vertex_count
    # The same clusters (at 1e8 in float32 alone they would be 4 units off).
    np.testing.assert_allclose(simplified.positions_f64 - 1e8, reference.positions_f64, rtol=0, atol=1e-5)


# ---- float64 input ---------------------------------------------------------------------------


@pytest.mark.parametrize("offset", [1e6, 1e7, 1e8])
def test_float64_positions_far_from_the_origin_are_kept_as_a_file_keeps_them(offset):
    # A unit sphere 1e6 to 1e8 away: float32 coordinates there are 1/16 to 8 apart, so it came
    # back with radius errors of 0.24 at 1e6 and as one point at 1e7 and beyond.
    sphere = fibonacci_sphere(3000).astype(np.float64)
    far = sphere + offset
    mesh = vstree.Mesh(far, None, sphere)
    # The readers' rule: relative to the box's centre rounded to float32, in float32.
    origin = ((far.min(0) + far.max(0)) / 2).astype(np.float32).astype(np.float64)
    expected = (far - origin).astype(np.float32).astype(np.float64) + origin
    np.testing.assert_array_equal(mesh.positions_f64, expected)
    radius_error = np.abs(np.linalg.norm(mesh.positions_f64 - offset, axis=1) - 1).max()
    assert radius_error < 1e-6, radius_error
    # float32 input keeps the float32 path: stored as given.
    as_float32 = far.astype(np.float32)
    np.testing.assert_array_equal(vstree.Mesh(as_float32).positions_f64, as_float32.astype(np.float64))


# ---- copies and pickles ----------------------------------------------------------------------


def _same_mesh(a, b):
    np.testing.assert_array_equal(a.positions_f64, b.positions_f64)
    np.testing.assert_array_equal(a.triangles, b.triangles)
    if a.normals is None:
        assert b.normals is None
    else:
        np.testing.assert_array_equal(a.normals, b.normals)


COPIES = {
    "copy": copy.copy,
    "deepcopy": copy.deepcopy,
    "pickle": lambda m: pickle.loads(pickle.dumps(m)),
}


@pytest.mark.parametrize("how", sorted(COPIES))
def test_a_copied_or_pickled_mesh_is_an_independent_equal_mesh(shape, how):
    mesh = vstree.Mesh(*shape)
    p, t, n = torus(16, 8)
    far = vstree.Mesh(p.astype(np.float64) + np.array([1e6, -3e7, 1e8]), t, n)
    for original in (mesh, far, vstree.Mesh(p), vstree.Mesh(p, None, n)):
        copied = COPIES[how](original)
        assert copied is not original and copied._handle != original._handle
        _same_mesh(copied, original)  # exact, far from the origin too
    source = vstree.Mesh(p, t)
    copied = COPIES[how](source)
    source.close()
    assert copied.vertex_count == len(p)  # its own handle: closing the original leaves it
    with pytest.raises(ValueError, match="^the mesh was closed$"):
        COPIES[how](source)


TREE_REFUSED = (
    "vstree.Tree cannot be copied or pickled: it owns a tree in the library, which a copy would share and "
    "free twice, and a pickle would store only its address; build another with vstree.Tree(mesh, **params), "
    "or copy or pickle its arrays (stats, nodes, t_nodes, levels, vertex_labels()), which are plain Python and "
    "numpy objects"
)


@pytest.mark.parametrize("how", sorted(COPIES))
def test_a_tree_refuses_to_be_copied_or_pickled(shape, how):
    with vstree.Tree(vstree.Mesh(*shape)) as tree:
        with pytest.raises(TypeError) as e:
            COPIES[how](tree)
        assert str(e.value) == TREE_REFUSED
        assert tree.nodes.size > 0


COPY_THEN_DELETE = """
import copy, gc, pickle
import vstree
from test_vstree import torus
p, t, n = torus(16, 8)
mesh = vstree.Mesh(p, t, n)
tree = vstree.Tree(mesh)
copies = [copy.copy(mesh), copy.deepcopy(mesh), pickle.loads(pickle.dumps(mesh))]
for how in (copy.copy, copy.deepcopy, pickle.dumps):
    try:
        copies.append(how(tree))
    except TypeError:
        pass
del mesh, tree, copies
gc.collect()
print("all freed once")
"""


def test_copies_then_deleting_everything_does_not_crash():
    # Copies that shared the handle freed it twice: a segmentation fault (so in a subprocess).
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([os.path.join(ROOT, "bindings", "python"), os.path.join(ROOT, "tests", "python")])
    run = subprocess.run([sys.executable, "-c", COPY_THEN_DELETE], env=env, capture_output=True, text=True, timeout=120)
    assert (run.returncode, run.stdout, run.stderr) == (0, "all freed once\n", "")


# ---- closing what a running call uses ----------------------------------------------------------

IN_USE = (
    "Mesh.close: the mesh is in use by %s, which is still running (close() was called from its progress "
    "callback or from another thread); the library reads it, so it cannot be freed now: close it after the "
    "call returns"
)
CALLS_WITH_PROGRESS = {
    "vstree.simplify": lambda mesh, progress: vstree.simplify(mesh, progress=progress),
    "vstree.Tree": lambda mesh, progress: vstree.Tree(mesh, progress=progress),
    "vstree.reconstruct": lambda mesh, progress: vstree.reconstruct(mesh, progress=progress, max_levels=1),
    "vstree.estimate_normals": lambda mesh, progress: vstree.estimate_normals(mesh, progress=progress),
}


@pytest.mark.parametrize("who", sorted(CALLS_WITH_PROGRESS))
def test_closing_the_mesh_from_the_progress_callback_is_refused(who):
    # The library went on reading the freed mesh (valgrind: hundreds of invalid reads).
    points = fibonacci_sphere(2000)
    mesh = vstree.Mesh(points, None, None if who == "vstree.estimate_normals" else points)
    refused = []

    def progress(fraction, stage):
        try:
            mesh.close()
        except RuntimeError as e:
            refused.append(str(e))
        return True

    CALLS_WITH_PROGRESS[who](mesh, progress)
    assert refused and set(refused) == {IN_USE % who}
    np.testing.assert_array_equal(mesh.positions, points)  # still open, and whole
    mesh.close()
    with pytest.raises(ValueError, match="^the mesh was closed$"):
        mesh.vertex_count


def test_closing_the_mesh_from_the_callback_cancels_when_the_error_is_not_caught(shape):
    mesh = vstree.Mesh(*shape)
    with pytest.raises(RuntimeError) as e:
        vstree.simplify(mesh, progress=lambda fraction, stage: mesh.close())
    assert str(e.value) == IN_USE % "vstree.simplify"
    assert vstree.simplify(mesh).mesh.vertex_count > 0


def test_closing_the_mesh_from_another_thread_during_a_call_is_refused(shape):
    # ctypes releases the GIL during the call: another thread runs meanwhile. The callback
    # holds the call at its first report while this thread tries to close the mesh.
    mesh = vstree.Mesh(*shape)
    inside, release, results = threading.Event(), threading.Event(), []

    def progress(fraction, stage):
        inside.set()
        return release.wait(60)

    worker = threading.Thread(target=lambda: results.append(vstree.simplify(mesh, progress=progress)))
    worker.start()
    try:
        assert inside.wait(60)
        with pytest.raises(RuntimeError) as e:
            mesh.close()
        assert str(e.value) == IN_USE % "vstree.simplify"
    finally:
        release.set()
        worker.join(60)
    assert results[0].mesh.vertex_count > 0
    mesh.close()


def test_closing_a_tree_or_mesh_while_a_call_holds_it_is_refused(shape):
    # Queries and saves have no callback; what holds them is the same use count.
    mesh = vstree.Mesh(*shape)
    tree = vstree.Tree(mesh)
    for thing, who in [(tree, "Tree.nodes"), (mesh, "Mesh.save")]:
        with thing._use(who):
            with pytest.raises(RuntimeError, match="in use by %s, which is still running" % who):
                thing.close()
        thing.close()
        thing.close()


def test_threads_reading_a_mesh_while_another_closes_it_see_it_whole_or_closed(shape):
    for _ in range(20):
        mesh = vstree.Mesh(*shape)
        seen, start = [], threading.Barrier(5)

        def read():
            start.wait()
            for _ in range(50):
                try:
                    seen.append(mesh.positions.shape)
                except (ValueError, RuntimeError):
                    pass

        def close():
            start.wait()
            while True:
                try:
                    return mesh.close()
                except RuntimeError:  # a reader holds it: try again
                    pass

        threads = [threading.Thread(target=read) for _ in range(4)] + [threading.Thread(target=close)]
        for th in threads:
            th.start()
        for th in threads:
            th.join()
        assert set(seen) <= {shape[0].shape}
        with pytest.raises(ValueError):
            mesh.positions
