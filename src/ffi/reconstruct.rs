//! Surface reconstruction from a point cloud: the parameter struct, the call, and its result
//! handle with the output mesh and statistics.

use super::mesh::{mesh_ref, vstree_mesh};
use super::normals::{orientation, orientation_value};
use super::params::{self, constant_field, flag, threads, Versioned};
use super::progress::{vstree_progress_fn, with_progress};
use super::{guard, guard_or, handle, non_null, vstree_status, write_out, FfiResult};
use crate::normals::NormalParams;
use crate::reconstruct::{reconstruct, BaseMesh, Closure, ReconstructParams, ReconstructStats, RefinementStop};
use crate::tree::{Metric, TreeKind, TreeParams};
use std::ffi::{c_char, c_void};
use std::mem::size_of;
use std::time::Instant;

/// Parameters of vstree_reconstruct(). Always start from vstree_reconstruct_params_default()
/// and change fields by name: it sets `struct_size`, and fields added in later versions then
/// keep their defaults. Passing NULL means the defaults. The struct has no padding; every field
/// is checked, and an out-of-range one fails the call with VSTREE_STATUS_INVALID_PARAMETER and
/// a message naming it.
///
/// The tree is always a Volume-Surface Tree with the quadric (L2) metric; its fields are those
/// of ::vstree_simplify_params with other defaults. The normal-estimation fields are those of
/// ::vstree_normal_params; `threads` applies to the whole call.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct vstree_reconstruct_params {
    /// Size of this struct in bytes as the caller knows it; set by the _default() function.
    pub struct_size: u32,
    /// How estimated normals get their signs (VSTREE_ORIENTATION_* value); used only where the
    /// cloud has no normals, or for all of them with `reorient_given`. Default
    /// VSTREE_ORIENTATION_PROPAGATE_OUTWARD (reconstruction needs outward normals).
    pub orient: i32,
    /// The tree's L2 bound: squared distance from a cluster's point to its samples' tangent
    /// planes, over the squared bounding-box diagonal. The de-noising control (larger =
    /// smoother, fewer details). Finite and > 0; default 1e-5.
    pub error: f64,
    /// Height-field test, normal cone (see ::vstree_simplify_params). Unitless, in [0, 1)
    /// (at 1 no cell becomes a T-node); default 0. Raising it makes the base mesh denser where curvature is high.
    pub d_a: f32,
    /// Height-field test, displacement (see ::vstree_simplify_params). Unitless, in (0, 1]
    /// (at 0 no cell becomes a T-node); default 1/6.
    pub d_d: f32,
    /// Deepest tree level, in [1, 30]; default 24.
    pub max_depth: u32,
    /// Most refinement levels, each multiplying the triangle count by 4; in [0, 12], default 6.
    pub max_levels: u32,
    /// Cells smaller than this fraction of the bounding-box diagonal are not split. In [0, 1);
    /// default 1e-7.
    pub min_cell_size: f64,
    /// Refinement stops once the RMS distance from the samples to the mesh, over the
    /// bounding-box diagonal, is at most this, and each level splits only the regions whose
    /// samples are farther than this from them (an adaptive mesh). Finite, >= 0; default 0
    /// (refine everywhere until the quadtrees have no detail left or `max_levels`).
    pub target_distance: f64,
    /// A level that displaces fewer than this fraction of its new vertices ends refinement.
    /// Unitless, in [0, 1]; default 0.02.
    pub min_displaced: f64,
    /// No refinement level is started that would exceed this many triangles. In [1, 2^32 - 1];
    /// default 20,000,000.
    pub max_triangles: u32,
    /// The polygonisation grid is never finer than 2^`max_grid_depth` cells across the cloud's
    /// bounding cube. In [4, 20]; default 10.
    pub max_grid_depth: u32,
    /// Faces farther than this many grid cells from every sample are removed (open scans give
    /// open meshes). Finite, >= 0; default 0 (keep the closed surface).
    pub trim: f32,
    /// Neighbours per point for normal estimation, in [3, 256]; default 16.
    pub neighbours: u32,
    /// 0 (default): normals the cloud has are kept. 1: they are re-oriented with `orient`.
    pub reorient_given: u32,
    /// Worker threads: 0 = all cores (default), else at most 1024. Results do not depend on it.
    pub threads: u32,
    /// Open or closed output, a VSTREE_CLOSURE_* value. Default VSTREE_CLOSURE_AUTO (since
    /// 0.3.0; VSTREE_CLOSURE_CLOSED before): a scan from one side comes out open, a closed
    /// object closed. Since 0.2.0.
    pub closure: i32,
    /// What decides the base mesh's inside and outside, and how it is polygonised, a
    /// VSTREE_BASE_MESH_* value. Default VSTREE_BASE_MESH_ADAPTIVE (since 0.7.0;
    /// VSTREE_BASE_MESH_WINDING before); VSTREE_BASE_MESH_PAPER is the paper's construction, to
    /// compare with. Since 0.2.0.
    pub base_mesh: i32,
}

