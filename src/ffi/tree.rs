//! The tree handle, for applications that show the structure: statistics, node counts per
//! level and kind, every node, the T-layer with its local frames, and per-vertex labels (the
//! cluster or T-node each input vertex belongs to) to colour the mesh by.

use super::arrays::copy_out;
use super::mesh::{mesh_ref, vstree_mesh};
use super::params::{c_enum, CEnum};
use super::progress::{vstree_progress_fn, with_progress};
use super::simplify::{read_params, tree_figures, vstree_simplify_params};
use super::{guard, guard_or, handle, non_null, vstree_status, write_out, Failure, FfiResult};
use crate::mesh::Mesh;
use crate::progress::{Progress, Threads};
use crate::simplify::{cluster_mesh, vertex_labels, Clustered, SimplifyParams, NO_CLUSTER};
use crate::tree::NodeKind;
use std::ffi::c_void;
use std::time::Instant;

/// Marks "none" in index fields and labels: a vertex no cluster holds (used by no triangle),
/// a vertex whose cluster is not below a T-node, a node that is not a leaf or has no T-node.
pub const VSTREE_NO_INDEX: u32 = u32::MAX;

/// The kind of a node (the `kind` field of vstree_node).
#[repr(i32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum vstree_node_kind {
    /// An octree cell: a cube, with up to 8 V- or T-node children.
    Volume = 0,
    /// A T-node: an octree cell where the surface is a height field; it carries a local frame
    /// and roots a quadtree of S-nodes in that frame's plane.
    Transition = 1,
    /// A quadtree cell: a square in its T-node's plane, with up to 4 S-node children.
    Surface = 2,
}
c_enum!(vstree_node_kind {
    Volume = "VSTREE_NODE_KIND_VOLUME",
    Transition = "VSTREE_NODE_KIND_TRANSITION",
    Surface = "VSTREE_NODE_KIND_SURFACE",
});

/// The C kind of a node.
fn node_kind(kind: NodeKind) -> vstree_node_kind {
    match kind {
        NodeKind::Volume => vstree_node_kind::Volume,
        NodeKind::Transition => vstree_node_kind::Transition,
        NodeKind::Surface => vstree_node_kind::Surface,
    }
}

/// What vstree_tree_copy_vertex_labels() gives per input vertex.
#[repr(i32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum vstree_label_kind {
    /// The vertex's cluster, 0 to clusters - 1 (the leaves in node order), or VSTREE_NO_INDEX.
    Cluster = 0,
    /// The index in the T-layer (vstree_tree_copy_t_nodes()) of the T-node above the vertex's
    /// cluster, or VSTREE_NO_INDEX when the cluster is an octree leaf or there is none.
    TNode = 1,
}
c_enum!(vstree_label_kind { Cluster = "VSTREE_LABEL_KIND_CLUSTER", TNode = "VSTREE_LABEL_KIND_T_NODE" });

/// One node of the tree, as vstree_tree_copy_nodes() gives them: node 0 is the root, and a
/// node's children are contiguous.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct vstree_node {
    /// Index of the parent node (the root is its own parent).
    pub parent: u32,
    /// Index of the first child; the children are first_child to first_child + child_count - 1.
    pub first_child: u32,
    /// Number of children: 0 for a leaf, else 1 to 8 (V-node) or 1 to 4 (T-, S-node); empty
    /// cells get no node.
    pub child_count: u32,
    /// A vstree_node_kind value.
    pub kind: i32,
    /// Level: the root is 0.
    pub depth: u32,
    /// Number of samples in the cell.
    pub sample_count: u32,
    /// For T- and S-nodes, the index in the T-layer (vstree_tree_copy_t_nodes()) of the T-node
    /// whose frame the cell lives in; VSTREE_NO_INDEX for V-nodes.
    pub t_node: u32,
    /// For leaves, the cluster index (as in the labels); VSTREE_NO_INDEX for inner nodes.
    pub cluster: u32,
    /// V- and T-nodes: the cube's centre (x, y, z). S-nodes: the square's centre (u, v, 0) in
    /// the plane coordinates of its T-node's frame.
    pub center: [f32; 3],
    /// Half the side of the cube or square, in the mesh's units.
    pub half: f32,
}

