"""vstree for Python: Volume-Surface Trees (Boubekeur et al. 2006) for clustering simplification,
through the library's C API with numpy arrays in and out.

    import numpy as np, vstree
    mesh = vstree.Mesh(positions, triangles)          # (n, 3) floats, (m, 3) ints
    result = vstree.simplify(mesh, error=2e-3, progress=lambda f, stage: print(f, stage))
    result.mesh.positions, result.mesh.triangles       # numpy arrays
    result.stats["clusters"], result.stats["seconds_total"]
    tree = vstree.Tree(mesh)                          # the structure, for viewers
    tree.vertex_labels("cluster")                     # colour the mesh by cluster
    surface = vstree.reconstruct(points)              # (n, 3) points, or a Mesh cloud
    surface.mesh.triangles, surface.stats["base_genus"]
    oriented = vstree.estimate_normals(points)        # a Mesh with normals; .report too

Failures raise :class:`VstreeError` with the C status and the library's message; arguments
the binding can judge before calling C raise TypeError or ValueError naming the function and
the argument (a path with a NUL byte, a closed Mesh or Tree, a float where an integer is
needed, an unknown enum name), as do arrays numpy cannot convert. Depends on
numpy and the standard library only (Blender's Python has both). The calls release the GIL,
so threads can simplify different meshes at once. Closing a Mesh or Tree while a call uses it
(from the call's progress callback, or from another thread) raises RuntimeError and leaves
it open: close it after the call returns.
"""

import contextlib
import ctypes
import numbers
import operator
import os
import threading
from collections import namedtuple

import numpy as np

from . import _ffi
from ._ffi import lib

__all__ = [
    "ABI_VERSION",
    "Mesh",
    "Tree",
    "SimplifyResult",
    "ReconstructResult",
    "NormalsResult",
    "VstreeError",
    "CancelledError",
    "simplify",
    "simplify_ply_file",
    "reconstruct",
    "estimate_normals",
    "load",
    "version",
    "library_path",
    "Status",
]

ABI_VERSION = _ffi.ABI_VERSION
version = _ffi.version
library_path = _ffi.library_path


class Status:
    """The C API's status numbers (vstree_status)."""

    OK = 0
    NULL_POINTER = 1
    INVALID_ARGUMENT = 2
    INVALID_PARAMETER = 3
    INVALID_INPUT = 4
    TOO_LARGE = 5
    OUT_OF_MEMORY = 6
    IO = 7
    PARSE = 8
    UNSUPPORTED_FORMAT = 9
    CANCELLED = 10
    BUFFER_TOO_SMALL = 11
    INTERNAL = 12


class VstreeError(Exception):
    """A failed vstree call. ``status`` is the C status number (see :class:`Status`),
    ``message`` the library's detail (function, parameter or argument, file and line...)."""

    def __init__(self, status, message):
        self.status = status
        self.message = message
        name = lib.vstree_status_str(status).decode()
        super().__init__("%s [status %d: %s]" % (message, status, name))


class CancelledError(VstreeError):
    """The progress callback asked to stop (status CANCELLED)."""


def _check(status):
    if status != Status.OK:
        message = lib.vstree_last_error_message().decode("utf-8", "replace")
        cls = CancelledError if status == Status.CANCELLED else VstreeError
        raise cls(status, message)


def _c_string(value, what):
    """The bytes of a path or name (str, bytes or os.PathLike) for a NUL-terminated C string.
    C ends the string at the first NUL, so a path with one in it would name another file
    ("victim.ply\\0-simplified.ply" would overwrite victim.ply): refuse it, as open() does."""
    encoded = os.fsencode(value)
    if b"\0" in encoded:
        raise ValueError("%s contains an embedded null byte: %r" % (what, os.fspath(value)))
    return encoded


def _path(path):
    return _c_string(path, "path")