/// `base_mesh` value: the points' winding number says inside or outside, the distance to the
/// nearest point how far, polygonised on a grid as fine as the smallest T-node (the default
/// before 0.7.0).
pub const VSTREE_BASE_MESH_WINDING: i32 = 0;
/// `base_mesh` value: the paper's blend of the T-nodes' planes near the points.
pub const VSTREE_BASE_MESH_PAPER: i32 = 1;
/// `base_mesh` value: the winding number's side, polygonised over the tree's octree with each
/// region at its own T-node's size instead of on a grid as fine as the smallest; an open output
/// is still made on the grid. The default since 0.7.0. Since 0.6.0.
pub const VSTREE_BASE_MESH_ADAPTIVE: i32 = 2;

/// `closure` value: open when more than 30% of the closed surface is unsupported by the points
/// (far from all, or near only points facing the other way; a scan from one side leaves about
/// half), else closed. The default since 0.3.0.
pub const VSTREE_CLOSURE_AUTO: i32 = 0;
/// `closure` value: always the closed surface, holes and the back of an open scan closed over.
pub const VSTREE_CLOSURE_CLOSED: i32 = 1;
/// `closure` value: only the part of the surface the points support (open where they end).
pub const VSTREE_CLOSURE_OPEN: i32 = 2;

/// Reads a `closure` field.
fn closure(value: i32) -> FfiResult<Closure> {
    constant_field(
        "closure",
        value,
        &[
            (VSTREE_CLOSURE_AUTO, "VSTREE_CLOSURE_AUTO", Closure::Auto),
            (VSTREE_CLOSURE_CLOSED, "VSTREE_CLOSURE_CLOSED", Closure::Closed),
            (VSTREE_CLOSURE_OPEN, "VSTREE_CLOSURE_OPEN", Closure::Open),
        ],
    )
}

/// Reads a `base_mesh` field.
fn base_mesh(value: i32) -> FfiResult<BaseMesh> {
    constant_field(
        "base_mesh",
        value,
        &[
            (VSTREE_BASE_MESH_WINDING, "VSTREE_BASE_MESH_WINDING", BaseMesh::Winding),
            (VSTREE_BASE_MESH_PAPER, "VSTREE_BASE_MESH_PAPER", BaseMesh::Paper),
            (VSTREE_BASE_MESH_ADAPTIVE, "VSTREE_BASE_MESH_ADAPTIVE", BaseMesh::Adaptive),
        ],
    )
}

/// The C value of a base mesh.
fn base_mesh_value(base_mesh: BaseMesh) -> i32 {
    match base_mesh {
        BaseMesh::Winding => VSTREE_BASE_MESH_WINDING,
        BaseMesh::Paper => VSTREE_BASE_MESH_PAPER,
        BaseMesh::Adaptive => VSTREE_BASE_MESH_ADAPTIVE,
    }
}

/// The C value of a closure.
fn closure_value(closure: Closure) -> i32 {
    match closure {
        Closure::Auto => VSTREE_CLOSURE_AUTO,
        Closure::Closed => VSTREE_CLOSURE_CLOSED,
        Closure::Open => VSTREE_CLOSURE_OPEN,
    }
}

