"""The C API of vstree through ctypes: finds and loads the library, checks its ABI version,
declares the structs and every function's argtypes/restype once.

The library is looked for, in order: the path in the environment variable ``VSTREE_LIBRARY``;
next to this package (``libvstree.so``, ``libvstree.so.<ABI>``, ``libvstree.dylib``,
``vstree.dll``). Standard library only.
"""

import ctypes
import os
import sys
from ctypes import (
    CFUNCTYPE,
    POINTER,
    Structure,
    c_char_p,
    c_double,
    c_float,
    c_int32,
    c_size_t,
    c_uint32,
    c_uint64,
    c_void_p,
)

#: The ABI this module is written for (VSTREE_ABI_VERSION in vstree.h).
ABI_VERSION = 0

_HERE = os.path.dirname(os.path.abspath(__file__))


def _candidates():
    env = os.environ.get("VSTREE_LIBRARY")
    if env:
        return [env]
    names = {
        "darwin": ["libvstree.dylib", "libvstree.%d.dylib" % ABI_VERSION],
        "win32": ["vstree.dll"],
    }.get(sys.platform, ["libvstree.so", "libvstree.so.%d" % ABI_VERSION])
    return [os.path.join(_HERE, name) for name in names]


def _load():
    tried = []
    for path in _candidates():
        if os.path.exists(path):
            try:
                return ctypes.CDLL(path), path
            except OSError as e:
                tried.append("%s (%s)" % (path, e))
        else:
            tried.append("%s (not found)" % path)
    raise ImportError(
        "vstree: cannot load the vstree library; tried: %s. Build it with "
        "`cargo build --release --no-default-features`, then copy target/release/libvstree.so "
        "next to this module or set VSTREE_LIBRARY to its path." % "; ".join(tried)
    )


lib, library_path = _load()

# ---- types (field for field as in vstree.h) -------------------------------------------------

status_t = c_int32
PROGRESS = CFUNCTYPE(c_int32, c_void_p, c_float, c_char_p)


class SimplifyParams(Structure):
    _fields_ = [
        ("struct_size", c_uint32),
        ("tree_kind", c_int32),
        ("metric", c_int32),
        ("sampling", c_int32),
        ("error", c_double),
        ("d_a", c_float),
        ("d_d", c_float),
        ("max_depth", c_uint32),
        ("threads", c_uint32),
        ("min_cell_size", c_double),
        ("keep_topology", c_int32),
        ("target_faces", c_uint32),
    ]


class SimplifyStats(Structure):
    _fields_ = [
        ("struct_size", c_uint32),
        ("max_depth", c_uint32),
        ("t_depth_min", c_uint32),
        ("t_depth_max", c_uint32),
        ("input_vertices", c_uint64),
        ("input_triangles", c_uint64),
        ("output_vertices", c_uint64),
        ("output_triangles", c_uint64),
        ("samples", c_uint64),
        ("nodes", c_uint64),
        ("v_nodes", c_uint64),
        ("t_nodes", c_uint64),
        ("s_nodes", c_uint64),
        ("clusters", c_uint64),
        ("cluster_size_mean", c_double),
        ("cluster_size_variance", c_double),
        ("seconds_samples", c_double),
        ("seconds_tree", c_double),
        ("seconds_cluster", c_double),
        ("seconds_total", c_double),
        ("kept_topology", c_uint32),
        ("target_faces", c_uint32),
    ]


class TreeStats(Structure):
    _fields_ = [
        ("struct_size", c_uint32),
        ("max_depth", c_uint32),
        ("t_depth_min", c_uint32),
        ("t_depth_max", c_uint32),
        ("samples", c_uint64),
        ("nodes", c_uint64),
        ("v_nodes", c_uint64),
        ("t_nodes", c_uint64),
        ("s_nodes", c_uint64),
        ("clusters", c_uint64),
        ("vertices", c_uint64),
        ("cluster_size_mean", c_double),
        ("cluster_size_variance", c_double),
        ("max_cluster_error", c_double),
        ("mean_cluster_error", c_double),
        ("diagonal", c_double),
        ("seconds_samples", c_double),
        ("seconds_tree", c_double),
        ("seconds_total", c_double),
    ]


class Node(Structure):
    _fields_ = [
        ("parent", c_uint32),
        ("first_child", c_uint32),
        ("child_count", c_uint32),
        ("kind", c_int32),
        ("depth", c_uint32),
        ("sample_count", c_uint32),
        ("t_node", c_uint32),
        ("cluster", c_uint32),
        ("center", c_float * 3),
        ("half", c_float),
    ]


class TNode(Structure):
    _fields_ = [
        ("node", c_uint32),
        ("depth", c_uint32),
        ("sample_count", c_uint32),
        ("cluster_count", c_uint32),
        ("cube_center", c_float * 3),
        ("cube_half", c_float),
        ("origin", c_float * 3),
        ("normal", c_float * 3),
        ("u", c_float * 3),
        ("v", c_float * 3),
        ("square_center", c_float * 2),
        ("square_half", c_float),
    ]


