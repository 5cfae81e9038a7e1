//! Clustering simplification: the parameter struct (shared with vstree_tree_build(), which
//! builds the same tree), the call, and its result handle with the output mesh and statistics.

use super::mesh::{mesh_ref, path_arg, vstree_mesh};
use super::params::{self, c_enum, enum_field, threads, Versioned};
use super::progress::{vstree_progress_fn, with_progress};
use super::{guard, handle, non_null, vstree_status, write_out, FfiResult};
use crate::mesh::Mesh;
use crate::samples::MeshSampling;
use crate::simplify::{simplify, simplify_ply_streaming, KeepTopology, SimplifyParams, SimplifyStats};
use crate::tree::{Metric, TreeKind, TreeParams, TreeStats};
use std::ffi::{c_char, c_void};
use std::time::Instant;

/// Which hierarchy to build (the `tree_kind` field).
#[repr(i32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum vstree_tree_kind {
    /// The Volume-Surface Tree: an octree far from the surface, quadtrees in the surface's
    /// local frames near it (the paper's structure).
    VsTree = 0,
    /// A plain octree with the same metric and thresholds: the baseline to compare with.
    Octree = 1,
}
c_enum!(vstree_tree_kind { VsTree = "VSTREE_TREE_KIND_VS_TREE", Octree = "VSTREE_TREE_KIND_OCTREE" });

/// The error metric that decides whether a cell is split (the `metric` field).
#[repr(i32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum vstree_metric {
    /// Quadric (L2) error: sum of squared distances from the cluster's point to its samples'
    /// tangent planes, over the squared bounding-box diagonal. Every sample's plane then passes
    /// within sqrt(error) × diagonal of its cluster's point.
    L2 = 0,
    /// Normal deviation (L2,1): mean of |n - mean n|² over the cell's samples; unitless, 0 for
    /// a flat cell, at most 4.
    L21 = 1,
    /// Sample count: a cell with at most `error` samples is a leaf.
    Density = 2,
}
c_enum!(vstree_metric { L2 = "VSTREE_METRIC_L2", L21 = "VSTREE_METRIC_L21", Density = "VSTREE_METRIC_DENSITY" });

/// Which mesh elements become the tree's samples (the `sampling` field). Point clouds always
/// use their points.
#[repr(i32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum vstree_sampling {
    /// One sample per vertex used by a non-degenerate triangle, with the area-weighted normal
    /// of its triangles.
    Vertices = 0,
    /// One sample per non-degenerate triangle, at its centre, with its normal.
    FaceCenters = 1,
}
c_enum!(vstree_sampling { Vertices = "VSTREE_SAMPLING_VERTICES", FaceCenters = "VSTREE_SAMPLING_FACE_CENTERS" });

/// Whether vstree_simplify() keeps the input's topology (the `keep_topology` field).
#[repr(i32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum vstree_keep_topology {
    /// Keep it when no edge of the input has more than two triangles (closed or with
    /// borders, as most scans are); plain clustering on non-manifold input. The default.
    Auto = 0,
    /// Clusters merge by edge collapses under the link condition: a closed 2-manifold stays
    /// closed and manifold with its genus, an open one keeps its borders manifold and its holes. A cluster
    /// that cannot merge without changing the topology keeps a vertex per piece.
    On = 1,
    /// Plain vertex clustering (the paper's): faster, but it may fuse sheets and make
    /// non-manifold edges.
    Off = 2,
}
c_enum!(vstree_keep_topology {
    Auto = "VSTREE_KEEP_TOPOLOGY_AUTO",
    On = "VSTREE_KEEP_TOPOLOGY_ON",
    Off = "VSTREE_KEEP_TOPOLOGY_OFF",
});