unsafe impl Versioned for vstree_reconstruct_params {
    const NAME: &'static str = "vstree_reconstruct_params";
    const MIN_SIZE: usize = 80;
    fn defaults() -> Self {
        let d = ReconstructParams::default();
        vstree_reconstruct_params {
            struct_size: size_of::<Self>() as u32,
            orient: orientation_value(d.normals.orient),
            error: d.tree.error,
            d_a: d.tree.d_a,
            d_d: d.tree.d_d,
            max_depth: d.tree.max_depth,
            max_levels: d.max_levels,
            min_cell_size: d.tree.min_cell_size,
            target_distance: d.target_distance,
            min_displaced: d.min_displaced,
            max_triangles: u32::try_from(d.max_triangles).unwrap_or(u32::MAX),
            max_grid_depth: d.max_grid_depth,
            trim: d.trim,
            neighbours: d.normals.neighbours as u32,
            reorient_given: u32::from(d.normals.reorient_given),
            threads: 0,
            closure: closure_value(d.closure),
            base_mesh: base_mesh_value(d.base_mesh),
        }
    }
}

/// The default parameters, with `struct_size` set. Thread-safe; returns a value (nothing to
/// free).
#[no_mangle]
pub extern "C" fn vstree_reconstruct_params_default() -> vstree_reconstruct_params {
    vstree_reconstruct_params::defaults()
}

/// Reads and checks the caller's parameters (NULL: defaults), naming any bad field.
pub(crate) unsafe fn read_reconstruct_params(
    pointer: *const vstree_reconstruct_params,
) -> FfiResult<ReconstructParams> {
    let p = unsafe { params::read(pointer, "params") }?;
    let threads = threads(p.threads)?;
    let normals = NormalParams {
        neighbours: p.neighbours as usize,
        orient: orientation(p.orient)?,
        reorient_given: flag("reorient_given", p.reorient_given)?,
        threads,
    };
    normals.check()?;
    let params = ReconstructParams {
        tree: TreeParams {
            kind: TreeKind::VsTree,
            metric: Metric::L2,
            error: p.error,
            d_a: p.d_a,
            d_d: p.d_d,
            max_depth: p.max_depth,
            min_cell_size: p.min_cell_size,
        },
        target_distance: p.target_distance,
        max_levels: p.max_levels,
        min_displaced: p.min_displaced,
        max_triangles: p.max_triangles as usize,
        max_grid_depth: p.max_grid_depth,
        trim: p.trim,
        closure: closure(p.closure)?,
        base_mesh: base_mesh(p.base_mesh)?,
        normals,
        threads,
    };
    params.check()?;
    Ok(params)
}

/// What a reconstruction did. Owned by its result (vstree_reconstruct_result_get_stats());
/// later versions only add fields at the end, and `struct_size` says how many there are.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct vstree_reconstruct_stats {
    /// Size of this struct in bytes as the library filled it.
    pub struct_size: u32,
    /// Cells across the polygonisation grid of the base mesh (a power of two).
    pub grid_cells: u32,
    /// Genus of the base mesh M0, or -1 when M0 is not a closed manifold.
    pub base_genus: i32,
    /// Refinement levels done (each splits every triangle in 4, or with a target distance those
    /// whose samples are farther from them than the target).
    pub levels: u32,
    /// Deepest level of the tree (the root is level 0).
    pub max_depth: u32,
    /// Neighbours per point used for normal estimation (0 when the cloud's normals were kept).
    pub normals_neighbours: u32,
    /// Normals estimated (0 when the cloud's own were all kept).
    pub normals_estimated: u64,
    /// Normals whose sign the orientation changed.
    pub normals_flipped: u64,
    /// Points of the input cloud.
    pub input_points: u64,
    /// Samples the tree was built from: `input_points` less the isolated points left out
    /// (stray points far from the rest for their neighbours' spacing).
    pub samples: u64,
    /// Nodes of the tree, of every kind.
    pub nodes: u64,
    /// Transition nodes: one vertex of the base mesh M0 each, at most.
    pub t_nodes: u64,
    /// Triangles of the fine polygonisation clustered into M0.
    pub fine_triangles: u64,
    /// Vertices of the base mesh M0.
    pub base_vertices: u64,
    /// Triangles of the base mesh M0.
    pub base_triangles: u64,
    /// RMS distance from the samples to M0, over the bounding-box diagonal.
    pub base_error: f64,
    /// RMS distance from the samples to the final mesh (before trimming), over the diagonal.
    pub final_error: f64,
    /// Largest distance from a sample to the final mesh (before trimming), over the diagonal.
    pub final_max_error: f64,
    /// Triangles removed by trimming (0 when `trim` is 0).
    pub trimmed_triangles: u64,
    /// Vertices of the output mesh.
    pub output_vertices: u64,
    /// Triangles of the output mesh.
    pub output_triangles: u64,
    /// Seconds estimating normals (and taking the samples).
    pub seconds_normals: f64,
    /// Seconds building the tree.
    pub seconds_tree: f64,
    /// Seconds making the base mesh M0.
    pub seconds_base: f64,
    /// Seconds refining.
    pub seconds_refine: f64,
    /// Seconds trimming.
    pub seconds_trim: f64,
    /// Seconds in the whole library call, from parameter check to result.
    pub seconds_total: f64,
    /// Why refinement stopped: one of the VSTREE_REFINEMENT_STOPPED_ values. Since 0.1.1.
    pub stopped: u32,
    /// 1 when the base mesh was polygonised with thin parts thickened (the plain
    /// polygonisation had handles and the thickened one fewer), else 0. Since 0.1.1.
    pub thickened: u32,
    /// 1 when the output is open (only the part of the surface the points support), else 0.
    /// Since 0.2.0.
    pub open: u32,
    /// Edges of the base mesh M0 with one face (0 when M0 is closed). Since 0.2.0.
    pub base_boundary_edges: u32,
    /// Share of the closed polygonised surface's area unsupported by the points (far from all,
    /// or near only points facing the other way; about half for a scan from one side); `closure` AUTO makes the output open above 0.3. Since 0.2.0.
    pub unsupported_share: f64,
}