class _Owner:
    """What :class:`Mesh` and :class:`Tree` share: the library handle each owns, freed by
    close() or when the object is garbage-collected. A copy that shared the handle would free
    it twice, and pickle would store a pointer into this process: copy.copy(),
    copy.deepcopy() and pickle refuse with TypeError unless the class makes a new handle from
    its data (Mesh does).

    Every call that gives the handle to the library holds it through :meth:`_use`, which
    counts the calls running with it (under a lock: the calls release the GIL, so other
    threads run meanwhile, and a progress callback runs Python code in the middle of one).
    close() refuses while that count is not zero, instead of freeing what the library reads."""

    __slots__ = ("_handle", "_lock", "_users")
    #: The object's name in messages ("mesh"), and what to do instead of copying it.
    _what = "object"
    _instead = ""

    def _own(self, handle):
        self._lock = threading.Lock()
        self._users = []  # the names of the calls running with the handle
        self._handle = handle

    def _free(self, handle):
        raise NotImplementedError

    @contextlib.contextmanager
    def _use(self, who):
        """The handle, held for the call ``who`` until the block ends; a closed object has
        none (C would report a NULL pointer instead of saying why)."""
        lock = getattr(self, "_lock", None)
        if lock is None:  # made by a constructor that failed
            raise ValueError("the %s was closed" % self._what)
        with lock:
            if not self._handle:
                raise ValueError("the %s was closed" % self._what)
            self._users.append(who)
        try:
            yield self._handle
        finally:
            with lock:
                self._users.remove(who)

    def close(self):
        """Frees the library's object now (it is freed when garbage-collected otherwise);
        closing twice is harmless. While a call uses the object (close() called from the
        call's progress callback, or from another thread: the calls release the GIL), it is
        refused with RuntimeError, and the object stays usable: the library is reading it, and
        a close deferred until the call returns would break close()'s promise that the memory
        is free when it returns. Close it after the call returns."""
        lock = getattr(self, "_lock", None)
        if lock is None:
            return
        with lock:
            if self._users:
                raise RuntimeError(
                    "%s.close: the %s is in use by %s, which is still running (close() was called from its "
                    "progress callback or from another thread); the library reads it, so it cannot be freed "
                    "now: close it after the call returns" % (type(self).__name__, self._what, self._users[0])
                )
            handle, self._handle = self._handle, None
        if handle:
            self._free(handle)

    def __del__(self):
        try:
            self.close()
        except Exception:  # interpreter shutdown: the library may already be unloaded
            pass

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __reduce__(self):
        name = type(self).__name__
        raise TypeError(
            "vstree.%s cannot be copied or pickled: it owns a %s in the library, which a copy would "
            "share and free twice, and a pickle would store only its address; %s" % (name, self._what, self._instead)
        )


