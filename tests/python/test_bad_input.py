"""Bad input at the Python entry points, as a table: each case names the call, the exact
exception type, the C status (VstreeError.status) when the library refused it, and the exact
message (or an exact part of it: the function, the parameter, the value, the file and line).
What the library says is pinned as it is today: a change of wording fails here on purpose.

``{tmp}`` in a message stands for the test's tmp_path."""

import copy
import os
import pathlib
import pickle

import numpy as np
import pytest

import vstree
from test_vstree import torus

S = vstree.Status


def grid_torus(rings=16, segments=8):
    """A small closed torus without bumps: (positions, triangles, normals)."""
    return torus(rings, segments, bump=0.0)


def sphere_points(count=200):
    """Points on the unit sphere; they are their own outward normals."""
    i = np.arange(count) + 0.5
    z = 1 - 2 * i / count
    r = np.sqrt(1 - z * z)
    phi = np.pi * (3 - np.sqrt(5)) * i
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], -1).astype(np.float32)


P, T, N = grid_torus()
THREE = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float32)
UP = np.array([[0, 0, 1]] * 3, np.float32)
CLOUD = sphere_points()


class Context:
    """What a case's call gets: a tmp directory to write files in, and fresh objects."""

    def __init__(self, tmp):
        self.tmp = tmp

    def write(self, name, content):
        path = self.tmp / name
        if isinstance(content, str):
            content = content.encode()
        path.write_bytes(content)
        return str(path)

    def mesh(self):
        return vstree.Mesh(P, T)

    def closed_mesh(self):
        mesh = vstree.Mesh(P, T)
        mesh.close()
        return mesh

    def closed_tree(self):
        with vstree.Tree(self.mesh()) as tree:
            pass
        return tree


def case(id, call, exc, status, message, exact=True):
    """One row: ``call(ctx)`` must raise exactly ``exc`` with ``status`` (None: not a
    VstreeError) and ``message``: the whole message, or when ``exact`` is False a part of it
    (or a tuple of parts, each of which must be in it)."""
    return pytest.param(call, exc, status, message, exact, id=id)


def with_item(array, index, value):
    out = np.array(array)
    out[index] = value
    return out


# ---- NUL bytes in paths and names ----------------------------------------------------------

NUL_CASES = [
    case(
        "save-str-path-with-nul",
        lambda c: c.mesh().save(str(c.tmp / "victim.ply") + "\0-simplified.ply"),
        ValueError,
        None,
        "path contains an embedded null byte: '{tmp}/victim.ply\\x00-simplified.ply'",
    ),
    case(
        "save-bytes-path-with-nul",
        lambda c: c.mesh().save(os.fsencode(c.tmp) + b"/victim.ply\0.off"),
        ValueError,
        None,
        "path contains an embedded null byte: b'{tmp}/victim.ply\\x00.off'",
    ),
    case(
        "save-pathlike-with-nul",
        lambda c: c.mesh().save(c.tmp / "victim.ply\0x.obj"),
        ValueError,
        None,
        "path contains an embedded null byte: '{tmp}/victim.ply\\x00x.obj'",
    ),
    case(
        "load-str-path-with-nul",
        lambda c: vstree.Mesh.load(c.write("cube.off", "OFF\n") + "\0.ply"),
        ValueError,
        None,
        "path contains an embedded null byte: '{tmp}/cube.off\\x00.ply'",
    ),
    case(
        "module-load-bytes-path-with-nul",
        lambda c: vstree.load(os.fsencode(c.tmp) + b"/a.ply\0"),
        ValueError,
        None,
        "path contains an embedded null byte: b'{tmp}/a.ply\\x00'",
    ),
    case(
        "from-bytes-name-with-nul",
        lambda c: vstree.Mesh.from_bytes(b"OFF\n3 1 0\n0 0 0\n", "scan.off\0.ply"),
        ValueError,
        None,
        "name contains an embedded null byte: 'scan.off\\x00.ply'",
    ),
    case(
        "from-bytes-bytes-name-with-nul",
        lambda c: vstree.Mesh.from_bytes(b"", b"\0ply"),
        ValueError,
        None,
        "name contains an embedded null byte: b'\\x00ply'",
    ),
]


# ---- closed objects: a clear error, not the C library's NULL pointer -----------------------

MESH_CLOSED = "the mesh was closed"
TREE_CLOSED = "the tree was closed"


def closed_result_mesh(c):
    with vstree.simplify(c.mesh()).mesh as mesh:
        pass
    return mesh.positions


CLOSED_CASES = [
    case("closed-mesh-save", lambda c: c.closed_mesh().save(c.tmp / "out.ply"), ValueError, None, MESH_CLOSED),
    case("closed-mesh-vertex-count", lambda c: c.closed_mesh().vertex_count, ValueError, None, MESH_CLOSED),
    case("closed-mesh-triangle-count", lambda c: c.closed_mesh().triangle_count, ValueError, None, MESH_CLOSED),
    case("closed-mesh-has-normals", lambda c: c.closed_mesh().has_normals, ValueError, None, MESH_CLOSED),
    case("closed-mesh-positions", lambda c: c.closed_mesh().positions, ValueError, None, MESH_CLOSED),
    case("closed-mesh-normals", lambda c: c.closed_mesh().normals, ValueError, None, MESH_CLOSED),
    case("closed-mesh-triangles", lambda c: c.closed_mesh().triangles, ValueError, None, MESH_CLOSED),
    case("closed-result-mesh-positions", closed_result_mesh, ValueError, None, MESH_CLOSED),
    case("simplify-closed-mesh", lambda c: vstree.simplify(c.closed_mesh()), ValueError, None, MESH_CLOSED),
    case("tree-of-closed-mesh", lambda c: vstree.Tree(c.closed_mesh()), ValueError, None, MESH_CLOSED),
    case("reconstruct-closed-mesh", lambda c: vstree.reconstruct(c.closed_mesh()), ValueError, None, MESH_CLOSED),
    case("normals-of-closed-mesh", lambda c: vstree.estimate_normals(c.closed_mesh()), ValueError, None, MESH_CLOSED),
    case("closed-tree-nodes", lambda c: c.closed_tree().nodes, ValueError, None, TREE_CLOSED),
    case("closed-tree-t-nodes", lambda c: c.closed_tree().t_nodes, ValueError, None, TREE_CLOSED),
    case("closed-tree-levels", lambda c: c.closed_tree().levels, ValueError, None, TREE_CLOSED),
    case("closed-tree-vertex-labels", lambda c: c.closed_tree().vertex_labels("t_node"), ValueError, None, TREE_CLOSED),
    case("copy-closed-mesh", lambda c: copy.copy(c.closed_mesh()), ValueError, None, MESH_CLOSED),
    case("pickle-closed-mesh", lambda c: pickle.dumps(c.closed_mesh()), ValueError, None, MESH_CLOSED),
]


# ---- copies of what cannot be copied, and closing what a running call uses --------------------

TREE_NOT_COPIED = (
    "vstree.Tree cannot be copied or pickled: it owns a tree in the library, which a copy would share and free "
    "twice, and a pickle would store only its address; build another with vstree.Tree(mesh, **params), or copy "
    "or pickle its arrays (stats, nodes, t_nodes, levels, vertex_labels()), which are plain Python and numpy "
    "objects"
)
IN_USE = (
    "Mesh.close: the mesh is in use by %s, which is still running (close() was called from its progress "
    "callback or from another thread); the library reads it, so it cannot be freed now: close it after the "
    "call returns"
)