/// `stopped` value: error(M, S) reached `target_distance`.
pub const VSTREE_REFINEMENT_STOPPED_TARGET: u32 = 0;
/// `stopped` value: a level displaced fewer than `min_displaced` of its new vertices (the tree's
/// quadtrees have no detail left).
pub const VSTREE_REFINEMENT_STOPPED_NO_DETAIL: u32 = 1;
/// `stopped` value: `max_levels` levels were done.
pub const VSTREE_REFINEMENT_STOPPED_MAX_LEVELS: u32 = 2;
/// `stopped` value: the next level would have exceeded `max_triangles`; raise it or the target.
pub const VSTREE_REFINEMENT_STOPPED_TRIANGLE_BUDGET: u32 = 3;

/// The refinement stop a `stopped` value means, if it is one.
fn refinement_stop(stopped: u32) -> Option<RefinementStop> {
    RefinementStop::ALL.into_iter().find(|&stop| stopped_value(stop) == stopped)
}

/// The C value of a refinement stop.
fn stopped_value(stop: RefinementStop) -> u32 {
    match stop {
        RefinementStop::Target => VSTREE_REFINEMENT_STOPPED_TARGET,
        RefinementStop::NoDetail => VSTREE_REFINEMENT_STOPPED_NO_DETAIL,
        RefinementStop::MaxLevels => VSTREE_REFINEMENT_STOPPED_MAX_LEVELS,
        RefinementStop::TriangleBudget => VSTREE_REFINEMENT_STOPPED_TRIANGLE_BUDGET,
    }
}

/// The C statistics of a reconstruction of `input_points` points.
pub(crate) fn stats_of(s: &ReconstructStats, input_points: usize, seconds_total: f64) -> vstree_reconstruct_stats {
    vstree_reconstruct_stats {
        struct_size: size_of::<vstree_reconstruct_stats>() as u32,
        grid_cells: s.grid_cells,
        base_genus: s.base_genus.and_then(|g| i32::try_from(g).ok()).unwrap_or(-1),
        levels: s.levels.len() as u32,
        max_depth: s.tree.max_depth,
        normals_neighbours: s.normals.neighbours as u32,
        normals_estimated: s.normals.estimated as u64,
        normals_flipped: s.normals.orient.map_or(0, |o| o.flipped as u64),
        input_points: input_points as u64,
        samples: s.tree.samples as u64,
        nodes: s.tree.nodes as u64,
        t_nodes: s.tree.t_nodes as u64,
        fine_triangles: s.fine_triangles as u64,
        base_vertices: s.base_vertices as u64,
        base_triangles: s.base_triangles as u64,
        base_error: s.base_error,
        final_error: s.final_error,
        final_max_error: s.final_max_error,
        trimmed_triangles: s.trimmed_triangles as u64,
        output_vertices: s.output_vertices as u64,
        output_triangles: s.output_triangles as u64,
        seconds_normals: s.seconds_normals,
        seconds_tree: s.seconds_tree,
        seconds_base: s.seconds_base,
        seconds_refine: s.seconds_refine,
        seconds_trim: s.seconds_trim,
        seconds_total,
        stopped: stopped_value(s.stopped),
        thickened: u32::from(s.thickened),
        open: u32::from(s.open),
        base_boundary_edges: u32::try_from(s.base_boundary_edges).unwrap_or(u32::MAX),
        unsupported_share: s.unsupported_share,
    }
}