class Mesh(_Owner):
    """A triangle mesh, or a point cloud when it has no triangles; immutable.

    ``positions``: (n, 3) array-like of floats; ``triangles``: (m, 3) array-like of vertex
    indices (None or empty for a point cloud); ``normals``: None or (n, 3) floats. The arrays
    are copied into the library.

    float32 positions are used as they are. Any others (float64, integers, lists) are read in
    double precision and kept as a file's are: a model far from the origin for its size
    (georeferenced coordinates at 1e6 or 1e8) is stored relative to its own centre, so its
    detail survives and :attr:`positions_f64` gives it back.

    copy.copy(), copy.deepcopy() and pickle make an independent mesh from its arrays
    (positions in float64, so a model far from the origin is copied exactly).
    """

    __slots__ = ()
    _what = "mesh"

    def __init__(self, positions, triangles=None, normals=None):
        p = _as_rows(positions, None, "positions")
        n = None if normals is None else _as_rows(normals, np.float32, "normals")
        if n is not None and n.shape != p.shape:
            raise ValueError("normals has shape %s, positions %s" % (n.shape, p.shape))
        t = np.zeros((0, 3), np.uint32) if triangles is None else _as_indices(triangles)
        create, pointer = (
            (lib.vstree_mesh_create, _ffi._F32P) if p.dtype == np.float32 else (lib.vstree_mesh_create_f64, _ffi._F64P)
        )
        handle = ctypes.c_void_p()
        _check(
            create(
                p.ctypes.data_as(pointer),
                p.shape[0],
                None if n is None else n.ctypes.data_as(_ffi._F32P),
                t.ctypes.data_as(_ffi._U32P),
                t.shape[0],
                ctypes.byref(handle),
            )
        )
        self._own(handle.value)

    @classmethod
    def _wrap(cls, handle):
        mesh = cls.__new__(cls)
        mesh._own(handle)
        return mesh

    def _free(self, handle):
        lib.vstree_mesh_free(handle)

    def __reduce__(self):
        """A new mesh from this one's arrays: what copy and pickle use."""
        return (Mesh, (self.positions_f64, self.triangles, self.normals))

    @classmethod
    def load(cls, path):
        """Reads .ply, .obj, .off, .xyz or .pwn (the extension gives the format)."""
        handle = ctypes.c_void_p()
        _check(lib.vstree_mesh_load(_path(path), ctypes.byref(handle)))
        return cls._wrap(handle.value)

    @classmethod
    def from_bytes(cls, data, name):
        """Parses a whole file held in memory; ``name`` ("scan.ply" or "ply"; str, bytes or
        os.PathLike) gives the format."""
        try:  # bytes(5) would be five NUL bytes, bytes("OFF") an unclear TypeError
            data = memoryview(data).tobytes()
        except TypeError:
            raise TypeError(
                "Mesh.from_bytes: `data` must be bytes-like (the file's content), not %s" % type(data).__name__
            ) from None
        handle = ctypes.c_void_p()
        _check(lib.vstree_mesh_load_memory(data, len(data), _c_string(name, "name"), ctypes.byref(handle)))
        return cls._wrap(handle.value)

    def save(self, path, ascii=False):
        """Writes the mesh (format from the extension; atomic: on error the file is unchanged)."""
        path = _path(path)
        with self._use("Mesh.save") as handle:
            _check(lib.vstree_mesh_save(handle, path, 1 if ascii else 0))

    @property
    def vertex_count(self):
        with self._use("Mesh.vertex_count") as handle:
            return lib.vstree_mesh_vertex_count(handle)

    @property
    def triangle_count(self):
        with self._use("Mesh.triangle_count") as handle:
            return lib.vstree_mesh_triangle_count(handle)

    @property
    def has_normals(self):
        with self._use("Mesh.has_normals") as handle:
            return lib.vstree_mesh_has_normals(handle) == 1

    @property
    def positions(self):
        """(n, 3) float32 array (a copy)."""
        with self._use("Mesh.positions") as handle:
            out = np.empty((lib.vstree_mesh_vertex_count(handle), 3), np.float32)
            _check(lib.vstree_mesh_copy_positions(handle, out.ctypes.data_as(_ffi._F32P), out.size))
        return out

    @property
    def positions_f64(self):
        """(n, 3) float64 array (a copy): the exact positions of a model read from a file far
        from the origin (georeferenced coordinates), which float32 would round."""
        with self._use("Mesh.positions_f64") as handle:
            out = np.empty((lib.vstree_mesh_vertex_count(handle), 3), np.float64)
            _check(lib.vstree_mesh_copy_positions_f64(handle, out.ctypes.data_as(_ffi._F64P), out.size))
        return out

    @property
    def normals(self):
        """(n, 3) float32 array (a copy), or None when the mesh has none."""
        with self._use("Mesh.normals") as handle:
            if lib.vstree_mesh_has_normals(handle) != 1:
                return None
            out = np.empty((lib.vstree_mesh_vertex_count(handle), 3), np.float32)
            _check(lib.vstree_mesh_copy_normals(handle, out.ctypes.data_as(_ffi._F32P), out.size))
        return out

    @property
    def triangles(self):
        """(m, 3) uint32 array of vertex indices (a copy)."""
        with self._use("Mesh.triangles") as handle:
            out = np.empty((lib.vstree_mesh_triangle_count(handle), 3), np.uint32)
            _check(lib.vstree_mesh_copy_triangles(handle, out.ctypes.data_as(_ffi._U32P), out.size))
        return out

    def __repr__(self):
        if not getattr(self, "_handle", None):
            return "<vstree.Mesh closed>"
        return "<vstree.Mesh %d vertices, %d triangles%s>" % (
            self.vertex_count,
            self.triangle_count,
            ", normals" if self.has_normals else "",
        )


def load(path):
    """Reads a mesh or point cloud: same as :meth:`Mesh.load`."""
    return Mesh.load(path)


def _using(who, mesh):
    """The handle of ``mesh``, which must be a :class:`Mesh` (not an array), held for the call
    ``who`` (see ``_Owner._use``)."""
    if not isinstance(mesh, Mesh):
        raise TypeError(
            "%s: `mesh` must be a vstree.Mesh, not %s (make one with vstree.Mesh(positions, triangles))"
            % (who, type(mesh).__name__)
        )
    return mesh._use(who)


def _rows(a, array, name):
    """``a`` as (n, 3) rows: flat arrays of 3k values are k rows."""
    if a.ndim == 1 and a.size % 3 == 0:
        a = a.reshape(-1, 3)
    if a.ndim != 2 or a.shape[1] != 3:
        raise ValueError("%s must have shape (n, 3), not %s" % (name, np.shape(array)))
    return a


