"""The work of the VS-Tree operators as plain functions (testable without a GUI): mesh data in
and out of numpy, the lazy load of the vstree binding, and simplify / reconstruct / labels.

Every function takes ``progress(fraction, stage) -> bool``; returning False cancels (the
binding then raises ``CancelledError``) and nothing in the scene has been changed yet, because
the scene is only written after the library call returned.
"""

import importlib
import os
import platform

import bpy
try:
    import numpy as np
except ImportError:  # Blender built on the system's Python (Debian's) may come without numpy
    np = None

_BINDING = None
_BINDING_ERROR = None


class VstreeUnavailable(Exception):
    """The native library could not be loaded (missing, wrong platform, ABI mismatch)."""


def binding():
    """The ``vstree`` binding shipped inside this add-on, loaded on first use. Raises
    :class:`VstreeUnavailable` with a readable message when the library cannot be loaded; the
    failure is not cached, so fixing the installation and retrying works."""
    global _BINDING, _BINDING_ERROR
    if np is None:
        raise VstreeUnavailable(
            "VS-Tree needs numpy, which this Blender's Python does not have: install it "
            "(Debian and Ubuntu: apt install python3-numpy) and restart Blender"
        )
    if _BINDING is None:
        try:
            _BINDING = importlib.import_module(__package__ + ".vstree")
            _BINDING_ERROR = None
        except (ImportError, OSError) as e:
            _BINDING_ERROR = str(e)
            raise VstreeUnavailable(
                "VS-Tree native library unavailable: %s. Details: %s" % (what_to_install(), e)
            ) from None
    return _BINDING


# ---- platforms -----------------------------------------------------------------------------

#: The library file of each platform, as plugins/blender/build.sh puts it in each zip.
LIBRARY_NAMES = {"linux": "libvstree.so", "windows": "vstree.dll", "macos": "libvstree.dylib"}


def this_platform():
    """Blender's name for the platform this Blender runs on (``linux-x64``, ``windows-x64``,
    ``macos-arm64``, ``macos-x64``...), as its extension platform tags zips."""
    system = {"darwin": "macos"}.get(platform.system().lower(), platform.system().lower())
    machine = platform.machine().lower()
    machine = {"x86_64": "x64", "amd64": "x64", "aarch64": "arm64"}.get(machine, machine)
    return "%s-%s" % (system, machine)


def library_platform(path):
    """The platform a shared library was built for, read from its header (ELF, PE or
    Mach-O), or None when the file is none of those."""
    try:
        with open(path, "rb") as f:
            head = f.read(64)
            if head[:4] == b"\x7fELF" and len(head) >= 20:
                machine = int.from_bytes(head[18:20], "big" if head[5] == 2 else "little")
                return "linux-" + {0x3E: "x64", 0xB7: "arm64"}.get(machine, "0x%x" % machine)
            if head[:2] == b"MZ" and len(head) >= 64:
                f.seek(int.from_bytes(head[60:64], "little"))
                pe = f.read(6)
                if pe[:4] == b"PE\0\0":
                    machine = int.from_bytes(pe[4:6], "little")
                    return "windows-" + {0x8664: "x64", 0xAA64: "arm64"}.get(machine, "0x%x" % machine)
            if head[:4] == b"\xcf\xfa\xed\xfe" and len(head) >= 8:
                cpu = int.from_bytes(head[4:8], "little")
                return "macos-" + {0x01000007: "x64", 0x0100000C: "arm64"}.get(cpu, "0x%x" % cpu)
    except OSError:
        pass
    return None


def _zip_name(platform_name):
    """The name plugins/blender/build.sh gives this version's zip for ``platform_name``."""
    try:
        import tomllib

        with open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "blender_manifest.toml"), "rb") as f:
            version = tomllib.load(f)["version"]
    except (OSError, ValueError, KeyError, ImportError):
        version = "<version>"
    return "vstree-%s-%s.zip" % (version, platform_name.replace("-", "_"))


def what_to_install(directory=None):
    """What the user should install, for the message of a library that did not load: names the
    platform the installed library was built for, when it is another one, and the zip for this
    platform."""
    directory = directory or os.path.join(os.path.dirname(os.path.abspath(__file__)), "vstree")
    here = this_platform()
    want = "Install %s (Edit > Preferences > Get Extensions > Install from Disk)" % _zip_name(here)
    if here not in ("linux-x64", "windows-x64", "macos-arm64", "macos-x64"):
        return "VS-Tree is built for linux-x64, windows-x64, macos-arm64 and macos-x64, not for %s" % here
    found = []
    for name in sorted(set(LIBRARY_NAMES.values())):
        path = os.path.join(directory, name)
        if os.path.exists(path):
            found.append((name, library_platform(path)))
    others = [(name, p) for name, p in found if p != here]
    if others and len(others) == len(found):
        name, p = others[0]
        return "This installation holds %s for %s, but Blender runs on %s. %s" % (
            name, p or "an unknown platform", here, want)
    return "Reinstall the extension built for this platform (%s). %s" % (here, want)