def close_in_callback(call):
    """``call(mesh, progress)`` with a callback that closes the mesh the call is using."""

    def run(c):
        mesh = vstree.Mesh(CLOUD, None, CLOUD) if call is not vstree.estimate_normals else vstree.Mesh(CLOUD)
        return call(mesh, progress=lambda fraction, stage: mesh.close())

    return run


IN_USE_CASES = [
    case("copy-tree", lambda c: copy.copy(vstree.Tree(c.mesh())), TypeError, None, TREE_NOT_COPIED),
    case("deepcopy-tree", lambda c: copy.deepcopy(vstree.Tree(c.mesh())), TypeError, None, TREE_NOT_COPIED),
    case("pickle-tree", lambda c: pickle.dumps(vstree.Tree(c.mesh())), TypeError, None, TREE_NOT_COPIED),
    case("simplify-closes-its-mesh", close_in_callback(vstree.simplify), RuntimeError, None,
         IN_USE % "vstree.simplify"),
    case("tree-closes-its-mesh", close_in_callback(vstree.Tree), RuntimeError, None, IN_USE % "vstree.Tree"),
    case("reconstruct-closes-its-mesh", close_in_callback(vstree.reconstruct), RuntimeError, None,
         IN_USE % "vstree.reconstruct"),
    case("estimate-normals-closes-its-mesh", close_in_callback(vstree.estimate_normals), RuntimeError, None,
         IN_USE % "vstree.estimate_normals"),
]


# ---- parameters: the library's ranges, and the binding's types ------------------------------

NAN, INF = float("nan"), float("inf")
BAD = S.INVALID_PARAMETER


def simplify_with(**params):
    return lambda c: vstree.simplify(c.mesh(), **params)


def tree_with(**params):
    return lambda c: vstree.Tree(c.mesh(), **params)


def reconstruct_with(**params):
    return lambda c: vstree.reconstruct(CLOUD, CLOUD, **params)


def normals_with(**params):
    return lambda c: vstree.estimate_normals(CLOUD, **params)


ENUM_TREE = "must be one of 0 (VSTREE_TREE_KIND_VS_TREE), 1 (VSTREE_TREE_KIND_OCTREE)"
ENUM_METRIC = "must be one of 0 (VSTREE_METRIC_L2), 1 (VSTREE_METRIC_L21), 2 (VSTREE_METRIC_DENSITY)"
ENUM_SAMPLING = "must be one of 0 (VSTREE_SAMPLING_VERTICES), 1 (VSTREE_SAMPLING_FACE_CENTERS)"
ENUM_ORIENT = (
    "must be one of 0 (VSTREE_ORIENTATION_UNORIENTED), 1 (VSTREE_ORIENTATION_PROPAGATE), "
    "2 (VSTREE_ORIENTATION_PROPAGATE_MAJORITY), 3 (VSTREE_ORIENTATION_PROPAGATE_OUTWARD)"
)
ORIENT_NAMES = "'propagate', 'propagate_majority', 'propagate_outward', 'unoriented'"