def _as_rows(array, dtype, name):
    """(n, 3) rows of ``positions`` or ``normals`` in ``dtype``; None for positions: float32
    stays float32, anything else becomes float64. Refused here, with the array's name: None,
    strings, complex numbers (numpy would drop the imaginary part), objects that do not
    convert, and finite values too large for ``dtype`` (the library would see infinities)."""
    if array is None:
        raise TypeError("%s must be an (n, 3) array of numbers, not None" % name)
    try:  # ragged lists, objects that are not numbers: numpy's reason, with the array's name
        source = np.asarray(array)
        if dtype is None:
            dtype = np.float32 if source.dtype == np.float32 else np.float64
        if source.dtype.kind not in "USc":
            with np.errstate(over="ignore"):  # overflow is reported below, with the vertex
                a = np.ascontiguousarray(source, dtype=dtype)
    except (TypeError, ValueError) as e:
        raise type(e)("%s: %s" % (name, e)) from None
    if source.dtype.kind in "USc":
        raise TypeError("%s must be real numbers, not %s" % (name, source.dtype))
    a = _rows(a, array, name)
    if source.dtype.kind == "f" and source.dtype.itemsize > a.dtype.itemsize:
        overflow = np.isinf(a) & np.isfinite(source.reshape(a.shape))
        if overflow.any():
            row, column = np.argwhere(overflow)[0]
            value = source.reshape(a.shape)[row, column]
            if name == "positions":
                detail = (
                    "vertex %d has a coordinate of %g: at most 1e18 in magnitude is supported "
                    "(32-bit geometry); rescale the input" % (row, value)
                )
            else:
                detail = "normal %d has a component of %g, beyond the float32 range" % (row, value)
            raise VstreeError(Status.INVALID_INPUT, "vstree.Mesh: invalid input: " + detail)
    return a


def _as_indices(triangles):
    try:
        t = np.asarray(triangles)
    except (TypeError, ValueError) as e:
        raise type(e)("triangles: %s" % e) from None
    if t.size == 0:
        return np.zeros((0, 3), np.uint32)
    if t.dtype.kind not in "ui":
        raise TypeError("triangles must be integers, not %s" % t.dtype)
    t = _rows(t, triangles, "triangles")
    # Indices of a type wider than uint32, or signed, might not fit: check before converting
    # (the library checks each index against the vertex count anyway).
    fits = t.dtype.kind == "u" and t.dtype.itemsize <= 4
    if not fits:
        bad = (t < 0) | (t > 0xFFFFFFFF)
        if bad.any():
            row, column = np.argwhere(bad)[0]
            raise ValueError(
                "triangle %d uses vertex %d: indices must be in [0, 2^32 - 1]" % (row, t[row, column])
            )
    return np.ascontiguousarray(t, dtype=np.uint32)


# ---- parameters -----------------------------------------------------------------------------

Choice = namedtuple("Choice", ["value", "name", "label", "help"])
Choice.__doc__ = "One value of a choice parameter: its number, name (what the keyword takes), label and help."

Param = namedtuple(
    "Param", ["call", "name", "flag", "label", "kind", "default", "min", "max", "min_open", "max_open", "unit", "help", "choices"]
)
Param.__doc__ = """One parameter of a call, from the library's table (see :func:`parameters`):
``call`` ("simplify", "reconstruct" or "normals"), ``name`` (the keyword), ``flag`` (the
command line's, or ""), ``label``, ``kind`` ("real", "integer", "flag" or "choice"), ``default``
(for a choice, its name), ``min``/``max`` (each end included unless ``min_open``/``max_open``;
``max`` is ``inf`` where there is none), ``unit``, ``help`` and ``choices`` (a tuple of
:class:`Choice`)."""

_CALLS = ("simplify", "reconstruct", "normals")
_KINDS = ("real", "integer", "flag", "choice")


def _read_table():
    table = []
    for i in range(lib.vstree_param_count()):
        p = lib.vstree_param_get(i).contents
        choices = tuple(
            Choice(c.value, c.name.decode(), c.label.decode(), c.help.decode())
            for c in (lib.vstree_param_choice_get(i, k).contents for k in range(p.choice_count))
        )
        kind = _KINDS[p.kind]
        default = p.default_value
        if kind == "choice":
            default = next(c.name for c in choices if c.value == default)
        elif kind != "real":
            default = int(default)
        table.append(
            Param(_CALLS[p.call], p.name.decode(), p.flag.decode(), p.label.decode(), kind, default, p.min, p.max,
                  bool(p.min_open), bool(p.max_open), p.unit.decode(), p.help.decode(), choices)
        )
    return tuple(table)


_TABLE = _read_table()