class TreeLevel(Structure):
    _fields_ = [
        ("v_nodes", c_uint64),
        ("t_nodes", c_uint64),
        ("s_nodes", c_uint64),
        ("leaves", c_uint64),
    ]


class NormalParams(Structure):
    _fields_ = [
        ("struct_size", c_uint32),
        ("orient", c_int32),
        ("neighbours", c_uint32),
        ("reorient_given", c_uint32),
        ("threads", c_uint32),
    ]


class NormalsReport(Structure):
    _fields_ = [
        ("struct_size", c_uint32),
        ("oriented", c_uint32),
        ("estimated", c_uint64),
        ("neighbours", c_uint64),
        ("degenerate", c_uint64),
        ("components", c_uint64),
        ("largest_component", c_uint64),
        ("undecided_components", c_uint64),
        ("flipped", c_uint64),
    ]


class ReconstructParams(Structure):
    _fields_ = [
        ("struct_size", c_uint32),
        ("orient", c_int32),
        ("error", c_double),
        ("d_a", c_float),
        ("d_d", c_float),
        ("max_depth", c_uint32),
        ("max_levels", c_uint32),
        ("min_cell_size", c_double),
        ("target_distance", c_double),
        ("min_displaced", c_double),
        ("max_triangles", c_uint32),
        ("max_grid_depth", c_uint32),
        ("trim", c_float),
        ("neighbours", c_uint32),
        ("reorient_given", c_uint32),
        ("threads", c_uint32),
        ("closure", c_int32),
        ("base_mesh", c_int32),
    ]


class ReconstructStats(Structure):
    _fields_ = [
        ("struct_size", c_uint32),
        ("grid_cells", c_uint32),
        ("base_genus", c_int32),
        ("levels", c_uint32),
        ("max_depth", c_uint32),
        ("normals_neighbours", c_uint32),
        ("normals_estimated", c_uint64),
        ("normals_flipped", c_uint64),
        ("input_points", c_uint64),
        ("samples", c_uint64),
        ("nodes", c_uint64),
        ("t_nodes", c_uint64),
        ("fine_triangles", c_uint64),
        ("base_vertices", c_uint64),
        ("base_triangles", c_uint64),
        ("base_error", c_double),
        ("final_error", c_double),
        ("final_max_error", c_double),
        ("trimmed_triangles", c_uint64),
        ("output_vertices", c_uint64),
        ("output_triangles", c_uint64),
        ("seconds_normals", c_double),
        ("seconds_tree", c_double),
        ("seconds_base", c_double),
        ("seconds_refine", c_double),
        ("seconds_trim", c_double),
        ("seconds_total", c_double),
        ("stopped", c_uint32),
        ("thickened", c_uint32),
        ("open", c_uint32),
        ("base_boundary_edges", c_uint32),
        ("unsupported_share", c_double),
    ]


class ParamInfo(Structure):
    _fields_ = [
        ("struct_size", c_uint32),
        ("call", c_int32),
        ("kind", c_int32),
        ("choice_count", c_uint32),
        ("name", c_char_p),
        ("flag", c_char_p),
        ("label", c_char_p),
        ("unit", c_char_p),
        ("help", c_char_p),
        ("default_value", c_double),
        ("min", c_double),
        ("max", c_double),
        ("min_open", c_uint32),
        ("max_open", c_uint32),
    ]


class ParamChoice(Structure):
    _fields_ = [
        ("struct_size", c_uint32),
        ("value", c_int32),
        ("name", c_char_p),
        ("label", c_char_p),
        ("help", c_char_p),
    ]


# ---- functions ------------------------------------------------------------------------------