PARAMETER_CASES = [
    # simplify: the library checks the ranges.
    case("simplify-error-negative", simplify_with(error=-1.0), vstree.VstreeError, BAD,
         "vstree_simplify: parameter `error`: -1: must be a finite number > 0"),
    case("simplify-error-zero", simplify_with(error=0.0), vstree.VstreeError, BAD,
         "vstree_simplify: parameter `error`: 0: must be a finite number > 0"),
    case("simplify-error-nan", simplify_with(error=NAN), vstree.VstreeError, BAD,
         "vstree_simplify: parameter `error`: NaN: must be a finite number > 0"),
    case("simplify-error-inf", simplify_with(error=INF), vstree.VstreeError, BAD,
         "vstree_simplify: parameter `error`: inf: must be a finite number > 0"),
    # A cloud that keeps nothing of its shape is an error, not one point (issue 26, item 14).
    case("simplify-three-points", lambda c: vstree.simplify(vstree.Mesh(THREE, None, UP)), vstree.VstreeError, BAD,
         "vstree_simplify: parameter `error`: 0.001: all 3 points collapsed into one (1 cluster for the whole "
         "model): the model is within this bound of too few planes; use a smaller bound (a flat model, within "
         "any bound of one plane, needs the density metric)"),
    case("simplify-d_a-too-big", simplify_with(d_a=2.0), vstree.VstreeError, BAD,
         "vstree_simplify: parameter `d_a`: 2: must be in [0, 1]"),
    case("simplify-d_a-nan", simplify_with(d_a=NAN), vstree.VstreeError, BAD,
         "vstree_simplify: parameter `d_a`: NaN: must be in [0, 1]"),
    case("simplify-d_d-negative", simplify_with(d_d=-0.5), vstree.VstreeError, BAD,
         "vstree_simplify: parameter `d_d`: -0.5: must be in [0, 1]"),
    case("simplify-d_d-inf", simplify_with(d_d=INF), vstree.VstreeError, BAD,
         "vstree_simplify: parameter `d_d`: inf: must be in [0, 1]"),
    case("simplify-max_depth-zero", simplify_with(max_depth=0), vstree.VstreeError, BAD,
         "vstree_simplify: parameter `max_depth`: 0: must be from 1 to 30"),
    case("simplify-max_depth-too-big", simplify_with(max_depth=99), vstree.VstreeError, BAD,
         "vstree_simplify: parameter `max_depth`: 99: must be from 1 to 30"),
    case("simplify-threads-too-many", simplify_with(threads=5000), vstree.VstreeError, BAD,
         "vstree_simplify: parameter `threads`: 5000: must be 0 (all cores) to 1024"),
    case("simplify-min_cell_size-one", simplify_with(min_cell_size=1.0), vstree.VstreeError, BAD,
         "vstree_simplify: parameter `min_cell_size`: 1: must be in [0, 1)"),
    case("simplify-min_cell_size-negative", simplify_with(min_cell_size=-1.0), vstree.VstreeError, BAD,
         "vstree_simplify: parameter `min_cell_size`: -1: must be in [0, 1)"),
    case("simplify-tree_kind-number", simplify_with(tree_kind=7), vstree.VstreeError, BAD,
         "vstree_simplify: parameter `tree_kind`: 7: " + ENUM_TREE),
    case("simplify-metric-number", simplify_with(metric=3), vstree.VstreeError, BAD,
         "vstree_simplify: parameter `metric`: 3: " + ENUM_METRIC),
    case("simplify-sampling-number", simplify_with(sampling=2), vstree.VstreeError, BAD,
         "vstree_simplify: parameter `sampling`: 2: " + ENUM_SAMPLING),
    # simplify to a size: a count the input has, a ratio in (0, 1], meshes only.
    case("simplify-target-above-input", simplify_with(target_faces=257), vstree.VstreeError, BAD,
         "vstree_simplify: parameter `target_faces`: 257: more than the input's 256 triangles"),
    case("simplify-target-on-a-cloud", lambda c: vstree.simplify(vstree.Mesh(CLOUD, None, CLOUD), target_faces=10),
         vstree.VstreeError, BAD,
         "vstree_simplify: parameter `target_faces`: 10 triangles asked of a point cloud: a target needs a mesh "
         "(use the error bound)"),
    case("simplify-target-negative", simplify_with(target_faces=-1), vstree.VstreeError, BAD,
         "vstree.simplify: parameter `target_faces`: -1 is out of range for the C field (uint32)"),
    case("simplify-keep_topology-number", simplify_with(keep_topology=3), vstree.VstreeError, BAD,
         "vstree_simplify: parameter `keep_topology`: 3: must be one of 0 (VSTREE_KEEP_TOPOLOGY_AUTO), "
         "1 (VSTREE_KEEP_TOPOLOGY_ON), 2 (VSTREE_KEEP_TOPOLOGY_OFF)"),
    case("simplify-keep_topology-unknown-name", simplify_with(keep_topology="sometimes"), ValueError, None,
         "vstree.simplify: parameter `keep_topology`: 'sometimes' is not one of 'auto', 'off', 'on'"),
    case("simplify-ratio-zero", simplify_with(ratio=0), vstree.VstreeError, BAD,
         "vstree.simplify: parameter `ratio`: 0: must be in (0, 1], a fraction of the input's triangles"),
    case("simplify-ratio-above-one", simplify_with(ratio=1.5), vstree.VstreeError, BAD,
         "vstree.simplify: parameter `ratio`: 1.5: must be in (0, 1], a fraction of the input's triangles"),
    case("simplify-ratio-nan", simplify_with(ratio=NAN), vstree.VstreeError, BAD,
         "vstree.simplify: parameter `ratio`: NaN: must be in (0, 1], a fraction of the input's triangles"),
    case("simplify-ratio-string", simplify_with(ratio="half"), TypeError, None,
         "vstree.simplify: parameter `ratio`: must be a real number, not 'half' (str)"),
    case("simplify-ratio-and-target", simplify_with(ratio=0.5, target_faces=10), TypeError, None,
         "vstree.simplify: give `ratio` or `target_faces`, not both"),
    case("simplify-ratio-on-a-cloud", lambda c: vstree.simplify(vstree.Mesh(CLOUD, None, CLOUD), ratio=0.5),
         vstree.VstreeError, BAD, "vstree.simplify: parameter `ratio`: 0.5: the input is a point cloud, with no triangles to take a fraction of: a ratio needs a mesh"),
    # simplify: what the binding refuses before C (names, types, C field widths).
    case("simplify-tree_kind-quadtree", simplify_with(tree_kind="quadtree"), ValueError, None,
         "vstree.simplify: parameter `tree_kind`: 'quadtree' is not one of 'octree', 'vstree'"),
    case("simplify-metric-unknown-name", simplify_with(metric="l1"), ValueError, None,
         "vstree.simplify: parameter `metric`: 'l1' is not one of 'density', 'l2', 'l21'"),
    case("simplify-sampling-unknown-name", simplify_with(sampling="edges"), ValueError, None,
         "vstree.simplify: parameter `sampling`: 'edges' is not one of 'face_centers', 'faces', 'vertices'"),
    case("simplify-tree_kind-float", simplify_with(tree_kind=1.5), TypeError, None,
         "vstree.simplify: parameter `tree_kind`: must be one of 'octree', 'vstree' or an integer, not 1.5 (float)"),
    case("simplify-tree_kind-beyond-int32", simplify_with(tree_kind=2**40), vstree.VstreeError, BAD,
         "vstree.simplify: parameter `tree_kind`: 1099511627776 is out of range for the C field (int32)"),
    case("simplify-max_depth-negative", simplify_with(max_depth=-1), vstree.VstreeError, BAD,
         "vstree.simplify: parameter `max_depth`: -1 is out of range for the C field (uint32)"),
    case("simplify-max_depth-2^32", simplify_with(max_depth=2**32), vstree.VstreeError, BAD,
         "vstree.simplify: parameter `max_depth`: 4294967296 is out of range for the C field (uint32)"),
    case("simplify-max_depth-float-not-truncated", simplify_with(max_depth=1.5), TypeError, None,
         "vstree.simplify: parameter `max_depth`: must be an integer, not 1.5 (float)"),
    case("simplify-max_depth-nan", simplify_with(max_depth=NAN), TypeError, None,
         "vstree.simplify: parameter `max_depth`: must be an integer, not nan (float)"),
    case("simplify-threads-negative-numpy", simplify_with(threads=np.int64(-1)), vstree.VstreeError, BAD,
         "vstree.simplify: parameter `threads`: -1 is out of range for the C field (uint32)"),
    case("simplify-error-string", simplify_with(error="big"), TypeError, None,
         "vstree.simplify: parameter `error`: must be a real number, not 'big' (str)"),
    case("simplify-error-none", simplify_with(error=None), TypeError, None,
         "vstree.simplify: parameter `error`: must be a real number, not None (NoneType)"),
    case("simplify-unknown-parameter", simplify_with(eror=1e-3), TypeError, None,
         "vstree.simplify: unknown parameter 'eror' (the parameters are tree_kind, metric, sampling, "
         "error, d_a, d_d, max_depth, threads, min_cell_size, keep_topology, target_faces)"),
    # Tree: the same parameters, its own function name.
    case("tree-tree_kind-quadtree", tree_with(tree_kind="quadtree"), ValueError, None,
         "vstree.Tree: parameter `tree_kind`: 'quadtree' is not one of 'octree', 'vstree'"),
    case("tree-error-nan", tree_with(error=NAN), vstree.VstreeError, BAD,
         "vstree_tree_build: parameter `error`: NaN: must be a finite number > 0"),
    case("tree-max_depth-too-big", tree_with(max_depth=31), vstree.VstreeError, BAD,
         "vstree_tree_build: parameter `max_depth`: 31: must be from 1 to 30"),
    case("tree-metric-negative", tree_with(metric=-1), vstree.VstreeError, BAD,
         "vstree_tree_build: parameter `metric`: -1: " + ENUM_METRIC),
    case("tree-threads-float", tree_with(threads=2.0), TypeError, None,
         "vstree.Tree: parameter `threads`: must be an integer, not 2.0 (float)"),
    # reconstruct
    case("reconstruct-error-zero", reconstruct_with(error=0.0), vstree.VstreeError, BAD,
         "vstree_reconstruct: parameter `error`: 0: must be a finite number > 0"),
    case("reconstruct-d_a-too-big", reconstruct_with(d_a=1.5), vstree.VstreeError, BAD,
         "vstree_reconstruct: parameter `d_a`: 1.5: must be in [0, 1]"),
    # At these ends the height-field test never holds: refused before the work (issue 26, 7).
    case("reconstruct-d_a-one", reconstruct_with(d_a=1.0), vstree.VstreeError, BAD,
         "vstree_reconstruct: parameter `d_a`: 1: the height-field test (every normal's dot product "
         "with the cell's mean normal above d_a) can never hold, so no cell becomes a T-node and there "
         "is no base mesh; reconstruction needs d_a below 1 (default 0)"),
    case("reconstruct-d_d-zero", reconstruct_with(d_d=0.0), vstree.VstreeError, BAD,
         "vstree_reconstruct: parameter `d_d`: 0: the height-field test (every sample's height over the "
         "cell's plane below d_d times the cell's radius) can never hold, so no cell becomes a T-node "
         "and there is no base mesh; reconstruction needs d_d above 0 (default 0.1667)"),
    case("reconstruct-max_depth-zero", reconstruct_with(max_depth=0), vstree.VstreeError, BAD,
         "vstree_reconstruct: parameter `max_depth`: 0: must be from 1 to 30"),
    case("reconstruct-max_levels-too-big", reconstruct_with(max_levels=13), vstree.VstreeError, BAD,
         "vstree_reconstruct: parameter `max_levels`: 13: must be from 0 to 12"),
    case("reconstruct-max_levels-negative", reconstruct_with(max_levels=-1), vstree.VstreeError, BAD,
         "vstree.reconstruct: parameter `max_levels`: -1 is out of range for the C field (uint32)"),
    case("reconstruct-max_levels-float-not-truncated", reconstruct_with(max_levels=2.7), TypeError, None,
         "vstree.reconstruct: parameter `max_levels`: must be an integer, not 2.7 (float)"),
    case("reconstruct-min_cell_size-nan", reconstruct_with(min_cell_size=NAN), vstree.VstreeError, BAD,
         "vstree_reconstruct: parameter `min_cell_size`: NaN: must be in [0, 1)"),
    case("reconstruct-target_distance-negative", reconstruct_with(target_distance=-1.0), vstree.VstreeError, BAD,
         "vstree_reconstruct: parameter `target_distance`: -1: must be a finite number >= 0"),
    case("reconstruct-target_distance-inf", reconstruct_with(target_distance=INF), vstree.VstreeError, BAD,
         "vstree_reconstruct: parameter `target_distance`: inf: must be a finite number >= 0"),
    case("reconstruct-min_displaced-too-big", reconstruct_with(min_displaced=2.0), vstree.VstreeError, BAD,
         "vstree_reconstruct: parameter `min_displaced`: 2: must be in [0, 1]"),
    case("reconstruct-min_displaced-nan", reconstruct_with(min_displaced=NAN), vstree.VstreeError, BAD,
         "vstree_reconstruct: parameter `min_displaced`: NaN: must be in [0, 1]"),
    case("reconstruct-max_triangles-zero", reconstruct_with(max_triangles=0), vstree.VstreeError, BAD,
         "vstree_reconstruct: parameter `max_triangles`: 0: must be from 1 to 4294967295"),
    case("reconstruct-max_triangles-2^32", reconstruct_with(max_triangles=2**32), vstree.VstreeError, BAD,
         "vstree.reconstruct: parameter `max_triangles`: 4294967296 is out of range for the C field (uint32)"),
    case("reconstruct-max_grid_depth-too-small", reconstruct_with(max_grid_depth=3), vstree.VstreeError, BAD,
         "vstree_reconstruct: parameter `max_grid_depth`: 3: must be from 4 to 20"),
    case("reconstruct-max_grid_depth-too-big", reconstruct_with(max_grid_depth=21), vstree.VstreeError, BAD,
         "vstree_reconstruct: parameter `max_grid_depth`: 21: must be from 4 to 20"),
    case("reconstruct-trim-negative", reconstruct_with(trim=-1.0), vstree.VstreeError, BAD,
         "vstree_reconstruct: parameter `trim`: -1: must be a finite number >= 0"),
    case("reconstruct-trim-inf", reconstruct_with(trim=INF), vstree.VstreeError, BAD,
         "vstree_reconstruct: parameter `trim`: inf: must be a finite number >= 0"),
    case("reconstruct-trim-string", reconstruct_with(trim="x"), TypeError, None,
         "vstree.reconstruct: parameter `trim`: must be a real number, not 'x' (str)"),
    case("reconstruct-neighbours-too-few", reconstruct_with(neighbours=2), vstree.VstreeError, BAD,
         "vstree_reconstruct: parameter `neighbours`: 2: must be from 3 to 256"),
    case("reconstruct-reorient_given-two", reconstruct_with(reorient_given=2), vstree.VstreeError, BAD,
         "vstree_reconstruct: parameter `reorient_given`: 2: must be 0 or 1"),
    case("reconstruct-threads-too-many", reconstruct_with(threads=1025), vstree.VstreeError, BAD,
         "vstree_reconstruct: parameter `threads`: 1025: must be 0 (all cores) to 1024"),
    case("reconstruct-orient-number", reconstruct_with(orient=9), vstree.VstreeError, BAD,
         "vstree_reconstruct: parameter `orient`: 9: " + ENUM_ORIENT),
    case("reconstruct-orient-inward", reconstruct_with(orient="inward"), ValueError, None,
         "vstree.reconstruct: parameter `orient`: 'inward' is not one of " + ORIENT_NAMES),
    case("reconstruct-orient-none", reconstruct_with(orient=None), TypeError, None,
         "vstree.reconstruct: parameter `orient`: must be one of %s or an integer, not None (NoneType)" % ORIENT_NAMES),
    case("reconstruct-simplify-only-parameter", reconstruct_with(metric="l2"), TypeError, None,
         "vstree.reconstruct: unknown parameter 'metric' (the parameters are orient, error, d_a, d_d, "
         "max_depth, max_levels, min_cell_size, target_distance, min_displaced, max_triangles, "
         "max_grid_depth, trim, neighbours, reorient_given, threads, closure, base_mesh)"),
    case("reconstruct-closure-unknown", reconstruct_with(closure="half"), ValueError, None,
         "vstree.reconstruct: parameter `closure`: 'half' is not one of 'auto', 'closed', 'open'"),
    case("reconstruct-base-mesh-unknown", reconstruct_with(base_mesh="poisson"), ValueError, None,
         "vstree.reconstruct: parameter `base_mesh`: 'poisson' is not one of 'adaptive', 'paper', 'winding'"),
    # estimate_normals
    case("normals-neighbours-too-many", normals_with(neighbours=300), vstree.VstreeError, BAD,
         "vstree_estimate_normals: parameter `neighbours`: 300: must be from 3 to 256"),
    case("normals-neighbours-zero", normals_with(neighbours=0), vstree.VstreeError, BAD,
         "vstree_estimate_normals: parameter `neighbours`: 0: must be from 3 to 256"),
    case("normals-neighbours-negative", normals_with(neighbours=-1), vstree.VstreeError, BAD,
         "vstree.estimate_normals: parameter `neighbours`: -1 is out of range for the C field (uint32)"),
    case("normals-neighbours-float-not-truncated", normals_with(neighbours=16.5), TypeError, None,
         "vstree.estimate_normals: parameter `neighbours`: must be an integer, not 16.5 (float)"),
    case("normals-orient-negative", normals_with(orient=-1), vstree.VstreeError, BAD,
         "vstree_estimate_normals: parameter `orient`: -1: " + ENUM_ORIENT),
    case("normals-orient-outward", normals_with(orient="outward"), ValueError, None,
         "vstree.estimate_normals: parameter `orient`: 'outward' is not one of " + ORIENT_NAMES),
    case("normals-reorient_given-two", normals_with(reorient_given=2), vstree.VstreeError, BAD,
         "vstree_estimate_normals: parameter `reorient_given`: 2: must be 0 or 1"),
    case("normals-threads-too-many", normals_with(threads=2000), vstree.VstreeError, BAD,
         "vstree_estimate_normals: parameter `threads`: 2000: must be 0 (all cores) to 1024"),
    case("normals-reconstruct-only-parameter", normals_with(error=1e-3), TypeError, None,
         "vstree.estimate_normals: unknown parameter 'error' (the parameters are orient, neighbours, "
         "reorient_given, threads)"),
]