def parameters(call=None):
    """The library's parameters (a tuple of :class:`Param`), every call's or ``call``'s alone
    ("simplify", "reconstruct" or "normals"): their keywords, defaults, ranges, units and
    descriptions, as the command line, the MeshLab plugin and the Blender add-on show them."""
    if call is not None and call not in _CALLS:
        raise ValueError("vstree.parameters: call %r is not one of %s" % (call, ", ".join(map(repr, _CALLS))))
    return tuple(p for p in _TABLE if call is None or p.call == call)


# Choice names to numbers, per keyword; "face_centers" is sampling's older name.
_ENUMS = {p.name: {c.name: c.value for c in p.choices} for p in _TABLE if p.kind == "choice"}
_ENUMS["sampling"]["face_centers"] = _ENUMS["sampling"]["faces"]
_C_INTEGERS = {ctypes.c_uint32: ("uint32", 0, 2**32 - 1), ctypes.c_int32: ("int32", -(2**31), 2**31 - 1)}


def _integer(who, key, value, expected="an integer"):
    """``value`` as a Python int; floats and strings are refused, not truncated (2.7 is not 2)."""
    try:
        return operator.index(value)
    except TypeError:
        raise TypeError(
            "%s: parameter `%s`: must be %s, not %r (%s)" % (who, key, expected, value, type(value).__name__)
        ) from None


def _set_options(who, p, options, fields):
    """Sets the fields of a C parameter struct from keyword options (the C field names; enums
    by name or number; booleans for flags). ``who`` names the Python function in messages.
    The library checks each value's range; here, only that it fits the C field's type."""
    types = dict(p._fields_)
    for key, value in options.items():
        if key not in fields:
            raise TypeError("%s: unknown parameter %r (the parameters are %s)" % (who, key, ", ".join(fields)))
        c_type = types[key]
        expected = "an integer"
        if key == "keep_topology" and isinstance(value, bool):
            value = "on" if value else "off"
        if key in _ENUMS:
            names = ", ".join(repr(n) for n in sorted(_ENUMS[key]))
            expected = "one of %s or an integer" % names
            if isinstance(value, str):
                if value.lower() not in _ENUMS[key]:
                    raise ValueError("%s: parameter `%s`: %r is not one of %s" % (who, key, value, names))
                value = _ENUMS[key][value.lower()]
        if c_type in _C_INTEGERS:
            value = _integer(who, key, value, expected)
            c_name, low, high = _C_INTEGERS[c_type]
            if not low <= value <= high:
                raise VstreeError(
                    Status.INVALID_PARAMETER,
                    "%s: parameter `%s`: %d is out of range for the C field (%s)" % (who, key, value, c_name),
                )
        try:
            setattr(p, key, value)
        except TypeError:
            raise TypeError(
                "%s: parameter `%s`: must be a real number, not %r (%s)" % (who, key, value, type(value).__name__)
            ) from None
    return p


_SIMPLIFY_FIELDS = tuple(p.name for p in parameters("simplify"))


def _params(who, options):
    """The C parameter struct of simplify and Tree from keyword options."""
    p = lib.vstree_simplify_params_default()
    p.struct_size = ctypes.sizeof(_ffi.SimplifyParams)
    return _set_options(who, p, options, _SIMPLIFY_FIELDS)


def _struct_dict(struct):
    out = {}
    for name, _ in struct._fields_:
        if name != "struct_size":
            out[name] = getattr(struct, name)
    return out


class _Progress:
    """Adapts a Python callable ``(fraction, stage) -> bool`` to the C callback. Returning False
    cancels; an exception inside it cancels too and is re-raised from the call."""

    def __init__(self, who, callback):
        if callback is not None and not callable(callback):
            raise TypeError(
                "%s: `progress` must be a callable (fraction, stage) -> bool, or None, not %r (%s)"
                % (who, callback, type(callback).__name__)
            )
        self.callback = callback
        self.error = None
        self.c_function = _ffi.PROGRESS(self._call) if callback is not None else _ffi.PROGRESS()

    def _call(self, _user_data, fraction, stage):
        try:
            keep_going = self.callback(fraction, stage.decode("utf-8", "replace"))
            return 0 if keep_going is False else 1
        except BaseException as e:  # noqa: B902 - carried across C and re-raised
            self.error = e
            return 0

    def check(self, status):
        if self.error is not None:
            raise self.error
        _check(status)