/// The output of vstree_reconstruct(): the reconstructed mesh and what was done. Opaque; freed
/// with vstree_reconstruct_result_free(), which frees the mesh it holds too. Immutable: several
/// threads may read it at once.
pub struct vstree_reconstruct_result {
    mesh: vstree_mesh,
    stats: vstree_reconstruct_stats,
}

/// Reconstructs a triangle mesh from the points of `cloud` (its triangles, if any, are
/// ignored): normals are estimated where the cloud has none (all, or zero-length ones), the
/// VS-Tree of the points is built, its T-nodes give a coarse base mesh (closed, or only the
/// part the points support where `params->closure` says so), which is refined
/// by the quadtrees below them until it is close enough to the points; with `params->trim` >
/// 0, faces far from every point are removed at the end. The output has
/// unit per-vertex normals and counter-clockwise triangles seen from outside.
///
/// `params` NULL means the defaults. `progress` (may be NULL) is called with `user_data` from
/// the calling thread as the work goes; returning 0 from it cancels. On success the new result
/// is written to `*out_result` and belongs to the caller, who frees it with
/// vstree_reconstruct_result_free(); the caller keeps ownership of `cloud`, which is not
/// changed. On failure nothing is written and nothing is left allocated.
///
/// Fails with VSTREE_STATUS_NULL_POINTER, VSTREE_STATUS_INVALID_ARGUMENT (bad
/// `params->struct_size`), VSTREE_STATUS_INVALID_PARAMETER, VSTREE_STATUS_INVALID_INPUT (fewer
/// than 10 points, points all on a line, normals so inconsistent that no surface is found),
/// VSTREE_STATUS_TOO_LARGE (the surface needs more grid cells than the library allows) or
/// VSTREE_STATUS_CANCELLED. Thread-safe: calls on different clouds, or on the same cloud, may
/// run at once from different threads.
#[no_mangle]
pub unsafe extern "C" fn vstree_reconstruct(
    cloud: *const vstree_mesh,
    params: *const vstree_reconstruct_params,
    progress: vstree_progress_fn,
    user_data: *mut c_void,
    out_result: *mut *mut vstree_reconstruct_result,
) -> vstree_status {
    guard("vstree_reconstruct", || {
        let start = Instant::now();
        non_null(out_result, "out_result")?;
        let cloud = unsafe { mesh_ref(cloud, "cloud") }?;
        let params = unsafe { read_reconstruct_params(params) }?;
        let (out, s) = with_progress(progress, user_data, |p| reconstruct(cloud, &params, p))?;
        let stats = stats_of(&s, cloud.positions.len(), start.elapsed().as_secs_f64());
        let result = vstree_reconstruct_result { mesh: vstree_mesh { mesh: out }, stats };
        unsafe { write_out(out_result, handle::into_raw(result)) };
        Ok(())
    })
}

/// The reconstructed mesh, owned by `result`: valid until vstree_reconstruct_result_free(result),
/// and never to be passed to vstree_mesh_free(). Use it with every `const vstree_mesh *`
/// function (counts, copies, vstree_mesh_save(), vstree_simplify()). NULL for NULL.
#[no_mangle]
pub unsafe extern "C" fn vstree_reconstruct_result_get_mesh(
    result: *const vstree_reconstruct_result,
) -> *const vstree_mesh {
    unsafe { handle::part(result, |r| &r.mesh) }
}

/// The statistics of the reconstruction, owned by `result` (valid until it is freed; do not
/// free it). NULL for NULL.
#[no_mangle]
pub unsafe extern "C" fn vstree_reconstruct_result_get_stats(
    result: *const vstree_reconstruct_result,
) -> *const vstree_reconstruct_stats {
    unsafe { handle::part(result, |r| &r.stats) }
}

/// Frees a result of vstree_reconstruct() and the mesh and statistics it owns. NULL is a
/// no-op.
#[no_mangle]
pub unsafe extern "C" fn vstree_reconstruct_result_free(result: *mut vstree_reconstruct_result) {
    unsafe { handle::free(result) }
}