# ---- arrays ----------------------------------------------------------------------------------

INPUT = S.INVALID_INPUT
LINE = np.stack([np.arange(50), 2 * np.arange(50), np.zeros(50)], -1)


def mesh_of(positions, triangles=None, normals=None):
    return lambda c: vstree.Mesh(positions, triangles, normals)


ARRAY_CASES = [
    case("positions-two-columns", mesh_of(P[:, :2]), ValueError, None,
         "positions must have shape (n, 3), not (128, 2)"),
    case("positions-three-dimensions", mesh_of(P[None]), ValueError, None,
         "positions must have shape (n, 3), not (1, 128, 3)"),
    case("positions-flat-not-a-multiple-of-3", mesh_of(np.zeros(7)), ValueError, None,
         "positions must have shape (n, 3), not (7,)"),
    case("positions-strings", mesh_of([["1", "2", "x"]]), TypeError, None,
         "positions must be real numbers, not <U1"),
    case("positions-complex", mesh_of(P + 1j), TypeError, None,
         "positions must be real numbers, not complex64"),
    case("positions-none", mesh_of(None), TypeError, None,
         "positions must be an (n, 3) array of numbers, not None"),
    case("positions-ragged", mesh_of([[0, 0, 0], [1, 1]]), ValueError, None,
         "positions: setting an array element with a sequence.", False),
    case("positions-objects", mesh_of([[0, 0, {}]]), TypeError, None,
         "positions: float() argument must be a string or a real number, not 'dict'"),
    case("positions-empty", mesh_of(np.zeros((0, 3))), vstree.VstreeError, INPUT,
         "vstree_mesh_create_f64: `vertex_count` is 0: a mesh needs at least one vertex"),
    case("positions-empty-list", mesh_of([]), vstree.VstreeError, INPUT,
         "vstree_mesh_create_f64: `vertex_count` is 0: a mesh needs at least one vertex"),
    case("positions-nan", mesh_of(with_item(P, (5, 1), np.nan), T), vstree.VstreeError, INPUT,
         "vstree_mesh_create: invalid input: vertex 5 has a NaN or infinite coordinate"),
    case("positions-inf", mesh_of(with_item(P, (7, 0), np.inf), T), vstree.VstreeError, INPUT,
         "vstree_mesh_create: invalid input: vertex 7 has a NaN or infinite coordinate"),
    case("positions-minus-inf-flat", mesh_of(with_item(P.ravel(), 29, -np.inf)), vstree.VstreeError, INPUT,
         "vstree_mesh_create: invalid input: vertex 9 has a NaN or infinite coordinate"),
    case("positions-beyond-1e18", mesh_of(with_item(P, (11, 0), 2e18), T), vstree.VstreeError, INPUT,
         "vstree_mesh_create: invalid input: vertex 11 has a coordinate of 2e18: at most 1e18 in "
         "magnitude is supported (32-bit geometry); rescale the input"),
    case("positions-float64-beyond-float32", mesh_of(with_item(P.astype(np.float64), (12, 2), -1e300), T),
         vstree.VstreeError, INPUT,
         "vstree_mesh_create_f64: invalid input: vertex 12 has a coordinate of 1e300: at most 1e18 in "
         "magnitude is supported (32-bit geometry); rescale the input"),
    case("positions-float64-nan", mesh_of(with_item(P.astype(np.float64) + 1e6, (5, 1), np.nan), T),
         vstree.VstreeError, INPUT, "vstree_mesh_create_f64: invalid input: vertex 5 has a NaN or infinite "
         "coordinate (1000000.7878679633, NaN, 999999.7878679633)"),
    case("positions-float64-beyond-1e18", mesh_of(with_item(P.astype(np.float64), (11, 0), -2e18), T),
         vstree.VstreeError, INPUT, "vstree_mesh_create_f64: invalid input: vertex 11 has a coordinate of 2e18: "
         "at most 1e18 in magnitude is supported (32-bit geometry); rescale the input"),
    case("triangles-negative", mesh_of(P, T.astype(np.int64) - 1), ValueError, None,
         "triangle 0 uses vertex -1: indices must be in [0, 2^32 - 1]"),
    case("triangles-beyond-uint32", mesh_of(P, with_item(T.astype(np.int64), (3, 2), 2**33)), ValueError, None,
         "triangle 3 uses vertex 8589934592: indices must be in [0, 2^32 - 1]"),
    case("triangles-past-the-last-vertex", mesh_of(P, with_item(T, (3, 2), 128)), vstree.VstreeError, INPUT,
         "vstree_mesh_create: invalid input: triangle 3 uses vertex 128, but there are only 128 vertices"),
    case("triangles-floats", mesh_of(P, T.astype(np.float32)), TypeError, None,
         "triangles must be integers, not float32"),
    case("triangles-booleans", mesh_of(P, T > 5), TypeError, None, "triangles must be integers, not bool"),
    case("triangles-two-columns", mesh_of(P, T[:, :2]), ValueError, None,
         "triangles must have shape (n, 3), not (256, 2)"),
    case("triangles-ragged", mesh_of(P, [[0, 1, 2], [0, 1]]), ValueError, None,
         "triangles: setting an array element with a sequence.", False),
    case("normals-one-short", mesh_of(P, T, N[:-1]), ValueError, None,
         "normals has shape (127, 3), positions (128, 3)"),
    case("normals-two-columns", mesh_of(P, T, N[:, :2]), ValueError, None,
         "normals must have shape (n, 3), not (128, 2)"),
    case("normals-nan", mesh_of(P, T, with_item(N, (4, 2), np.nan)), vstree.VstreeError, INPUT,
         "vstree_mesh_create: invalid input: normal 4 has a NaN or infinite component"),
    case("normals-float64-beyond-float32", mesh_of(P, T, with_item(N.astype(np.float64), (6, 0), 1e40)),
         vstree.VstreeError, INPUT,
         "vstree.Mesh: invalid input: normal 6 has a component of 1e+40, beyond the float32 range"),
    case("normals-strings", mesh_of(P, T, np.full(P.shape, "0")), TypeError, None,
         "normals must be real numbers, not <U1"),
    case("simplify-cloud-without-normals", lambda c: vstree.simplify(vstree.Mesh(P)), vstree.VstreeError, INPUT,
         "vstree_simplify: invalid input: the point cloud has no normals (estimate them first)"),
    case("reconstruct-normals-one-short", lambda c: vstree.reconstruct(CLOUD, CLOUD[:-1]), ValueError, None,
         "normals has shape (199, 3), positions (200, 3)"),
    case("reconstruct-mesh-and-normals", lambda c: vstree.reconstruct(vstree.Mesh(CLOUD), CLOUD), ValueError, None,
         "normals are given with the Mesh, not separately"),
    case("reconstruct-no-points", lambda c: vstree.reconstruct(np.zeros((0, 3))), vstree.VstreeError, INPUT,
         "vstree_mesh_create_f64: `vertex_count` is 0: a mesh needs at least one vertex"),
    case("reconstruct-five-points", lambda c: vstree.reconstruct(CLOUD[:5]), vstree.VstreeError, INPUT,
         "vstree_reconstruct: invalid input: 5 points: at least 10 are needed"),
    case("reconstruct-points-on-a-line", lambda c: vstree.reconstruct(LINE), vstree.VstreeError, INPUT,
         "vstree_reconstruct: invalid input: all 50 points lie on one line: no surface passes through them"),
    case("reconstruct-points-at-one-place", lambda c: vstree.reconstruct(np.ones((50, 3))), vstree.VstreeError,
         INPUT, "vstree_reconstruct: invalid input: all 50 points are at the same place: no surface "
         "passes through them"),
    case("normals-two-points", lambda c: vstree.estimate_normals(CLOUD[:2]), vstree.VstreeError, INPUT,
         "vstree_estimate_normals: invalid input: 2 points: normals need at least 3"),
    case("normals-points-on-a-line", lambda c: vstree.estimate_normals(LINE[:20]), vstree.VstreeError, INPUT,
         "vstree_estimate_normals: invalid input: all 20 points lie on one line: no surface passes through them"),
    case("normals-points-at-one-place", lambda c: vstree.estimate_normals(np.zeros((20, 3))), vstree.VstreeError,
         INPUT, "vstree_estimate_normals: invalid input: all 20 points are at the same place: no surface "
         "passes through them"),
]