/// Parameters of vstree_simplify() and vstree_tree_build(). Always start from
/// vstree_simplify_params_default() and change fields by name: it sets `struct_size`, and
/// fields added in later versions then keep their defaults. Passing NULL means the defaults.
/// The struct has no padding; every field is checked, and an out-of-range one fails the call
/// with VSTREE_STATUS_INVALID_PARAMETER and a message naming it.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct vstree_simplify_params {
    /// Size of this struct in bytes as the caller knows it; set by the _default() function.
    pub struct_size: u32,
    /// A vstree_tree_kind value. Default VSTREE_TREE_KIND_VS_TREE.
    pub tree_kind: i32,
    /// A vstree_metric value. Default VSTREE_METRIC_L2.
    pub metric: i32,
    /// A vstree_sampling value. Default VSTREE_SAMPLING_VERTICES.
    pub sampling: i32,
    /// Split threshold per cluster, read according to `metric`: L2, relative to the squared
    /// bounding-box diagonal, finite and > 0 (default 1e-3; larger = coarser); L2,1, unitless,
    /// in (0, 4] (default 1e-3); density, a sample count >= 1 (default 16: the default 1e-3
    /// left in place reads as 16 under density, where it means nothing). Ignored, and not
    /// checked, when `target_faces` is set.
    pub error: f64,
    /// Height-field test, normal cone: a cell becomes a surface (2D) node only if every
    /// sample's normal has a dot product above `d_a` with the mean normal. Unitless, in [0, 1];
    /// default 0. Raise it for more adaptivity on curved parts.
    pub d_a: f32,
    /// Height-field test, displacement: the samples' heights above the cell's mean plane over
    /// its radius must stay below `d_d`. Unitless, in [0, 1]; default 1/6.
    pub d_d: f32,
    /// Deepest tree level, octree and quadtree levels counted together, in [1, 30]; default 24.
    pub max_depth: u32,
    /// Worker threads: 0 = all cores (default), else at most 1024. Results do not depend on it.
    pub threads: u32,
    /// Cells smaller than this fraction of the bounding-box diagonal are not split (guards
    /// against duplicate points). In [0, 1); default 1e-7.
    pub min_cell_size: f64,
    /// A vstree_keep_topology value. Default VSTREE_KEEP_TOPOLOGY_AUTO. Since 0.2.0 (callers
    /// built against an older header get the default).
    pub keep_topology: i32,
    /// Triangles wanted, from 1 to the input's count; 0 (the default) = as many as `error`
    /// gives. With a target, `error` is no bound: the tree is grown or cut, splitting the
    /// cluster with the largest error first, to about half as many clusters as triangles
    /// wanted (twice as many when the topology is kept, so that collapses choose the last
    /// vertices), and quadric edge collapses (under the same topology rules) bring the mesh
    /// to the target, within one triangle. A target below what the topology allows (a closed
    /// surface of genus g needs more than 4 g triangles; a tetrahedron, 4, is the least) gives
    /// the smallest mesh the collapses reach: compare the stats' `output_triangles`. Meshes
    /// only; ignored by vstree_tree_build(). Since 0.2.0.
    pub target_faces: u32,
}

unsafe impl Versioned for vstree_simplify_params {
    const NAME: &'static str = "vstree_simplify_params";
    const MIN_SIZE: usize = 48;
    fn defaults() -> Self {
        let tree = TreeParams::default();
        vstree_simplify_params {
            struct_size: std::mem::size_of::<Self>() as u32,
            tree_kind: vstree_tree_kind::VsTree as i32,
            metric: vstree_metric::L2 as i32,
            sampling: vstree_sampling::Vertices as i32,
            error: tree.error,
            d_a: tree.d_a,
            d_d: tree.d_d,
            max_depth: tree.max_depth,
            threads: 0,
            min_cell_size: tree.min_cell_size,
            keep_topology: vstree_keep_topology::Auto as i32,
            target_faces: 0,
        }
    }
}

/// The default parameters, with `struct_size` set. Thread-safe; returns a value (nothing to
/// free).
#[no_mangle]
pub extern "C" fn vstree_simplify_params_default() -> vstree_simplify_params {
    vstree_simplify_params::defaults()
}

/// Reads and checks the caller's parameters (NULL: defaults), naming any bad field.
pub(crate) unsafe fn read_params(pointer: *const vstree_simplify_params) -> FfiResult<SimplifyParams> {
    let p = unsafe { params::read(pointer, "params") }?;
    let kind = match enum_field("tree_kind", p.tree_kind)? {
        vstree_tree_kind::VsTree => TreeKind::VsTree,
        vstree_tree_kind::Octree => TreeKind::Octree,
    };
    let metric = match enum_field("metric", p.metric)? {
        vstree_metric::L2 => Metric::L2,
        vstree_metric::L21 => Metric::L21,
        vstree_metric::Density => Metric::Density,
    };
    let sampling = match enum_field("sampling", p.sampling)? {
        vstree_sampling::Vertices => MeshSampling::Vertices,
        vstree_sampling::FaceCenters => MeshSampling::FaceCenters,
    };
    // The default struct holds L2's bound, which the density metric cannot read as a count.
    let error = if metric == Metric::Density && p.error == vstree_simplify_params::defaults().error {
        metric.default_error()
    } else {
        p.error
    };
    let tree = TreeParams {
        kind,
        metric,
        error,
        d_a: p.d_a,
        d_d: p.d_d,
        max_depth: p.max_depth,
        min_cell_size: p.min_cell_size,
    };
    let threads = threads(p.threads)?;
    let keep_topology = match enum_field("keep_topology", p.keep_topology)? {
        vstree_keep_topology::Auto => KeepTopology::Auto,
        vstree_keep_topology::On => KeepTopology::On,
        vstree_keep_topology::Off => KeepTopology::Off,
    };
    let params = SimplifyParams { tree, sampling, threads, keep_topology, target_faces: p.target_faces as usize };
    params.check()?;
    Ok(params)
}