def _target_from_ratio(ratio, params, triangles):
    """``target_faces`` for a fraction ``ratio`` of ``triangles``."""
    who = "vstree.simplify"
    if "target_faces" in params:
        raise TypeError("%s: give `ratio` or `target_faces`, not both" % who)
    if isinstance(ratio, bool) or not isinstance(ratio, numbers.Real):
        raise TypeError("%s: parameter `ratio`: must be a real number, not %r (%s)" % (who, ratio, type(ratio).__name__))
    faces = ctypes.c_uint32()
    status = lib.vstree_faces_for_ratio(float(ratio), triangles, ctypes.byref(faces))
    if status != Status.OK:
        message = lib.vstree_last_error_message().decode("utf-8", "replace")
        raise VstreeError(status, "%s: %s" % (who, message.split(": ", 1)[1]))
    return faces.value


SimplifyResult = namedtuple("SimplifyResult", ["mesh", "stats"])
SimplifyResult.__doc__ = "The simplified :class:`Mesh` and a dict of statistics."


def simplify(mesh, progress=None, ratio=None, **params):
    """Simplifies ``mesh`` (a :class:`Mesh`, or a point cloud with normals) by clustering in a
    VS-Tree. Parameters are the C struct's fields: ``error`` (L2: relative to the squared
    bounding-box diagonal; default 1e-3; with ``metric="density"`` samples per cell, default
    16; not used with a size), ``tree_kind`` ("vstree" | "octree"), ``metric``
    ("l2" | "l21" | "density"), ``sampling`` ("vertices" | "faces"), ``d_a``, ``d_d``,
    ``max_depth``, ``threads`` (0 = all cores), ``min_cell_size``, ``keep_topology``
    ("auto", the default: kept when no edge has more than two triangles, closed or with
    borders as scans have; "on" or True; "off" or False: plain clustering), ``target_faces`` (triangles wanted instead of the bound; 0 = the bound).

    ``ratio`` (in (0, 1]) asks for that fraction of the input's triangles instead of
    ``target_faces`` (rounded, at least 1). Below what the topology allows, the result is the
    smallest mesh reachable: ``stats["output_triangles"]`` says how many, and
    ``stats["size_missed"]`` why (None when the size was met within 1% or 2 triangles).

    ``progress(fraction, stage)`` is called on this thread; returning False cancels
    (:class:`CancelledError`). Returns ``SimplifyResult(mesh, stats)``.
    """
    with _using("vstree.simplify", mesh) as handle:
        if ratio is not None:
            params["target_faces"] = _target_from_ratio(ratio, params, lib.vstree_mesh_triangle_count(handle))
        p = _params("vstree.simplify", params)
        cb = _Progress("vstree.simplify", progress)
        result = ctypes.c_void_p()
        cb.check(lib.vstree_simplify(handle, ctypes.byref(p), cb.c_function, None, ctypes.byref(result)))
    return _simplify_result(result)


def simplify_ply_file(path, progress=None, **params):
    """Simplifies the PLY file at ``path`` to ``target_faces`` triangles without holding it in
    memory, for meshes larger than memory: the file is read three times, a few MiB at a time,
    and memory follows the output's size plus 4 bytes per input vertex. The clustering is plain
    (the topology is not kept, sheets closer than a cluster may fuse), so ``keep_topology``
    may only be "auto" or "off"; the tree is built from a sample of the triangles. Other
    parameters as :func:`simplify`. Returns ``SimplifyResult(mesh, stats)``."""
    p = _params("vstree.simplify_ply_file", params)
    cb = _Progress("vstree.simplify_ply_file", progress)
    result = ctypes.c_void_p()
    cb.check(lib.vstree_simplify_ply_file(_path(path), ctypes.byref(p), cb.c_function, None, ctypes.byref(result)))
    return _simplify_result(result)


def _simplify_result(result):
    """The mesh and statistics of a simplification's result handle, which is freed."""
    try:
        c_stats = lib.vstree_simplify_result_get_stats(result)
        if c_stats.contents.struct_size < ctypes.sizeof(_ffi.SimplifyStats):
            raise VstreeError(Status.INTERNAL, "the library's statistics are older than this module")
        stats = _struct_dict(c_stats.contents)
        missed = lib.vstree_simplify_size_missed(ctypes.cast(c_stats, ctypes.c_void_p))
        stats["size_missed"] = missed.decode() if missed is not None else None
    except BaseException:
        lib.vstree_simplify_result_free(result)
        raise
    out = ctypes.c_void_p()
    _check(lib.vstree_simplify_result_take_mesh(result, ctypes.byref(out)))
    return SimplifyResult(Mesh._wrap(out.value), stats)