# ---- wrong types and progress callbacks ------------------------------------------------------

CANCELLED = S.CANCELLED
NOT_A_MESH = "`mesh` must be a vstree.Mesh, not %s (make one with vstree.Mesh(positions, triangles))"


class HostGaveUp(Exception):
    pass


def give_up(fraction, stage):
    raise HostGaveUp("host gave up at %s" % stage)


TYPE_CASES = [
    case("simplify-an-array", lambda c: vstree.simplify(P), TypeError, None,
         "vstree.simplify: " + NOT_A_MESH % "ndarray"),
    case("simplify-none", lambda c: vstree.simplify(None), TypeError, None,
         "vstree.simplify: " + NOT_A_MESH % "NoneType"),
    case("tree-of-an-array", lambda c: vstree.Tree(P), TypeError, None, "vstree.Tree: " + NOT_A_MESH % "ndarray"),
    case("tree-vertex-labels-unknown-kind", lambda c: vstree.Tree(c.mesh()).vertex_labels("depth"), ValueError,
         None, "Tree.vertex_labels: `kind` must be 'cluster' or 't_node', not 'depth'"),
    case("tree-vertex-labels-number", lambda c: vstree.Tree(c.mesh()).vertex_labels(0), ValueError, None,
         "Tree.vertex_labels: `kind` must be 'cluster' or 't_node', not 0"),
    case("load-an-int-path", lambda c: vstree.load(3), TypeError, None,
         "expected str, bytes or os.PathLike object, not int"),
    case("save-a-none-path", lambda c: c.mesh().save(None), TypeError, None,
         "expected str, bytes or os.PathLike object, not NoneType"),
    case("from-bytes-an-int", lambda c: vstree.Mesh.from_bytes(5, "a.off"), TypeError, None,
         "Mesh.from_bytes: `data` must be bytes-like (the file's content), not int"),
    case("from-bytes-a-str", lambda c: vstree.Mesh.from_bytes("OFF\n", "a.off"), TypeError, None,
         "Mesh.from_bytes: `data` must be bytes-like (the file's content), not str"),
    case("from-bytes-a-none-name", lambda c: vstree.Mesh.from_bytes(b"OFF\n", None), TypeError, None,
         "expected str, bytes or os.PathLike object, not NoneType"),
    case("simplify-progress-not-callable", lambda c: vstree.simplify(c.mesh(), progress=5), TypeError, None,
         "vstree.simplify: `progress` must be a callable (fraction, stage) -> bool, or None, not 5 (int)"),
    case("reconstruct-progress-not-callable", lambda c: vstree.reconstruct(CLOUD, progress="log"), TypeError,
         None, "vstree.reconstruct: `progress` must be a callable (fraction, stage) -> bool, or None, not "
         "'log' (str)"),
    case("simplify-progress-returns-false", lambda c: vstree.simplify(c.mesh(), progress=lambda f, s: False),
         vstree.CancelledError, CANCELLED, "vstree_simplify: cancelled"),
    case("tree-progress-returns-false", lambda c: vstree.Tree(c.mesh(), progress=lambda f, s: f < 0.5),
         vstree.CancelledError, CANCELLED, "vstree_tree_build: cancelled"),
    case("reconstruct-progress-returns-false",
         lambda c: vstree.reconstruct(CLOUD, CLOUD, progress=lambda f, s: False),
         vstree.CancelledError, CANCELLED, "vstree_reconstruct: cancelled"),
    case("normals-progress-returns-false", lambda c: vstree.estimate_normals(CLOUD, progress=lambda f, s: False),
         vstree.CancelledError, CANCELLED, "vstree_estimate_normals: cancelled"),
    case("simplify-progress-raises", lambda c: vstree.simplify(c.mesh(), progress=give_up), HostGaveUp, None,
         "host gave up at building tree"),
    case("tree-progress-raises", lambda c: vstree.Tree(c.mesh(), progress=give_up), HostGaveUp, None,
         "host gave up at building tree"),
    case("reconstruct-progress-raises", lambda c: vstree.reconstruct(CLOUD, CLOUD, progress=give_up), HostGaveUp,
         None, "host gave up at building tree"),
    case("normals-progress-raises", lambda c: vstree.estimate_normals(CLOUD, progress=give_up), HostGaveUp, None,
         "host gave up at normals: k-d tree"),
    case("simplify-progress-wrong-signature", lambda c: vstree.simplify(c.mesh(), progress=lambda f: True),
         TypeError, None, "takes 1 positional argument but 2 were given", False),
]