/// A T-node with its local frame: what a viewer needs to draw the T-layer (the cube, and the
/// tangent square its quadtree subdivides). The 3D point at plane coordinates (a, b) is
/// origin + a·u + b·v.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct vstree_t_node {
    /// Index of the node in vstree_tree_copy_nodes().
    pub node: u32,
    /// Level of the node (the root is 0).
    pub depth: u32,
    /// Samples in the cell.
    pub sample_count: u32,
    /// Clusters (leaves) in its quadtree; 1 when the T-node is itself a leaf.
    pub cluster_count: u32,
    /// Centre of the octree cube.
    pub cube_center: [f32; 3],
    /// Half the side of the cube.
    pub cube_half: f32,
    /// Frame origin: the centroid of the samples.
    pub origin: [f32; 3],
    /// Unit normal of the tangent plane (the samples' mean normal).
    pub normal: [f32; 3],
    /// First unit axis of the plane.
    pub u: [f32; 3],
    /// Second unit axis of the plane (normal × u).
    pub v: [f32; 3],
    /// Centre (u, v) of the square that bounds the samples' projections: the quadtree's root.
    pub square_center: [f32; 2],
    /// Half the side of that square.
    pub square_half: f32,
}

/// Node counts of one level of the tree (vstree_tree_copy_levels()).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct vstree_tree_level {
    /// Volume (octree) nodes on this level.
    pub v_nodes: u64,
    /// T-nodes on this level.
    pub t_nodes: u64,
    /// Surface (quadtree) nodes on this level.
    pub s_nodes: u64,
    /// Leaves (clusters) on this level, of any kind.
    pub leaves: u64,
}

/// Figures that describe a tree (vstree_tree_get_stats()). Later versions only add fields at
/// the end; `struct_size` says how many there are.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct vstree_tree_stats {
    /// Size of this struct in bytes as the library filled it.
    pub struct_size: u32,
    /// Deepest level (the root is 0); there are max_depth + 1 levels.
    pub max_depth: u32,
    /// Shallowest level holding a T-node (0 when there is none).
    pub t_depth_min: u32,
    /// Deepest level holding a T-node (0 when there is none).
    pub t_depth_max: u32,
    /// Samples the tree was built from.
    pub samples: u64,
    /// Nodes of every kind.
    pub nodes: u64,
    /// Volume (octree) nodes.
    pub v_nodes: u64,
    /// T-nodes: the T-layer.
    pub t_nodes: u64,
    /// Surface (quadtree) nodes.
    pub s_nodes: u64,
    /// Leaves, i.e. clusters.
    pub clusters: u64,
    /// Vertices (points) of the mesh the tree was built from: the length of the labels.
    pub vertices: u64,
    /// Mean number of samples per cluster.
    pub cluster_size_mean: f64,
    /// Variance of the number of samples per cluster.
    pub cluster_size_variance: f64,
    /// The final error: the largest per-cluster error under the tree's metric, in the units of
    /// the `error` parameter (L2: relative to the squared bounding-box diagonal; L2,1:
    /// unitless; density: samples). At most `error` unless max_depth or min_cell_size stopped
    /// a split.
    pub max_cluster_error: f64,
    /// The mean per-cluster error, same units.
    pub mean_cluster_error: f64,
    /// Diagonal of the samples' bounding box, in the mesh's units: the unit of relative values.
    pub diagonal: f64,
    /// Seconds taking the samples.
    pub seconds_samples: f64,
    /// Seconds building the tree.
    pub seconds_tree: f64,
    /// Seconds in the whole call.
    pub seconds_total: f64,
}

/// A built tree with everything the accessors copy out, computed once. Opaque: made by
/// vstree_tree_build(), freed with vstree_tree_free(). Immutable: several threads may read it
/// at once.
pub struct vstree_tree {
    stats: vstree_tree_stats,
    nodes: Vec<vstree_node>,
    t_nodes: Vec<vstree_t_node>,
    levels: Vec<vstree_tree_level>,
    cluster_labels: Vec<u32>,
    t_node_labels: Vec<u32>,
}