/// What a simplification did. Owned by its result (vstree_simplify_result_get_stats()); later
/// versions only add fields at the end, and `struct_size` says how many there are.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct vstree_simplify_stats {
    /// Size of this struct in bytes as the library filled it.
    pub struct_size: u32,
    /// Deepest level of the tree (the root is level 0).
    pub max_depth: u32,
    /// Shallowest level holding a T-node (0 when there is none).
    pub t_depth_min: u32,
    /// Deepest level holding a T-node (0 when there is none).
    pub t_depth_max: u32,
    /// Vertices (points) of the input.
    pub input_vertices: u64,
    /// Triangles of the input (0 for a point cloud).
    pub input_triangles: u64,
    /// Vertices of the output: the clusters that kept a triangle (all clusters for clouds).
    pub output_vertices: u64,
    /// Triangles of the output.
    pub output_triangles: u64,
    /// Samples the tree was built from.
    pub samples: u64,
    /// Nodes of the tree, of every kind.
    pub nodes: u64,
    /// Volume (octree) nodes.
    pub v_nodes: u64,
    /// Transition nodes: the T-layer, where octree cells turn into quadtrees.
    pub t_nodes: u64,
    /// Surface (quadtree) nodes.
    pub s_nodes: u64,
    /// Leaves, i.e. clusters.
    pub clusters: u64,
    /// Mean number of samples per cluster.
    pub cluster_size_mean: f64,
    /// Variance of the number of samples per cluster.
    pub cluster_size_variance: f64,
    /// Seconds taking the samples.
    pub seconds_samples: f64,
    /// Seconds building the tree.
    pub seconds_tree: f64,
    /// Seconds clustering and re-indexing triangles.
    pub seconds_cluster: f64,
    /// Seconds in the whole library call, from parameter check to result.
    pub seconds_total: f64,
    /// 1 when the topology was kept (see vstree_keep_topology), else 0. Since 0.2.0.
    pub kept_topology: u32,
    /// The `target_faces` asked for (0: the error bound was used). Since 0.2.0.
    pub target_faces: u32,
}

/// Fills the tree part of a stats struct.
pub(crate) fn tree_figures(s: &TreeStats) -> [u64; 6] {
    [s.samples, s.nodes, s.v_nodes, s.t_nodes, s.s_nodes, s.leaves].map(|n| n as u64)
}

/// The output of vstree_simplify(): the simplified mesh and what was done. Opaque; freed with
/// vstree_simplify_result_free(), which frees the mesh it holds too. Immutable: several
/// threads may read it at once.
pub struct vstree_simplify_result {
    mesh: vstree_mesh,
    stats: vstree_simplify_stats,
}

/// Simplifies `mesh` (a triangle mesh, or a point cloud with normals) by clustering its
/// samples in the tree `params` describes (NULL: defaults): every cluster becomes one vertex,
/// triangles are re-indexed to them, and those that collapse or repeat are dropped. A point
/// cloud gives one point with a normal per cluster. A result that keeps nothing of the shape
/// fails with VSTREE_STATUS_INVALID_PARAMETER naming the parameter that made the tree that
/// coarse (`error`, `max_depth` or `min_cell_size`): a mesh whose every triangle collapses, or a
/// cloud whose every point collapses into one (a flat cloud, 3 points among them, is within any
/// L2 or L2,1 bound of one plane: the density metric splits it).
///
/// `progress` (may be NULL) is called with `user_data` from the calling thread as the work
/// goes; returning 0 from it cancels. On success the new result is written to `*out_result`
/// and belongs to the caller, who frees it with vstree_simplify_result_free(); the caller keeps
/// ownership of `mesh`. On failure nothing is written and nothing is left allocated.
///
/// Fails with VSTREE_STATUS_NULL_POINTER, VSTREE_STATUS_INVALID_ARGUMENT (bad
/// `params->struct_size`), VSTREE_STATUS_INVALID_PARAMETER, VSTREE_STATUS_INVALID_INPUT (e.g.
/// only degenerate triangles, a cloud without normals), VSTREE_STATUS_TOO_LARGE or
/// VSTREE_STATUS_CANCELLED. Thread-safe: calls on different meshes, or on the same mesh, may
/// run at once from different threads.
#[no_mangle]
pub unsafe extern "C" fn vstree_simplify(
    mesh: *const vstree_mesh,
    params: *const vstree_simplify_params,
    progress: vstree_progress_fn,
    user_data: *mut c_void,
    out_result: *mut *mut vstree_simplify_result,
) -> vstree_status {
    guard("vstree_simplify", || {
        let start = Instant::now();
        non_null(out_result, "out_result")?;
        let mesh = unsafe { mesh_ref(mesh, "mesh") }?;
        let params = unsafe { read_params(params) }?;
        let (out, s) = with_progress(progress, user_data, |p| simplify(mesh, &params, p))?;
        let result = simplify_result(out, &s, &params, start);
        unsafe { write_out(out_result, handle::into_raw(result)) };
        Ok(())
    })
}