# ---- files: the function, the path, the line --------------------------------------------------

IO, PARSE, FORMAT, ARGUMENT = S.IO, S.PARSE, S.UNSUPPORTED_FORMAT, S.INVALID_ARGUMENT
EXTENSIONS = "unsupported file format (expected .ply, .obj, .off, .xyz or .pwn)"
PLY_XYZ = "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nend_header\n"
TRIANGLE_PLY = (
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
    "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n"
)
TRIANGLE_OFF = "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n"
TRIANGLE_OBJ = "v 0 0 0\nv 1 0 0\nv 0 1 0\n"


def load_file(name, content):
    return lambda c: vstree.load(c.write(name, content))


def directory(c, name):
    (c.tmp / name).mkdir()
    return c.tmp / name


FILE_CASES = [
    case("load-missing-file", lambda c: vstree.load(c.tmp / "missing.ply"), vstree.VstreeError, IO,
         "vstree_mesh_load: {tmp}/missing.ply: No such file or directory (os error 2)"),
    case("load-missing-directory", lambda c: vstree.Mesh.load(str(c.tmp / "scans" / "a.off")), vstree.VstreeError,
         IO, "vstree_mesh_load: {tmp}/scans/a.off: No such file or directory (os error 2)"),
    # Only the function, the path and the word: the lead is rewording non-regular files.
    case("load-a-directory", lambda c: vstree.load(directory(c, "scans.ply")), vstree.VstreeError, IO,
         ("vstree_mesh_load: {tmp}/scans.ply: ", "directory"), False),
    case("load-unsupported-extension", load_file("part.stl", "solid part\n"), vstree.VstreeError, FORMAT,
         "vstree_mesh_load: {tmp}/part.stl: " + EXTENSIONS),
    case("load-no-extension", load_file("mesh", TRIANGLE_OFF), vstree.VstreeError, FORMAT,
         "vstree_mesh_load: {tmp}/mesh: " + EXTENSIONS),
    case("load-empty-path", lambda c: vstree.load(""), vstree.VstreeError, ARGUMENT,
         "vstree_mesh_load: `path`: the path is empty"),
    case("ply-not-ply", load_file("a.ply", "plx\nformat ascii 1.0\nend_header\n"), vstree.VstreeError, PARSE,
         "vstree_mesh_load: {tmp}/a.ply: line 1: not a PLY file: it must start with a `ply` line"),
    case("ply-empty-file", load_file("a.ply", ""), vstree.VstreeError, PARSE,
         "vstree_mesh_load: {tmp}/a.ply: line 1: file is empty"),
    case("ply-version-2", load_file("a.ply", PLY_XYZ.replace("1.0", "2.0")), vstree.VstreeError, PARSE,
         "vstree_mesh_load: {tmp}/a.ply: line 2: unsupported PLY version `2.0`"),
    case("ply-vertex-missing-a-value", load_file("a.ply", PLY_XYZ + "0 0 0\n1 1\n"), vstree.VstreeError, PARSE,
         "vstree_mesh_load: {tmp}/a.ply: line 9: vertex 1: expected 3 values, found 2"),
    case("ply-vertex-not-a-number", load_file("a.ply", PLY_XYZ + "0 0 0\n1 abc 1\n"), vstree.VstreeError, PARSE,
         "vstree_mesh_load: {tmp}/a.ply: line 9: vertex 1: expected a number, found `abc`"),
    case("ply-vertex-nan", load_file("a.ply", PLY_XYZ + "nan 0 0\n1 1 1\n"), vstree.VstreeError, PARSE,
         "vstree_mesh_load: {tmp}/a.ply: line 8: vertex 0: has a NaN or infinite coordinate (NaN, 0, 0)"),
    case("ply-face-past-the-last-vertex", load_file("a.ply", TRIANGLE_PLY + "3 0 1 7\n"), vstree.VstreeError,
         PARSE, "vstree_mesh_load: {tmp}/a.ply: line 13: face 0: uses vertex 7, but there are only 3 vertices"),
    case("ply-no-end-header", load_file("a.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"),
         vstree.VstreeError, PARSE, "vstree_mesh_load: {tmp}/a.ply: header: file ends before `end_header`"),
    case("ply-no-x-property",
         load_file("a.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float a\nend_header\n0\n"),
         vstree.VstreeError, PARSE, "vstree_mesh_load: {tmp}/a.ply: line 3: the vertex element has no scalar `x` property"),
    case("ply-binary-truncated",
         load_file("a.ply", PLY_XYZ.replace("ascii", "binary_little_endian").encode() + bytes(16)),
         vstree.VstreeError, PARSE, "vstree_mesh_load: {tmp}/a.ply: vertex 1: file ends after 1 of the 2 `vertex` elements"),
    case("off-wrong-keyword", load_file("a.off", "OFX\n3 1 0\n"), vstree.VstreeError, PARSE,
         "vstree_mesh_load: {tmp}/a.off: line 1: expected OFF, NOFF or COFF, found `OFX`"),
    case("off-count-not-a-number", load_file("a.off", "OFF\nthree 1 0\n"), vstree.VstreeError, PARSE,
         "vstree_mesh_load: {tmp}/a.off: line 2: expected a number, found `three`"),
    case("off-ends-in-the-vertices", load_file("a.off", "OFF\n3 1 0\n0 0 0\n"), vstree.VstreeError, PARSE,
         "vstree_mesh_load: {tmp}/a.off: line 3: file ends after 1 of the 3 vertices"),
    case("off-vertex-not-a-number", load_file("a.off", "OFF\n3 1 0\n0 0 0\n1 x 0\n0 1 0\n3 0 1 2\n"),
         vstree.VstreeError, PARSE, "vstree_mesh_load: {tmp}/a.off: line 4: vertex 1: expected a number, found `x`"),
    case("off-face-past-the-last-vertex", load_file("a.off", TRIANGLE_OFF + "3 0 1 5\n"), vstree.VstreeError,
         PARSE, "vstree_mesh_load: {tmp}/a.off: line 6: face 0: uses vertex 5, but there are only 3 vertices"),
    case("off-face-negative-index", load_file("a.off", TRIANGLE_OFF + "3 0 1 -1\n"), vstree.VstreeError, PARSE,
         "vstree_mesh_load: {tmp}/a.off: line 6: face 0: uses negative vertex index -1"),
    case("off-empty-file", load_file("a.off", ""), vstree.VstreeError, PARSE,
         "vstree_mesh_load: {tmp}/a.off: line 1: file is empty"),
    case("obj-vertex-with-two-numbers", load_file("a.obj", "v 0 0 0\nv 1 0\nv 0 1 0\nf 1 2 3\n"),
         vstree.VstreeError, PARSE, "vstree_mesh_load: {tmp}/a.obj: line 2: expected 3 numbers, found 2"),
    case("obj-vertex-not-a-number", load_file("a.obj", "v 0 0 0\nv 1 q 0\nv 0 1 0\n"), vstree.VstreeError,
         PARSE, "vstree_mesh_load: {tmp}/a.obj: line 2: expected a number, found `q`"),
    case("obj-face-past-the-last-vertex", load_file("a.obj", TRIANGLE_OBJ + "f 1 2 9\n"), vstree.VstreeError,
         PARSE, "vstree_mesh_load: {tmp}/a.obj: line 4: vertex index 9 is out of range: the file has 3 `v` lines"),
    case("obj-face-index-zero", load_file("a.obj", TRIANGLE_OBJ + "f 0 1 2\n"), vstree.VstreeError, PARSE,
         "vstree_mesh_load: {tmp}/a.obj: line 4: vertex index 0 is invalid: indices start at 1"),
    case("obj-relative-index-too-far-back", load_file("a.obj", TRIANGLE_OBJ + "f -1 -2 -9\n"),
         vstree.VstreeError, PARSE, "vstree_mesh_load: {tmp}/a.obj: line 4: relative vertex index -9 is out of "
         "range: only 3 `v` lines precede it"),
    case("obj-empty-file", load_file("a.obj", ""), vstree.VstreeError, PARSE,
         "vstree_mesh_load: {tmp}/a.obj: line 1: file is empty"),
    case("obj-coordinate-beyond-1e18", load_file("a.obj", "v 0 0 0\nv 1 0 0\nv 0 1 3e18\n"), vstree.VstreeError,
         PARSE, "vstree_mesh_load: {tmp}/a.obj: line 3: vertex 2 has a coordinate of 3e18: at most 1e18 in "
         "magnitude is supported (32-bit geometry); rescale the input"),
    case("xyz-row-with-two-numbers", load_file("a.xyz", "0 0 0\n1 1\n"), vstree.VstreeError, PARSE,
         "vstree_mesh_load: {tmp}/a.xyz: line 2: expected 3 numbers like line 1, found 2"),
    case("xyz-row-with-four-numbers", load_file("a.xyz", "0 0 0\n1 1 1 1\n"), vstree.VstreeError, PARSE,
         "vstree_mesh_load: {tmp}/a.xyz: line 2: expected 3 numbers like line 1, found 4"),
    case("xyz-not-a-number", load_file("a.xyz", "0 0 0\n1 1 z\n"), vstree.VstreeError, PARSE,
         "vstree_mesh_load: {tmp}/a.xyz: line 2: expected a number, found `z`"),
    case("xyz-nan", load_file("a.xyz", "0 0 0\nnan 1 1\n"), vstree.VstreeError, PARSE,
         "vstree_mesh_load: {tmp}/a.xyz: line 2: point 1: has a NaN or infinite coordinate (NaN, 1, 1)"),
    case("xyz-empty-file", load_file("a.xyz", ""), vstree.VstreeError, PARSE,
         "vstree_mesh_load: {tmp}/a.xyz: line 1: file is empty"),
    case("from-bytes-ends-in-the-vertices", lambda c: vstree.Mesh.from_bytes(b"OFF\n3 1 0\n0 0 0\n", "broken.off"),
         vstree.VstreeError, PARSE, "vstree_mesh_load_memory: broken.off: line 3: file ends after 1 of the 3 vertices"),
    case("from-bytes-extension-only", lambda c: vstree.Mesh.from_bytes(bytearray(b"OFF\n3 1 0\n"), "off"),
         vstree.VstreeError, PARSE, "vstree_mesh_load_memory: memory.off: line 2: file ends after 0 of the 3 vertices"),
    case("from-bytes-unsupported-name", lambda c: vstree.Mesh.from_bytes(b"solid\n", "part.stl"),
         vstree.VstreeError, FORMAT, "vstree_mesh_load_memory: part.stl: " + EXTENSIONS),
    case("from-bytes-empty-name", lambda c: vstree.Mesh.from_bytes(b"OFF\n", ""), vstree.VstreeError, ARGUMENT,
         "vstree_mesh_load_memory: `name`: the path is empty"),
    case("save-unsupported-extension", lambda c: c.mesh().save(c.tmp / "out.stl"), vstree.VstreeError, FORMAT,
         "vstree_mesh_save: {tmp}/out.stl: " + EXTENSIONS),
    case("save-no-extension", lambda c: c.mesh().save(str(c.tmp / "out")), vstree.VstreeError, FORMAT,
         "vstree_mesh_save: {tmp}/out: " + EXTENSIONS),
    case("save-empty-path", lambda c: c.mesh().save(""), vstree.VstreeError, ARGUMENT,
         "vstree_mesh_save: `path`: the path is empty"),
    case("save-into-a-missing-directory", lambda c: c.mesh().save(c.tmp / "out" / "a.ply"), vstree.VstreeError,
         IO, "vstree_mesh_save: {tmp}/out/a.ply: No such file or directory (os error 2)"),
    case("save-over-a-directory", lambda c: c.mesh().save(directory(c, "out.ply")), vstree.VstreeError, IO,
         ("vstree_mesh_save: {tmp}/out.ply: ", "directory"), False),
]