/// Builds the tree vstree_simplify() with the same `mesh` and `params` (NULL: defaults) would
/// cluster with, and labels the mesh's vertices with it. `progress` (may be NULL) is called
/// with `user_data` from the calling thread; returning 0 from it cancels. On success the new
/// tree is written to `*out_tree` and belongs to the caller, who frees it with
/// vstree_tree_free(); the caller keeps ownership of `mesh`. On failure nothing is written
/// and nothing is left allocated.
///
/// Fails like vstree_simplify(). Thread-safe, like vstree_simplify().
#[no_mangle]
pub unsafe extern "C" fn vstree_tree_build(
    mesh: *const vstree_mesh,
    params: *const vstree_simplify_params,
    progress: vstree_progress_fn,
    user_data: *mut c_void,
    out_tree: *mut *mut vstree_tree,
) -> vstree_status {
    guard("vstree_tree_build", || {
        let start = Instant::now();
        non_null(out_tree, "out_tree")?;
        let mesh = unsafe { mesh_ref(mesh, "mesh") }?;
        let params = unsafe { read_params(params) }?;
        let mut tree = with_progress(progress, user_data, |p| build(mesh, &params, p))?;
        tree.stats.seconds_total = start.elapsed().as_secs_f64();
        unsafe { write_out(out_tree, handle::into_raw(tree)) };
        Ok(())
    })
}

/// The same steps as the library's simplification up to the clusters, keeping the tree.
fn build(mesh: &Mesh, params: &SimplifyParams, progress: &mut Progress) -> FfiResult<vstree_tree> {
    let threads = Threads::new(params.threads)?;
    let Clustered { samples, tree, clusters, seconds_samples, seconds_tree, .. } =
        cluster_mesh(mesh, params, &threads, progress)?;
    let sampling = match mesh.is_point_cloud() {
        true => crate::MeshSampling::Vertices, // a cloud's samples are its points
        false => params.sampling,
    };
    let cluster_labels = vertex_labels(mesh, &samples, &clusters, sampling, &tree);
    progress.report(0.9, "describing tree")?;

    // The T-layer, in node order, and where each node's frame (T-node) is in it.
    let t_indices: Vec<usize> = (0..tree.nodes.len()).filter(|&i| tree.nodes[i].kind == NodeKind::Transition).collect();
    let mut frame_to_t = vec![VSTREE_NO_INDEX; tree.frames.len()];
    for (k, &i) in t_indices.iter().enumerate() {
        if let Some(slot) = frame_to_t.get_mut(tree.nodes[i].frame as usize) {
            *slot = k as u32;
        }
    }
    let t_of = |i: usize| match tree.nodes[i].kind {
        NodeKind::Volume => VSTREE_NO_INDEX,
        _ => frame_to_t.get(tree.nodes[i].frame as usize).copied().unwrap_or(VSTREE_NO_INDEX),
    };
    // The tree is built on positions relative to the mesh's origin; callers see absolute ones.
    let absolute = |p: glam::Vec3| (mesh.origin + p.as_dvec3()).as_vec3().to_array();
    let mut node_cluster = vec![VSTREE_NO_INDEX; tree.nodes.len()];
    for (k, &leaf) in clusters.leaves.iter().enumerate() {
        node_cluster[leaf as usize] = k as u32;
    }
    let nodes: Vec<vstree_node> = tree
        .nodes
        .iter()
        .enumerate()
        .map(|(i, n)| vstree_node {
            parent: n.parent,
            first_child: n.first_child,
            child_count: n.child_count.into(),
            kind: node_kind(n.kind).raw(),
            depth: n.depth.into(),
            sample_count: n.count,
            t_node: t_of(i),
            cluster: node_cluster[i],
            center: absolute(n.center),
            half: n.half,
        })
        .collect();
    let mut t_clusters = vec![0u32; t_indices.len()];
    for &leaf in &clusters.leaves {
        let t = t_of(leaf as usize);
        if let Some(count) = t_clusters.get_mut(t as usize) {
            *count += 1;
        }
    }
    let t_nodes: Vec<vstree_t_node> = t_indices
        .iter()
        .zip(&t_clusters)
        .map(|(&i, &cluster_count)| {
            let n = &tree.nodes[i];
            let f = &tree.frames[n.frame as usize];
            vstree_t_node {
                node: i as u32,
                depth: n.depth.into(),
                sample_count: n.count,
                cluster_count,
                cube_center: absolute(n.center),
                cube_half: n.half,
                origin: absolute(f.origin),
                normal: f.normal.to_array(),
                u: f.u.to_array(),
                v: f.v.to_array(),
                square_center: f.square_center.to_array(),
                square_half: f.square_half,
            }
        })
        .collect();
    let t_node_labels: Vec<u32> = cluster_labels
        .iter()
        .map(|&c| match c {
            NO_CLUSTER => VSTREE_NO_INDEX,
            c => clusters.leaves.get(c as usize).map_or(VSTREE_NO_INDEX, |&leaf| t_of(leaf as usize)),
        })
        .collect();
    let s = tree.stats();
    let mut levels = vec![vstree_tree_level::default(); s.max_depth as usize + 1];
    for n in &tree.nodes {
        let level = &mut levels[n.depth as usize];
        match n.kind {
            NodeKind::Volume => level.v_nodes += 1,
            NodeKind::Transition => level.t_nodes += 1,
            NodeKind::Surface => level.s_nodes += 1,
        }
        level.leaves += u64::from(n.is_leaf());
    }
    let errors = threads.run(|| tree.node_errors(&clusters.leaves));
    let max_error = errors.iter().copied().fold(0.0, f64::max);
    let mean_error = errors.iter().sum::<f64>() / errors.len().max(1) as f64;
    progress.report(1.0, "done")?;

    let [samples_n, nodes_n, v_nodes, t_nodes_n, s_nodes, clusters_n] = tree_figures(&s);
    let stats = vstree_tree_stats {
        struct_size: std::mem::size_of::<vstree_tree_stats>() as u32,
        max_depth: s.max_depth,
        t_depth_min: s.t_depth_min,
        t_depth_max: s.t_depth_max,
        samples: samples_n,
        nodes: nodes_n,
        v_nodes,
        t_nodes: t_nodes_n,
        s_nodes,
        clusters: clusters_n,
        vertices: mesh.positions.len() as u64,
        cluster_size_mean: s.leaf_size_mean,
        cluster_size_variance: s.leaf_size_variance,
        max_cluster_error: max_error,
        mean_cluster_error: mean_error,
        diagonal: f64::from(tree.diagonal),
        seconds_samples,
        seconds_tree,
        seconds_total: 0.0,
    };
    Ok(vstree_tree { stats, nodes, t_nodes, levels, cluster_labels, t_node_labels })
}