/// The result handle of a simplification that started at `start`.
fn simplify_result(out: Mesh, s: &SimplifyStats, params: &SimplifyParams, start: Instant) -> vstree_simplify_result {
    let [samples, nodes, v_nodes, t_nodes, s_nodes, clusters] = tree_figures(&s.tree);
    let stats = vstree_simplify_stats {
        struct_size: std::mem::size_of::<vstree_simplify_stats>() as u32,
        max_depth: s.tree.max_depth,
        t_depth_min: s.tree.t_depth_min,
        t_depth_max: s.tree.t_depth_max,
        input_vertices: s.input_vertices as u64,
        input_triangles: s.input_triangles as u64,
        output_vertices: s.output_vertices as u64,
        output_triangles: s.output_triangles as u64,
        samples,
        nodes,
        v_nodes,
        t_nodes,
        s_nodes,
        clusters,
        cluster_size_mean: s.tree.leaf_size_mean,
        cluster_size_variance: s.tree.leaf_size_variance,
        seconds_samples: s.seconds_samples,
        seconds_tree: s.seconds_tree,
        seconds_cluster: s.seconds_cluster,
        seconds_total: start.elapsed().as_secs_f64(),
        kept_topology: u32::from(s.kept_topology),
        target_faces: params.target_faces as u32,
    };
    vstree_simplify_result { mesh: vstree_mesh { mesh: out }, stats }
}

/// Simplifies the PLY file at `path` (NUL-terminated) to `params->target_faces` triangles
/// without holding it in memory, for meshes larger than memory: the file is read three times,
/// front to back, a few MiB at a time; memory follows the output's size, plus 4 bytes per input
/// vertex. The tree is built from a sample of the triangles (face centres, whatever
/// `params->sampling` says), and the clustering is plain: the topology is not kept (sheets
/// closer than a cluster may fuse), so `params->keep_topology` must be VSTREE_KEEP_TOPOLOGY_AUTO
/// or VSTREE_KEEP_TOPOLOGY_OFF. The result is as from vstree_simplify(); save its mesh with
/// vstree_mesh_save(). Since 0.9.0.
///
/// Fails as vstree_simplify() does and as vstree_mesh_load() does on the file, and with
/// VSTREE_STATUS_INVALID_PARAMETER for no target (`target_faces` 0), a target above the
/// file's triangles or VSTREE_KEEP_TOPOLOGY_ON, VSTREE_STATUS_INVALID_INPUT for a file that is
/// not PLY or whose faces come before its vertices, and VSTREE_STATUS_TOO_LARGE when the
/// memory it needs is not there. Thread-safe.
#[no_mangle]
pub unsafe extern "C" fn vstree_simplify_ply_file(
    path: *const c_char,
    params: *const vstree_simplify_params,
    progress: vstree_progress_fn,
    user_data: *mut c_void,
    out_result: *mut *mut vstree_simplify_result,
) -> vstree_status {
    guard("vstree_simplify_ply_file", || {
        let start = Instant::now();
        non_null(out_result, "out_result")?;
        let path = unsafe { path_arg(path, "path") }?;
        let params = unsafe { read_params(params) }?;
        let (out, s) = with_progress(progress, user_data, |p| simplify_ply_streaming(&path, &params, p))?;
        let result = simplify_result(out, &s, &params, start);
        unsafe { write_out(out_result, handle::into_raw(result)) };
        Ok(())
    })
}