CASES = NUL_CASES + CLOSED_CASES + IN_USE_CASES + PARAMETER_CASES + ARRAY_CASES + TYPE_CASES + FILE_CASES


@pytest.mark.parametrize("call, exc, status, message, exact", CASES)
def test_bad_input(tmp_path, call, exc, status, message, exact):
    with pytest.raises(BaseException) as e:
        call(Context(tmp_path))
    assert type(e.value) is exc, "%s: %s" % (type(e.value).__name__, e.value)
    if status is None:
        assert not isinstance(e.value, vstree.VstreeError), e.value
        text = str(e.value)
    else:
        assert e.value.status == status, e.value
        text = e.value.message
        assert str(e.value) == "%s [status %d: %s]" % (
            text,
            status,
            vstree._ffi.lib.vstree_status_str(status).decode(),
        )
    if exact:
        expected = message.replace("{tmp}", str(tmp_path))
        assert text == expected
    else:
        parts = message if isinstance(message, tuple) else (message,)
        for part in parts:
            assert part.replace("{tmp}", str(tmp_path)) in text, text


def test_a_path_with_nul_leaves_the_file_before_it_unchanged(tmp_path):
    """C would stop the string at the NUL: save("victim.ply\\0-simplified.ply") wrote victim.ply."""
    victim = tmp_path / "victim.ply"
    mesh = vstree.Mesh(P, T)
    mesh.save(victim)
    before = victim.read_bytes()
    simplified = vstree.simplify(mesh, error=1e-2).mesh
    assert simplified.vertex_count < mesh.vertex_count
    for path in (
        str(victim) + "\0-simplified.ply",
        os.fsencode(victim) + b"\0-simplified.ply",
        pathlib.Path(str(victim) + "\0-simplified.ply"),
    ):
        with pytest.raises(ValueError, match="embedded null byte"):
            simplified.save(path)
    assert victim.read_bytes() == before
    assert sorted(os.listdir(tmp_path)) == ["victim.ply"]
    # The path up to the NUL is not read either.
    with pytest.raises(ValueError, match="embedded null byte"):
        vstree.load(str(victim) + "\0")