/// Frees a tree made by vstree_tree_build(). NULL is a no-op.
#[no_mangle]
pub unsafe extern "C" fn vstree_tree_free(tree: *mut vstree_tree) {
    unsafe { handle::free(tree) }
}

/// The tree's statistics, owned by `tree` (valid until it is freed; do not free it). NULL for
/// NULL. Thread-safe.
#[no_mangle]
pub unsafe extern "C" fn vstree_tree_get_stats(tree: *const vstree_tree) -> *const vstree_tree_stats {
    unsafe { handle::part(tree, |t| &t.stats) }
}

/// Number of nodes (the length vstree_tree_copy_nodes() needs); 0 for NULL. Thread-safe.
#[no_mangle]
pub unsafe extern "C" fn vstree_tree_node_count(tree: *const vstree_tree) -> usize {
    guard_or(0, || unsafe { handle::borrow_opt(tree) }.map_or(0, |t| t.nodes.len()))
}

/// Number of T-nodes (the length vstree_tree_copy_t_nodes() needs); 0 for NULL. Thread-safe.
#[no_mangle]
pub unsafe extern "C" fn vstree_tree_t_node_count(tree: *const vstree_tree) -> usize {
    guard_or(0, || unsafe { handle::borrow_opt(tree) }.map_or(0, |t| t.t_nodes.len()))
}

/// Number of levels, max_depth + 1 (the length vstree_tree_copy_levels() needs); 0 for NULL.
/// Thread-safe.
#[no_mangle]
pub unsafe extern "C" fn vstree_tree_level_count(tree: *const vstree_tree) -> usize {
    guard_or(0, || unsafe { handle::borrow_opt(tree) }.map_or(0, |t| t.levels.len()))
}

/// Number of labels: the vertex (point) count of the mesh the tree was built from (the length
/// vstree_tree_copy_vertex_labels() needs); 0 for NULL. Thread-safe.
#[no_mangle]
pub unsafe extern "C" fn vstree_tree_vertex_count(tree: *const vstree_tree) -> usize {
    guard_or(0, || unsafe { handle::borrow_opt(tree) }.map_or(0, |t| t.cluster_labels.len()))
}