class Tree(_Owner):
    """The tree :func:`simplify` would cluster ``mesh`` with (same parameters), for viewers:
    ``stats`` (dict), ``nodes``, ``t_nodes`` (the T-layer with frames), ``levels`` (node
    counts per depth) as numpy structured arrays, and :meth:`vertex_labels`.

    A tree cannot be copied or pickled (TypeError): the library has no copy of it and it does
    not keep its mesh; build another, or copy its arrays, which are numpy arrays."""

    NO_INDEX = 0xFFFFFFFF
    _what = "tree"
    _instead = (
        "build another with vstree.Tree(mesh, **params), or copy or pickle its arrays (stats, nodes, "
        "t_nodes, levels, vertex_labels()), which are plain Python and numpy objects"
    )

    def __init__(self, mesh, progress=None, **params):
        p = _params("vstree.Tree", params)
        with _using("vstree.Tree", mesh) as mesh_handle:
            cb = _Progress("vstree.Tree", progress)
            handle = ctypes.c_void_p()
            cb.check(lib.vstree_tree_build(mesh_handle, ctypes.byref(p), cb.c_function, None, ctypes.byref(handle)))
        self._own(handle.value)
        self.stats = _struct_dict(lib.vstree_tree_get_stats(handle.value).contents)

    def _free(self, handle):
        lib.vstree_tree_free(handle)

    def _copy(self, who, struct, count, copy):
        with self._use(who) as handle:
            out = np.zeros(count(handle), dtype=np.dtype(struct))
            _check(copy(handle, out.ctypes.data_as(ctypes.POINTER(struct)), out.size))
        return out

    @property
    def nodes(self):
        """Every node: parent, first_child, child_count, kind (0 V, 1 T, 2 S), depth,
        sample_count, t_node, cluster, center (3), half."""
        return self._copy("Tree.nodes", _ffi.Node, lib.vstree_tree_node_count, lib.vstree_tree_copy_nodes)

    @property
    def t_nodes(self):
        """The T-layer: node, depth, sample_count, cluster_count, cube_center, cube_half,
        origin, normal, u, v, square_center, square_half."""
        return self._copy("Tree.t_nodes", _ffi.TNode, lib.vstree_tree_t_node_count, lib.vstree_tree_copy_t_nodes)

    @property
    def levels(self):
        """Node counts per depth: v_nodes, t_nodes, s_nodes, leaves."""
        return self._copy("Tree.levels", _ffi.TreeLevel, lib.vstree_tree_level_count, lib.vstree_tree_copy_levels)

    def vertex_labels(self, kind="cluster"):
        """One uint32 per input vertex: its cluster ("cluster") or its T-node's index in
        :attr:`t_nodes` ("t_node"); ``Tree.NO_INDEX`` for none."""
        kinds = {"cluster": 0, "t_node": 1}
        if not isinstance(kind, str) or kind not in kinds:
            raise ValueError("Tree.vertex_labels: `kind` must be 'cluster' or 't_node', not %r" % (kind,))
        with self._use("Tree.vertex_labels") as handle:
            out = np.empty(lib.vstree_tree_vertex_count(handle), np.uint32)
            _check(lib.vstree_tree_copy_vertex_labels(handle, kinds[kind], out.ctypes.data_as(_ffi._U32P), out.size))
        return out


# ---- reconstruction and normal estimation ---------------------------------------------------

_RECONSTRUCT_FIELDS = tuple(p.name for p in parameters("reconstruct"))
_NORMAL_FIELDS = tuple(p.name for p in parameters("normals"))


def _cloud(points, normals):
    """A :class:`Mesh` from a Mesh, or from (n, 3) points and optional normals."""
    if isinstance(points, Mesh):
        if normals is not None:
            raise ValueError("normals are given with the Mesh, not separately")
        return points
    return Mesh(points, None, normals)


ReconstructResult = namedtuple("ReconstructResult", ["mesh", "stats"])
ReconstructResult.__doc__ = "The reconstructed :class:`Mesh` (with normals) and a dict of statistics."

NormalsResult = namedtuple("NormalsResult", ["mesh", "report"])
NormalsResult.__doc__ = "A :class:`Mesh` with normals, and a dict saying what was estimated or flipped."