/// The simplified mesh, owned by `result`: valid until vstree_simplify_result_free(result),
/// and never to be passed to vstree_mesh_free(). Use it with every `const vstree_mesh *`
/// function (counts, copies, vstree_mesh_save(), even vstree_simplify() again). NULL for NULL.
#[no_mangle]
pub unsafe extern "C" fn vstree_simplify_result_get_mesh(result: *const vstree_simplify_result) -> *const vstree_mesh {
    unsafe { handle::part(result, |r| &r.mesh) }
}

/// The statistics of the simplification, owned by `result` (valid until it is freed; do not
/// free it). NULL for NULL.
#[no_mangle]
pub unsafe extern "C" fn vstree_simplify_result_get_stats(
    result: *const vstree_simplify_result,
) -> *const vstree_simplify_stats {
    unsafe { handle::part(result, |r| &r.stats) }
}

/// Frees a result of vstree_simplify() and the mesh and statistics it owns. NULL is a no-op.
#[no_mangle]
pub unsafe extern "C" fn vstree_simplify_result_free(result: *mut vstree_simplify_result) {
    unsafe { handle::free(result) }
}

/// Moves the mesh out of a simplification result into its own handle, for callers that want to
/// keep the mesh and not the statistics: `*out_mesh` gets a new mesh the caller frees with
/// vstree_mesh_free(), and `result` is freed (it must not be used again, whatever the status).
/// Fails with VSTREE_STATUS_NULL_POINTER; when `out_mesh` is NULL the result is left alone.
#[no_mangle]
pub unsafe extern "C" fn vstree_simplify_result_take_mesh(
    result: *mut vstree_simplify_result,
    out_mesh: *mut *mut vstree_mesh,
) -> vstree_status {
    unsafe { handle::take_mesh("vstree_simplify_result_take_mesh", result, out_mesh, |r| r.mesh.mesh) }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::mem::{offset_of, size_of};

    #[test]
    fn params_layout_has_no_padding() {
        assert_eq!(size_of::<vstree_simplify_params>(), 56);
        assert_eq!(offset_of!(vstree_simplify_params, error), 16);
        assert_eq!(offset_of!(vstree_simplify_params, min_cell_size), 40);
        assert_eq!(offset_of!(vstree_simplify_params, keep_topology), 48);
        assert_eq!(offset_of!(vstree_simplify_params, target_faces), 52);
        assert_eq!(size_of::<vstree_simplify_stats>(), 16 + 10 * 8 + 6 * 8 + 8);
    }

    #[test]
    fn short_struct_sizes_keep_defaults_and_bad_ones_are_refused() {
        let mut p = vstree_simplify_params_default();
        p.threads = 2;
        assert_eq!(unsafe { read_params(&p) }.unwrap().threads, 2);
        p.struct_size = 12;
        let e = unsafe { read_params(&p) }.unwrap_err();
        assert_eq!(e.status, vstree_status::InvalidArgument);
        assert!(e.message.contains("params->struct_size"), "{}", e.message);
        p.struct_size = 4096;
        assert!(unsafe { read_params(&p) }.unwrap_err().message.contains("newer vstree.h"));
        // A caller built against 0.1 (48 bytes): whatever lies after its struct, the fields
        // added in 0.2 keep their defaults.
        let mut p = vstree_simplify_params_default();
        (p.struct_size, p.keep_topology, p.target_faces, p.threads) = (48, 99, 7, 3);
        let read = unsafe { read_params(&p) }.unwrap();
        assert_eq!((read.keep_topology, read.target_faces, read.threads), (KeepTopology::Auto, 0, 3));
    }

    #[test]
    fn every_field_is_checked_by_name() {
        type Spoil = fn(&mut vstree_simplify_params);
        let cases: [(&str, Spoil); 10] = [
            ("tree_kind", |p| p.tree_kind = 7),
            ("metric", |p| p.metric = -1),
            ("sampling", |p| p.sampling = 2),
            ("error", |p| p.error = f64::NAN),
            ("d_a", |p| p.d_a = 1.5),
            ("d_d", |p| p.d_d = f32::NAN),
            ("max_depth", |p| p.max_depth = 31),
            ("min_cell_size", |p| p.min_cell_size = 1.0),
            ("threads", |p| p.threads = 5000),
            ("keep_topology", |p| p.keep_topology = 3),
        ];
        for (field, spoil) in cases {
            let mut p = vstree_simplify_params_default();
            spoil(&mut p);
            let e = unsafe { read_params(&p) }.unwrap_err();
            assert_eq!(e.status, vstree_status::InvalidParameter, "{field}");
            assert!(e.message.contains(&format!("`{field}`")), "{}", e.message);
        }
    }
}