/// Copies every node into the caller's array `out` of `capacity` elements, which must be at
/// least vstree_tree_node_count(). The caller owns `out`.
///
/// Fails with VSTREE_STATUS_NULL_POINTER, VSTREE_STATUS_INVALID_ARGUMENT (misaligned `out`) or
/// VSTREE_STATUS_BUFFER_TOO_SMALL (nothing written). Thread-safe.
#[no_mangle]
pub unsafe extern "C" fn vstree_tree_copy_nodes(
    tree: *const vstree_tree,
    out: *mut vstree_node,
    capacity: usize,
) -> vstree_status {
    guard("vstree_tree_copy_nodes", || {
        let tree = unsafe { handle::borrow(tree, "tree") }?;
        unsafe { copy_out(&tree.nodes, out, capacity, "out") }
    })
}

/// Copies the T-layer (every T-node, in node order, with its frame) into the caller's array
/// `out` of `capacity` elements, at least vstree_tree_t_node_count(). The caller owns `out`.
/// An octree (VSTREE_TREE_KIND_OCTREE) has no T-nodes: nothing is copied.
///
/// Fails like vstree_tree_copy_nodes(). Thread-safe.
#[no_mangle]
pub unsafe extern "C" fn vstree_tree_copy_t_nodes(
    tree: *const vstree_tree,
    out: *mut vstree_t_node,
    capacity: usize,
) -> vstree_status {
    guard("vstree_tree_copy_t_nodes", || {
        let tree = unsafe { handle::borrow(tree, "tree") }?;
        unsafe { copy_out(&tree.t_nodes, out, capacity, "out") }
    })
}

/// Copies the node counts of every level, root level first, into the caller's array `out` of
/// `capacity` elements, at least vstree_tree_level_count(). The caller owns `out`.
///
/// Fails like vstree_tree_copy_nodes(). Thread-safe.
#[no_mangle]
pub unsafe extern "C" fn vstree_tree_copy_levels(
    tree: *const vstree_tree,
    out: *mut vstree_tree_level,
    capacity: usize,
) -> vstree_status {
    guard("vstree_tree_copy_levels", || {
        let tree = unsafe { handle::borrow(tree, "tree") }?;
        unsafe { copy_out(&tree.levels, out, capacity, "out") }
    })
}

/// Copies one label per vertex of the mesh the tree was built from into the caller's array
/// `out` of `capacity` uint32 values, at least vstree_tree_vertex_count(). `kind` is a
/// vstree_label_kind value: the vertex's cluster, or its T-node. Vertices used by no triangle
/// get VSTREE_NO_INDEX. The caller owns `out`.
///
/// Fails like vstree_tree_copy_nodes(), and with VSTREE_STATUS_INVALID_ARGUMENT for an unknown
/// `kind`. Thread-safe.
#[no_mangle]
pub unsafe extern "C" fn vstree_tree_copy_vertex_labels(
    tree: *const vstree_tree,
    kind: i32,
    out: *mut u32,
    capacity: usize,
) -> vstree_status {
    guard("vstree_tree_copy_vertex_labels", || {
        let tree = unsafe { handle::borrow(tree, "tree") }?;
        let labels = match vstree_label_kind::from_raw(kind) {
            Some(vstree_label_kind::Cluster) => &tree.cluster_labels,
            Some(vstree_label_kind::TNode) => &tree.t_node_labels,
            None => {
                return Err(Failure::argument(
                    "kind",
                    format!(
                        "{kind}: must be VSTREE_LABEL_KIND_CLUSTER (0) or \
                         VSTREE_LABEL_KIND_T_NODE (1)"
                    ),
                ))
            }
        };
        unsafe { copy_out(labels, out, capacity, "out") }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::mem::size_of;

    #[test]
    fn structs_have_no_padding() {
        assert_eq!(size_of::<vstree_node>(), 8 * 4 + 4 * 4);
        assert_eq!(size_of::<vstree_t_node>(), 4 * 4 + 4 * 4 + 12 * 4 + 3 * 4);
        assert_eq!(size_of::<vstree_tree_level>(), 32);
        assert_eq!(size_of::<vstree_tree_stats>(), 16 + 7 * 8 + 8 * 8);
    }
}
