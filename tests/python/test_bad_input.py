"""Bad input at the Python entry points, as a table: each case names the call, the exact
exception type, the C status (VstreeError.status) when the library refused it, and the exact
message (or an exact part of it: the function, the parameter, the value, the file and line).
What the library says is pinned as it is today: a change of wording fails here on purpose.

``{tmp}`` in a message stands for the test's tmp_path."""

import os
import pathlib

import numpy as np
import pytest

import vstree

S = vstree.Status


def grid_torus(rings=16, segments=8):
    """A small closed torus: (positions, triangles, normals)."""
    u = np.linspace(0, 2 * np.pi, rings, endpoint=False)[:, None]
    v = np.linspace(0, 2 * np.pi, segments, endpoint=False)[None, :]
    n = np.stack([np.cos(v) * np.cos(u), np.cos(v) * np.sin(u), np.sin(v) + 0 * u], -1).reshape(-1, 3)
    p = np.stack([np.cos(u) + 0 * v, np.sin(u) + 0 * v, 0 * u + 0 * v], -1).reshape(-1, 3) + 0.3 * n
    i, j = np.meshgrid(np.arange(rings), np.arange(segments), indexing="ij")
    a = i * segments + j
    b = (i + 1) % rings * segments + j
    c = (i + 1) % rings * segments + (j + 1) % segments
    d = i * segments + (j + 1) % segments
    t = np.concatenate([np.stack([a, b, c], -1), np.stack([a, c, d], -1)]).reshape(-1, 3)
    return p.astype(np.float32), t.astype(np.uint32), n.astype(np.float32)


def sphere_points(count=200):
    """Points on the unit sphere; they are their own outward normals."""
    i = np.arange(count) + 0.5
    z = 1 - 2 * i / count
    r = np.sqrt(1 - z * z)
    phi = np.pi * (3 - np.sqrt(5)) * i
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], -1).astype(np.float32)


P, T, N = grid_torus()
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
    VstreeError) and ``message`` (the whole message, or a part when ``exact`` is False)."""
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
]

CASES = NUL_CASES + CLOSED_CASES


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
    expected = message.replace("{tmp}", str(tmp_path))
    if exact:
        assert text == expected
    else:
        assert expected in text, text


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