/// Moves the mesh out of a reconstruction result into its own handle: `*out_mesh` gets a new
/// mesh the caller frees with vstree_mesh_free(), and `result` is freed (it must not be used
/// again, whatever the status). Fails with VSTREE_STATUS_NULL_POINTER; when `out_mesh` is NULL
/// the result is left alone.
#[no_mangle]
pub unsafe extern "C" fn vstree_reconstruct_result_take_mesh(
    result: *mut vstree_reconstruct_result,
    out_mesh: *mut *mut vstree_mesh,
) -> vstree_status {
    unsafe { handle::take_mesh("vstree_reconstruct_result_take_mesh", result, out_mesh, |r| r.mesh.mesh) }
}

/// The name of a `stopped` value of ::vstree_reconstruct_stats, the end of its
/// VSTREE_REFINEMENT_STOPPED_ constant in lower case: "target", "no_detail", "max_levels" or
/// "triangle_budget"; other numbers give "unknown". A static, NUL-terminated string: never NULL,
/// never to be freed. Thread-safe. Since 0.4.0.
#[no_mangle]
pub extern "C" fn vstree_refinement_stopped_str(stopped: u32) -> *const c_char {
    guard_or(c"unknown".as_ptr(), || refinement_stop(stopped).map_or(c"unknown", RefinementStop::as_c_str).as_ptr())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::mem::offset_of;

    #[test]
    fn layouts_have_no_padding() {
        assert_eq!(offset_of!(vstree_reconstruct_params, error), 8);
        assert_eq!(offset_of!(vstree_reconstruct_params, min_cell_size), 32);
        assert_eq!(offset_of!(vstree_reconstruct_params, max_triangles), 56);
        assert_eq!(offset_of!(vstree_reconstruct_params, threads), 76);
        assert_eq!(size_of::<vstree_reconstruct_stats>(), 24 + 21 * 8 + 8 + 16);
        assert_eq!(offset_of!(vstree_reconstruct_params, closure), 80);
        assert_eq!(size_of::<vstree_reconstruct_params>(), 88);
        assert_eq!(offset_of!(vstree_reconstruct_stats, stopped), 24 + 21 * 8);
        assert_eq!(offset_of!(vstree_reconstruct_stats, unsupported_share), 24 + 21 * 8 + 16);
    }

    #[test]
    fn defaults_are_the_rust_defaults() {
        let p = unsafe { read_reconstruct_params(std::ptr::null()) }.unwrap();
        assert_eq!(p, ReconstructParams::default());
        let q = unsafe { read_reconstruct_params(&vstree_reconstruct_params_default()) }.unwrap();
        assert_eq!(q, ReconstructParams::default());
    }

    #[test]
    fn every_field_is_checked_by_name() {
        type Spoil = fn(&mut vstree_reconstruct_params);
        let cases: [(&str, Spoil); 19] = [
            ("orient", |p| p.orient = 4),
            ("error", |p| p.error = 0.0),
            ("error", |p| p.error = f64::NAN),
            ("d_a", |p| p.d_a = 1.5),
            ("d_d", |p| p.d_d = f32::NAN),
            ("max_depth", |p| p.max_depth = 0),
            ("max_levels", |p| p.max_levels = 13),
            ("min_cell_size", |p| p.min_cell_size = 1.0),
            ("target_distance", |p| p.target_distance = -1.0),
            ("target_distance", |p| p.target_distance = f64::INFINITY),
            ("min_displaced", |p| p.min_displaced = f64::NAN),
            ("max_triangles", |p| p.max_triangles = 0),
            ("max_grid_depth", |p| p.max_grid_depth = 21),
            ("trim", |p| p.trim = -1.0),
            ("neighbours", |p| p.neighbours = 1000),
            ("reorient_given", |p| p.reorient_given = 7),
            ("threads", |p| p.threads = u32::MAX),
            ("closure", |p| p.closure = 3),
            ("base_mesh", |p| p.base_mesh = 3),
        ];
        for (field, spoil) in cases {
            let mut p = vstree_reconstruct_params_default();
            spoil(&mut p);
            let e = unsafe { read_reconstruct_params(&p) }.unwrap_err();
            assert_eq!(e.status, vstree_status::InvalidParameter, "{field}");
            assert!(e.message.contains(&format!("`{field}`")), "{}", e.message);
        }
    }
}