_F32P = POINTER(c_float)
_F64P = POINTER(c_double)
_U32P = POINTER(c_uint32)
_SIGNATURES = {
    "vstree_version": (c_char_p, []),
    "vstree_param_count": (c_uint32, []),
    "vstree_param_get": (POINTER(ParamInfo), [c_uint32]),
    "vstree_param_choice_get": (POINTER(ParamChoice), [c_uint32, c_uint32]),
    "vstree_param_find": (c_int32, [c_int32, c_char_p]),
    "vstree_faces_for_ratio": (status_t, [c_double, c_uint64, _U32P]),
    "vstree_l2_error_for_distance": (c_double, [c_double, c_double]),
    "vstree_simplify_size_missed": (c_char_p, [c_void_p]),
    "vstree_abi_version": (c_uint32, []),
    "vstree_status_str": (c_char_p, [c_int32]),
    "vstree_last_error_message": (c_char_p, []),
    "vstree_last_error_copy": (c_size_t, [c_char_p, c_size_t]),
    "vstree_mesh_create": (
        status_t,
        [_F32P, c_size_t, _F32P, _U32P, c_size_t, POINTER(c_void_p)],
    ),
    "vstree_mesh_create_f64": (
        status_t,
        [_F64P, c_size_t, _F32P, _U32P, c_size_t, POINTER(c_void_p)],
    ),
    "vstree_mesh_load": (status_t, [c_char_p, POINTER(c_void_p)]),
    "vstree_mesh_load_memory": (status_t, [c_void_p, c_size_t, c_char_p, POINTER(c_void_p)]),
    "vstree_mesh_save": (status_t, [c_void_p, c_char_p, c_uint32]),
    "vstree_mesh_free": (None, [c_void_p]),
    "vstree_mesh_vertex_count": (c_size_t, [c_void_p]),
    "vstree_mesh_triangle_count": (c_size_t, [c_void_p]),
    "vstree_mesh_has_normals": (c_int32, [c_void_p]),
    "vstree_mesh_copy_positions": (status_t, [c_void_p, _F32P, c_size_t]),
    "vstree_mesh_copy_positions_f64": (status_t, [c_void_p, _F64P, c_size_t]),
    "vstree_mesh_copy_normals": (status_t, [c_void_p, _F32P, c_size_t]),
    "vstree_mesh_copy_triangles": (status_t, [c_void_p, _U32P, c_size_t]),
    "vstree_simplify_params_default": (SimplifyParams, []),
    "vstree_simplify": (
        status_t,
        [c_void_p, POINTER(SimplifyParams), PROGRESS, c_void_p, POINTER(c_void_p)],
    ),
    "vstree_simplify_ply_file": (
        status_t,
        [c_char_p, POINTER(SimplifyParams), PROGRESS, c_void_p, POINTER(c_void_p)],
    ),
    "vstree_simplify_result_get_mesh": (c_void_p, [c_void_p]),
    "vstree_simplify_result_get_stats": (POINTER(SimplifyStats), [c_void_p]),
    "vstree_simplify_result_free": (None, [c_void_p]),
    "vstree_simplify_result_take_mesh": (status_t, [c_void_p, POINTER(c_void_p)]),
    "vstree_tree_build": (
        status_t,
        [c_void_p, POINTER(SimplifyParams), PROGRESS, c_void_p, POINTER(c_void_p)],
    ),
    "vstree_tree_free": (None, [c_void_p]),
    "vstree_tree_get_stats": (POINTER(TreeStats), [c_void_p]),
    "vstree_tree_node_count": (c_size_t, [c_void_p]),
    "vstree_tree_t_node_count": (c_size_t, [c_void_p]),
    "vstree_tree_level_count": (c_size_t, [c_void_p]),
    "vstree_tree_vertex_count": (c_size_t, [c_void_p]),
    "vstree_tree_copy_nodes": (status_t, [c_void_p, POINTER(Node), c_size_t]),
    "vstree_tree_copy_t_nodes": (status_t, [c_void_p, POINTER(TNode), c_size_t]),
    "vstree_tree_copy_levels": (status_t, [c_void_p, POINTER(TreeLevel), c_size_t]),
    "vstree_tree_copy_vertex_labels": (status_t, [c_void_p, c_int32, _U32P, c_size_t]),
    "vstree_normal_params_default": (NormalParams, []),
    "vstree_estimate_normals": (
        status_t,
        [c_void_p, POINTER(NormalParams), PROGRESS, c_void_p, POINTER(c_void_p), POINTER(NormalsReport)],
    ),
    "vstree_reconstruct_params_default": (ReconstructParams, []),
    "vstree_reconstruct": (
        status_t,
        [c_void_p, POINTER(ReconstructParams), PROGRESS, c_void_p, POINTER(c_void_p)],
    ),
    "vstree_reconstruct_result_get_mesh": (c_void_p, [c_void_p]),
    "vstree_reconstruct_result_get_stats": (POINTER(ReconstructStats), [c_void_p]),
    "vstree_reconstruct_result_free": (None, [c_void_p]),
    "vstree_reconstruct_result_take_mesh": (status_t, [c_void_p, POINTER(c_void_p)]),
    "vstree_refinement_stopped_str": (c_char_p, [c_uint32]),
}

for _name, (_restype, _argtypes) in _SIGNATURES.items():
    try:
        _function = getattr(lib, _name)
    except AttributeError:
        raise ImportError(
            "vstree: %s has no %s(): the library is older than this module" % (library_path, _name)
        ) from None
    _function.restype = _restype
    _function.argtypes = _argtypes

# ---- ABI check ------------------------------------------------------------------------------

_abi = lib.vstree_abi_version()
if _abi != ABI_VERSION:
    raise ImportError(
        "vstree: %s has ABI version %d, this module needs %d (library version %s)"
        % (library_path, _abi, ABI_VERSION, lib.vstree_version().decode())
    )
if lib.vstree_simplify_params_default().struct_size < ctypes.sizeof(SimplifyParams):
    raise ImportError("vstree: %s is older than this module (parameter struct)" % library_path)
if lib.vstree_reconstruct_params_default().struct_size < ctypes.sizeof(ReconstructParams):
    raise ImportError("vstree: %s is older than this module (reconstruction parameters)" % library_path)

version = lib.vstree_version().decode()