def status():
    """One line for the UI: the library version, or why it is not loaded."""
    try:
        b = binding()
    except VstreeUnavailable as e:
        return False, str(e)
    return True, "libvstree %s (ABI %d)" % (b.version, b.ABI_VERSION)


# ---- Blender mesh <-> numpy ----------------------------------------------------------------


def mesh_arrays(me):
    """(positions float32 (n, 3), triangles int32 (m, 3)) of a Blender mesh (triangulated
    through its loop triangles; vertex indices are the mesh's)."""
    n = len(me.vertices)
    co = np.empty(n * 3, dtype=np.float32)
    me.vertices.foreach_get("co", co)
    me.calc_loop_triangles()
    t = len(me.loop_triangles)
    tris = np.empty(t * 3, dtype=np.int32)
    me.loop_triangles.foreach_get("vertices", tris)
    return co.reshape(n, 3), tris.reshape(t, 3)


def point_normals(me):
    """The point attribute "normal" (as PLY import makes it) as float32 (n, 3), or None. Never
    ``vertex.normal``: for loose vertices Blender derives that from the position."""
    attr = me.attributes.get("normal")
    if attr is None or attr.domain != 'POINT' or attr.data_type != 'FLOAT_VECTOR':
        return None
    out = np.empty(len(me.vertices) * 3, dtype=np.float32)
    attr.data.foreach_get("vector", out)
    return out.reshape(-1, 3)


def new_mesh(name, positions, triangles):
    """A Blender mesh from numpy arrays (fast path: add + foreach_set)."""
    p = np.ascontiguousarray(positions, dtype=np.float32).reshape(-1, 3)
    t = np.ascontiguousarray(triangles, dtype=np.int32).reshape(-1, 3)
    me = bpy.data.meshes.new(name)
    me.vertices.add(len(p))
    me.vertices.foreach_set("co", p.ravel())
    if len(t):
        me.loops.add(3 * len(t))
        me.polygons.add(len(t))
        me.loops.foreach_set("vertex_index", t.ravel())
        me.polygons.foreach_set("loop_start", np.arange(0, 3 * len(t), 3, dtype=np.int32))
    me.update(calc_edges=True)
    me.validate(verbose=False)
    return me


def label_colors(labels):
    """RGBA float32 (n, 4): one saturated colour per label (golden-ratio hues), grey for none."""
    labels = np.asarray(labels, dtype=np.uint64)
    h = (labels.astype(np.float64) * 0.618033988749895) % 1.0
    s, v = 0.65, 0.95
    i = np.floor(h * 6).astype(np.int64) % 6
    f = h * 6 - np.floor(h * 6)
    p, q, t = v * (1 - s), v * (1 - s * f), v * (1 - s * (1 - f))
    r = np.choose(i, [v, q, p, p, t, v])
    g = np.choose(i, [t, v, v, q, p, p])
    b = np.choose(i, [p, p, t, v, v, q])
    rgba = np.stack([r, g, b, np.ones_like(r)], axis=1).astype(np.float32)
    rgba[labels == 0xFFFFFFFF] = (0.5, 0.5, 0.5, 1.0)
    return rgba


# ---- the work ------------------------------------------------------------------------------


def source_mesh(context, ob, apply_modifiers):
    """(Blender mesh to read, cleanup function): the evaluated mesh (modifiers applied) or the
    object's own data."""
    if not apply_modifiers:
        return ob.data, lambda: None
    depsgraph = context.evaluated_depsgraph_get()
    ob_eval = ob.evaluated_get(depsgraph)
    me = ob_eval.to_mesh()
    return me, ob_eval.to_mesh_clear


# Each operation is read (main thread: Blender data -> numpy), compute (any thread: only numpy
# and the library, which releases the GIL) and write (main thread: numpy -> Blender data). The
# GUI runs compute on a worker thread; execute() and the *_object functions run all three.


def read_simplify(context, ob, apply_modifiers):
    me, cleanup = source_mesh(context, ob, apply_modifiers)
    try:
        positions, triangles = mesh_arrays(me)
    finally:
        cleanup()
    if len(positions) == 0:
        raise ValueError("'%s' has no vertices" % ob.name)
    if len(triangles) == 0:
        raise ValueError("'%s' has no faces: use Reconstruct for point clouds" % ob.name)
    return positions, triangles