def reconstruct(cloud, normals=None, progress=None, **params):
    """Reconstructs a triangle mesh from a point cloud: ``cloud`` is a :class:`Mesh`
    (its triangles are ignored) or an (n, 3) array of points, with ``normals`` optional (n, 3);
    missing normals are estimated and oriented outward. Parameters are the C struct's fields:
    ``error`` (the tree's L2 bound, the de-noising control; default 1e-5), ``max_levels``
    (refinement levels, 0-12; default 6), ``target_distance``, ``min_displaced``,
    ``max_triangles``, ``max_grid_depth`` (4-20; default 10), ``closure`` ("auto", the default: open
    where much of the closed surface is far from every point, as behind a scan from one side |
    "closed": always closed, holes closed over | "open": only the part of the surface the
    points support, holes kept), ``base_mesh`` ("adaptive", the
    default: the points' winding number decides inside and outside, polygonised over the tree's
    octree, each region at its own T-node's size | "winding": the same side on a grid as fine as
    the smallest T-node | "paper": the paper's blended T-node planes), ``trim`` (grid cells: every face farther goes; 0, the default,
    trims only past an open scan's border), ``d_a``, ``d_d``, ``max_depth``, ``min_cell_size``, ``orient``
    ("propagate_outward" | "propagate" | "propagate_majority" | "unoriented"), ``neighbours``,
    ``reorient_given``, ``threads``.

    ``progress(fraction, stage)`` is called on this thread; returning False cancels
    (:class:`CancelledError`). Returns ``ReconstructResult(mesh, stats)``; ``stats["base_genus"]``
    is -1 when the base mesh is not a closed manifold; ``stats["stopped"]`` says why refinement
    stopped ("target" | "no_detail" | "max_levels" | "triangle_budget"), and
    ``stats["thickened"]`` whether thin parts were thickened for the base mesh.
    """
    mesh = _cloud(cloud, normals)
    p = lib.vstree_reconstruct_params_default()
    p.struct_size = ctypes.sizeof(_ffi.ReconstructParams)
    _set_options("vstree.reconstruct", p, params, _RECONSTRUCT_FIELDS)
    cb = _Progress("vstree.reconstruct", progress)
    result = ctypes.c_void_p()
    with mesh._use("vstree.reconstruct") as handle:
        cb.check(lib.vstree_reconstruct(handle, ctypes.byref(p), cb.c_function, None, ctypes.byref(result)))
    try:
        stats = lib.vstree_reconstruct_result_get_stats(result).contents
        if stats.struct_size < ctypes.sizeof(_ffi.ReconstructStats):
            raise VstreeError(Status.INTERNAL, "the library's statistics are older than this module")
        stats = _struct_dict(stats)
        stats["stopped"] = lib.vstree_refinement_stopped_str(stats["stopped"]).decode()
        stats["thickened"] = bool(stats["thickened"])
        stats["open"] = bool(stats["open"])
    except BaseException:
        lib.vstree_reconstruct_result_free(result)
        raise
    out = ctypes.c_void_p()
    _check(lib.vstree_reconstruct_result_take_mesh(result, ctypes.byref(out)))
    return ReconstructResult(Mesh._wrap(out.value), stats)


def estimate_normals(cloud, normals=None, progress=None, **params):
    """Estimates unit normals where ``cloud`` has none (a :class:`Mesh`, whose triangles are
    kept but not used, or (n, 3) points with optional ``normals``; zero rows count as missing)
    and orients them; given normals are kept unless ``reorient_given=True``. Parameters:
    ``orient`` ("propagate_outward", the default, | "propagate" | "propagate_majority" |
    "unoriented"), ``neighbours`` (3-256; default 16), ``reorient_given``, ``threads``.

    The input is not changed: returns ``NormalsResult(mesh, report)`` with a new :class:`Mesh`
    (``mesh.normals`` the (n, 3) float32 normals) and a dict (``estimated``, ``flipped``...).
    """
    mesh = _cloud(cloud, normals)
    p = lib.vstree_normal_params_default()
    p.struct_size = ctypes.sizeof(_ffi.NormalParams)
    _set_options("vstree.estimate_normals", p, params, _NORMAL_FIELDS)
    report = _ffi.NormalsReport()
    report.struct_size = ctypes.sizeof(_ffi.NormalsReport)
    cb = _Progress("vstree.estimate_normals", progress)
    out = ctypes.c_void_p()
    with mesh._use("vstree.estimate_normals") as handle:
        cb.check(
            lib.vstree_estimate_normals(
                handle, ctypes.byref(p), cb.c_function, None, ctypes.byref(out), ctypes.byref(report)
            )
        )
    return NormalsResult(Mesh._wrap(out.value), _struct_dict(report))