def test_closing_twice_is_harmless_and_a_closed_object_says_so():
    mesh = vstree.Mesh(P, T)
    tree = vstree.Tree(mesh)
    stats = tree.stats
    for thing in (mesh, tree):
        thing.close()
        thing.close()
    assert repr(mesh) == "<vstree.Mesh closed>"
    assert tree.stats == stats and stats["vertices"] == len(P)  # a copy, kept after close()


def test_the_limits_themselves_are_accepted():
    """The edges of the ranges the cases above step over."""
    big = vstree.Mesh(with_item(P, (11, 0), 1e18), T)
    assert big.positions[11, 0] == np.float32(1e18)
    assert vstree.Mesh(P.astype(np.float64), T.astype(np.int64)).triangle_count == len(T)
    assert vstree.estimate_normals(CLOUD[:3]).report["estimated"] == 3
    assert vstree.simplify(vstree.Mesh(P, T), max_depth=1, min_cell_size=0.0, d_a=0.0, d_d=1.0).mesh.vertex_count > 0
    assert vstree.reconstruct(CLOUD, CLOUD, neighbours=256, max_levels=0, max_grid_depth=4).stats["levels"] == 0


@pytest.mark.parametrize("answer", [False, "raise"])
def test_a_callback_that_stops_is_not_called_again(answer):
    calls = []

    def progress(fraction, stage):
        calls.append((fraction, stage))
        if answer == "raise":
            raise HostGaveUp(stage)
        return False

    expected = vstree.CancelledError if answer is False else HostGaveUp
    for run in (
        lambda: vstree.simplify(vstree.Mesh(P, T), progress=progress),
        lambda: vstree.reconstruct(CLOUD, CLOUD, progress=progress),
        lambda: vstree.estimate_normals(CLOUD, progress=progress),
    ):
        del calls[:]
        with pytest.raises(expected):
            run()
        assert len(calls) == 1, calls