def compute_simplify(data, params, progress=None):
    vs = binding()
    positions, triangles = data
    with vs.Mesh(positions, triangles) as m:
        result = vs.simplify(m, progress=progress, **params)
    with result.mesh as out:
        return out.positions, out.triangles, result.stats


def write_simplify(context, ob, out, apply_modifiers=True, in_place=False):
    new_p, new_t, _ = out
    new = new_mesh(ob.data.name + "_vstree", new_p, new_t)
    if in_place:
        old = ob.data
        ob.data = new
        if apply_modifiers:
            ob.modifiers.clear()
        if old.users == 0:
            bpy.data.meshes.remove(old)
        return ob
    target = bpy.data.objects.new(ob.name + "_vstree", new)
    target.matrix_world = ob.matrix_world.copy()
    context.collection.objects.link(target)
    return target


def simplify_object(context, ob, params, apply_modifiers=True, in_place=False, progress=None):
    """Simplifies mesh object ``ob``; returns (object written, stats). ``params`` are the
    binding's keyword parameters (error, tree_kind, metric, ...). The scene is only written
    after the library call returned, so a cancel or an error leaves it untouched."""
    binding()
    out = compute_simplify(read_simplify(context, ob, apply_modifiers), params, progress)
    return write_simplify(context, ob, out, apply_modifiers, in_place), out[2]


def read_cloud(ob):
    me = ob.data
    positions, _ = mesh_arrays(me)
    if len(me.polygons):
        raise ValueError("'%s' has faces: Reconstruct takes a point cloud (vertices only)" % ob.name)
    if len(positions) < 10:
        raise ValueError("'%s' has %d points; reconstruction needs at least 10" % (ob.name, len(positions)))
    return positions, point_normals(me)


def compute_reconstruct(data, params, progress=None):
    vs = binding()
    positions, normals = data
    result = vs.reconstruct(positions, normals, progress=progress, **params)
    with result.mesh as out:
        return out.positions, out.triangles, result.stats


def write_reconstruct(context, ob, out):
    new_p, new_t, _ = out
    new = new_mesh(ob.name + "_surface", new_p, new_t)
    target = bpy.data.objects.new(ob.name + "_surface", new)
    target.matrix_world = ob.matrix_world.copy()
    context.collection.objects.link(target)
    return target


def reconstruct_object(context, ob, params, progress=None):
    """Reconstructs a surface from the vertices of mesh object ``ob`` (normals from its point
    attribute "normal" when present, else estimated); returns (new object, stats)."""
    binding()
    out = compute_reconstruct(read_cloud(ob), params, progress)
    return write_reconstruct(context, ob, out), out[2]


def read_labels(ob):
    me = ob.data
    positions, triangles = mesh_arrays(me)
    if len(positions) == 0:
        raise ValueError("'%s' has no vertices" % ob.name)
    normals = point_normals(me) if len(triangles) == 0 else None
    return positions, triangles, normals


def compute_labels(data, params, kind="cluster", progress=None):
    vs = binding()
    positions, triangles, normals = data
    with vs.Mesh(positions, triangles, normals) as m:
        if len(triangles) == 0 and normals is None:
            m = vs.estimate_normals(m, progress=progress).mesh
        with vs.Tree(m, progress=progress, **params) as tree:
            return tree.vertex_labels(kind)


def write_colors(ob, labels, name="vstree_cluster"):
    me = ob.data
    if len(labels) != len(me.vertices):
        raise ValueError("'%s' changed while its clusters were computed" % ob.name)
    rgba = label_colors(labels)
    old = me.color_attributes.get(name)
    if old is not None:
        me.color_attributes.remove(old)
    attr = me.color_attributes.new(name, 'FLOAT_COLOR', 'POINT')
    attr.data.foreach_set("color", rgba.ravel())
    me.color_attributes.active_color = attr
    me.update()
    return attr, int(len(np.unique(labels[labels != 0xFFFFFFFF])))


def cluster_colors(context, ob, params, kind="cluster", name="vstree_cluster", progress=None):
    """Adds (or replaces) a FLOAT_COLOR point attribute ``name`` on ``ob``'s mesh: one colour per
    cluster (``kind="cluster"``) or T-node (``"t_node"``) of the tree simplification would use.
    Reads the object's own mesh (no modifiers) so that the labels match its vertices. Returns
    (attribute, number of distinct labels)."""
    binding()
    labels = compute_labels(read_labels(ob), params, kind, progress)
    return write_colors(ob, labels, name)
