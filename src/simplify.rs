//! Clustering simplification (paper §4, after Schaefer & Warren 2003): every leaf of the tree is
//! a cluster; each cluster is represented by the minimiser of its samples' quadric, kept inside
//! its cell; triangles are re-indexed to representatives, and those that collapse or repeat
//! are dropped. The input's winding is kept, and non-manifold input is fine.

use crate::decimate::decimate;
use crate::error::{shown, Error, Result};
use crate::mesh::Mesh;
use crate::progress::{Progress, Threads};
use crate::quadric::CellStats;
use crate::samples::{MeshSampling, SampleSet};
use crate::topology::is_edge_manifold;
use crate::tree::{self, Metric, NodeKind, TreeParams, TreeStats, VsTree};
use glam::{DVec3, Vec3};
use merge::{collapse, collapse_keeping_topology};
use rayon::prelude::*;
use std::time::Instant;

/// Whether [`simplify`] keeps the input's topology.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum KeepTopology {
    /// On when no edge of the input has more than two triangles (closed or with borders, as
    /// most scans are; [`crate::topology::is_edge_manifold`]), off on non-manifold input, where
    /// sheets already meet and plain clustering's speed costs nothing.
    #[default]
    Auto,
    /// Clusters are merged by edge collapses under the link condition ([`crate::collapse`]),
    /// so a closed 2-manifold gives a closed 2-manifold of the same genus and an open one
    /// keeps its borders manifold; a cluster the condition keeps in pieces keeps a vertex per
    /// piece. On an edge-manifold input (tested first, as `Auto` does) the clusters that are
    /// disks away from the border and from each other's folds are merged by relabelling
    /// instead, which keeps the topology as the collapses do, in a fraction of their time.
    On,
    /// Plain vertex clustering (the paper's), which may fuse sheets and make non-manifold
    /// edges, and is faster.
    Off,
}

/// Parameters of [`simplify`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SimplifyParams {
    pub tree: TreeParams,
    pub sampling: MeshSampling,
    /// Worker threads; 0 = all cores.
    pub threads: usize,
    /// Whether the topology is kept; by default when the input is edge-manifold.
    pub keep_topology: KeepTopology,
    /// Triangles wanted, from 1 to the input's count; 0 = as many as the error bound gives.
    /// With a target, `tree.error` is ignored (not even checked): the tree, built at a coarse
    /// bound of its metric ([`SimplifyParams::check`]), is grown or cut by splitting the cluster
    /// with the largest error first until there are about half as many clusters as triangles wanted (with the topology
    /// kept, 4 times that: twice as many), and quadric edge collapses under the same topology
    /// rules bring the count to the target (within one triangle: a collapse removes two). A
    /// target below what the topology allows (a closed surface of genus g needs more triangles
    /// than 4 g; a tetrahedron is the least) gives the smallest mesh the collapses reach,
    /// which [`SimplifyStats::output_triangles`] shows.
    /// Meshes only: a point cloud with a target is refused.
    pub target_faces: usize,
}

impl SimplifyParams {
    /// Rejects out-of-range parameters, naming them. With a target size the bound is not used,
    /// so it is not checked: the tree starts from its metric's seed bound instead.
    pub fn check(&self) -> Result<()> {
        if self.target_faces > 0 {
            seed_tree(&self.tree).check()
        } else {
            self.tree.check()
        }
    }
}

/// `target_faces` for a `ratio` of `triangles`: round(ratio x triangles), at least 1, as the
/// command line and every host read "keep this fraction". A ratio outside (0, 1], or of a point
/// cloud (no triangles), is an error naming `ratio`.
pub fn faces_for_ratio(ratio: f64, triangles: u64) -> Result<usize> {
    let bad = |message: String| Err(crate::Error::InvalidParameter { name: "ratio", message });
    if !(ratio > 0.0 && ratio <= 1.0) {
        return bad(format!("{ratio}: must be in (0, 1], a fraction of the input's triangles"));
    }
    if triangles == 0 {
        return bad(format!(
            "{ratio}: the input is a point cloud, with no triangles to take a fraction of: a ratio needs a mesh"
        ));
    }
    Ok(((ratio * triangles as f64).round() as usize).clamp(1, usize::try_from(triangles).unwrap_or(usize::MAX)))
}

/// Why a simplification to a size gave another size.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SizeMissed {
    /// More triangles: fewer would change the topology that was kept.
    Topology,
    /// More triangles: no further edge collapses without folding or pinching the surface.
    NoCollapse,
    /// Fewer triangles: the input has no more distinct clusters to give.
    NoClusters,
}

impl SizeMissed {
    /// Outputs within this share of the target (or [`SizeMissed::SLACK_TRIANGLES`]) are on
    /// target: the collapses stop within a triangle or two, the tree's cut within about 1%.
    /// cbindgen:ignore
    pub const SLACK_SHARE: usize = 100;
    /// cbindgen:ignore
    pub const SLACK_TRIANGLES: usize = 2;

    /// Why `output` triangles came out where `target` were asked for (`kept_topology` as the
    /// stats say), or `None` when it is on target or no size was asked.
    pub fn of(target: usize, output: usize, kept_topology: bool) -> Option<SizeMissed> {
        let slack = (target / Self::SLACK_SHARE).max(Self::SLACK_TRIANGLES);
        if target == 0 || output.abs_diff(target) <= slack {
            return None;
        }
        Some(if output < target {
            SizeMissed::NoClusters
        } else if kept_topology {
            SizeMissed::Topology
        } else {
            SizeMissed::NoCollapse
        })
    }

    /// The reason, as a sentence without a final stop.
    pub fn reason(self) -> &'static str {
        self.reason_c().to_str().expect("ASCII")
    }

    /// [`SizeMissed::reason`] for C.
    pub fn reason_c(self) -> &'static std::ffi::CStr {
        match self {
            SizeMissed::Topology => {
                c"fewer would change the topology (genus, borders); turning keep_topology off allows it"
            }
            SizeMissed::NoCollapse => c"no further edge can collapse without folding the surface or pinching it",
            SizeMissed::NoClusters => c"the input has no more distinct clusters to give",
        }
    }
}

/// What [`simplify`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SimplifyStats {
    pub tree: TreeStats,
    pub input_vertices: usize,
    pub input_triangles: usize,
    pub output_vertices: usize,
    pub output_triangles: usize,
    pub seconds_samples: f64,
    pub seconds_tree: f64,
    pub seconds_cluster: f64,
    /// Whether the topology was kept (see [`KeepTopology`]).
    pub kept_topology: bool,
}

/// The clusters of a tree: one per leaf.
#[derive(Clone, Debug, PartialEq)]
pub struct Clustering {
    /// Representative point of each cluster.
    pub representatives: Vec<Vec3>,
    /// Normalised mean normal of each cluster.
    pub normals: Vec<Vec3>,
    /// The leaf node of each cluster.
    pub leaves: Vec<u32>,
    /// Cluster of each sample, indexed like the [`SampleSet`] the tree was built from.
    pub sample_cluster: Vec<u32>,
}

/// Marks a vertex that belongs to no cluster (it is used by no triangle).
pub const NO_CLUSTER: u32 = u32::MAX;

/// Computes the clusters of `tree`: representatives in parallel, deterministic.
pub fn cluster(tree: &VsTree, threads: &Threads) -> Clustering {
    cluster_with_stats(tree, threads).0
}

/// [`cluster`], with the sums of each cluster's samples (positions relative to the root's
/// centre), which are its quadric.
fn cluster_with_stats(tree: &VsTree, threads: &Threads) -> (Clustering, Vec<CellStats>) {
    let leaves: Vec<u32> = tree.leaves().map(|i| i as u32).collect();
    let origin = tree.root().center.as_dvec3();
    let (points, stats): (Vec<(Vec3, Vec3)>, Vec<CellStats>) =
        threads.run(|| leaves.par_iter().map(|&leaf| representative(tree, leaf as usize, origin)).unzip());
    let (representatives, normals) = points.into_iter().unzip();
    let mut sample_cluster = vec![NO_CLUSTER; tree.samples.len()];
    for (k, &leaf) in leaves.iter().enumerate() {
        for s in tree.samples_of(&tree.nodes[leaf as usize]) {
            sample_cluster[s.index as usize] = k as u32;
        }
    }
    (Clustering { representatives, normals, leaves, sample_cluster }, stats)
}

/// A leaf's representative (see [`tree::representative`]) and its mean normal, and its
/// samples' sums.
fn representative(tree: &VsTree, leaf: usize, origin: DVec3) -> ((Vec3, Vec3), CellStats) {
    let node = &tree.nodes[leaf];
    let mut stats = CellStats::default();
    for s in tree.samples_of(node) {
        stats.add(s.position.as_dvec3() - origin, s.normal.as_dvec3());
    }
    let frame = (node.kind == NodeKind::Surface).then(|| &tree.frames[node.frame as usize]);
    let x = tree::representative(node, frame, &stats, origin);
    let first = tree.samples_of(node).first().map_or(Vec3::Z, |s| s.normal);
    ((x.as_vec3(), cluster_normal(&stats, first)), stats)
}

/// The cluster's unit normal: its samples' mean normal. Where the normals cancel out (two
/// sheets facing away from each other in one cell), the mean says nothing; the axis the
/// normals share most (the main eigenvector of Σ n nᵀ) is used instead, turned towards
/// `first`, a sample's normal, so that no cluster gets a zero normal.
fn cluster_normal(stats: &CellStats, first: Vec3) -> Vec3 {
    let mean = stats.mean_normal();
    if mean.length() > 1e-6 {
        return mean.normalize().as_vec3();
    }
    let (_, vectors) = stats.nn.eigen();
    let axis = vectors[0].as_vec3().normalize_or(Vec3::Z);
    if axis.dot(first) < 0.0 {
        -axis
    } else {
        axis
    }
}

/// The samples, tree and clusters of a mesh (or a point cloud with normals): the steps
/// [`simplify`] and the C API's tree handle share, with their times in seconds.
pub struct Clustered {
    pub samples: SampleSet,
    pub tree: VsTree,
    pub clusters: Clustering,
    pub seconds_samples: f64,
    pub seconds_tree: f64,
    pub seconds_cluster: f64,
}

/// Takes the samples of `mesh` as `params` say (a cloud's points when it has no triangles),
/// builds their tree (progress 0 to 0.8) and its clusters.
pub fn cluster_mesh(
    mesh: &Mesh,
    params: &SimplifyParams,
    threads: &Threads,
    progress: &mut Progress,
) -> Result<Clustered> {
    let t0 = Instant::now();
    let samples =
        if mesh.is_point_cloud() { SampleSet::from_cloud(mesh)? } else { SampleSet::from_mesh(mesh, params.sampling)? };
    let t1 = Instant::now();
    let tree = tree::build(&samples, &params.tree, threads, &mut progress.stage(0.0, 0.8))?;
    let t2 = Instant::now();
    progress.report(0.8, "clustering")?;
    let clusters = cluster(&tree, threads);
    Ok(Clustered {
        samples,
        tree,
        clusters,
        seconds_samples: (t1 - t0).as_secs_f64(),
        seconds_tree: (t2 - t1).as_secs_f64(),
        seconds_cluster: t2.elapsed().as_secs_f64(),
    })
}

/// Simplifies `mesh` (or a point cloud with normals) by clustering in the tree `params`
/// describe, to the error bound or to the number of triangles asked for. Returns the
/// simplified mesh and what was done.
pub fn simplify(mesh: &Mesh, params: &SimplifyParams, progress: &mut Progress) -> Result<(Mesh, SimplifyStats)> {
    let threads = Threads::new(params.threads)?;
    params.check()?;
    check_target(mesh.triangles.len(), params.target_faces)?;
    let edge_manifold = || threads.run(|| is_edge_manifold(mesh));
    let merge = match params.keep_topology {
        _ if mesh.is_point_cloud() => Merge::Plain,
        KeepTopology::Off => Merge::Plain,
        KeepTopology::On => Merge::KeepTopology { edge_manifold: edge_manifold() },
        KeepTopology::Auto if edge_manifold() => Merge::KeepTopology { edge_manifold: true },
        KeepTopology::Auto => Merge::Plain,
    };
    let keep = merge != Merge::Plain;
    if params.target_faces > 0 {
        // Plain clustering stays plain: its output has non-manifold edges where sheets fused,
        // which collapses must not take, so it is cut to the target's clusters directly.
        let factor = if keep { CLUSTER_FACTOR } else { 1.0 };
        return simplify_to_size(mesh, params, merge, factor, &threads, progress);
    }
    let Clustered { samples, tree, clusters, seconds_samples, seconds_tree, seconds_cluster } =
        cluster_mesh(mesh, params, &threads, progress)?;
    let t = Instant::now();
    let stats = tree.stats();
    let mut out = if mesh.is_point_cloud() {
        Mesh::from_points(clusters.representatives, Some(clusters.normals))
    } else {
        let labels = vertex_labels(mesh, &samples, &clusters, params.sampling, &tree);
        merge_clusters(mesh, &labels, &clusters.representatives, merge, &threads)?.0
    };
    out.origin = mesh.origin;
    if !mesh.triangles.is_empty() && out.triangles.is_empty() {
        return Err(collapsed(&tree, "every triangle collapsed"));
    }
    // A cloud of one point is what was asked only when all its points are at one place.
    if mesh.is_point_cloud() && stats.leaves == 1 && samples.len() > 1 && tree.diagonal > 0.0 {
        return Err(collapsed(&tree, &format!("all {} points collapsed into one", samples.len())));
    }
    progress.report(1.0, "done")?;
    let stats = SimplifyStats {
        tree: stats,
        input_vertices: mesh.positions.len(),
        input_triangles: mesh.triangles.len(),
        output_vertices: out.positions.len(),
        output_triangles: out.triangles.len(),
        seconds_samples,
        seconds_tree,
        seconds_cluster: seconds_cluster + t.elapsed().as_secs_f64(),
        kept_topology: keep,
    };
    Ok((out, stats))
}

/// The error of a simplification that kept nothing of the model's shape (`what` happened): it
/// names the parameter that made the tree this coarse (the depth or cell-size limit where a
/// leaf beyond the bound could not be split, else the bound) and what to change.
fn collapsed(tree: &VsTree, what: &str) -> Error {
    let p = &tree.params;
    let defaults = TreeParams::default();
    let leaves = tree.stats().leaves;
    let what = format!("{what} ({leaves} cluster{} for the whole model)", if leaves == 1 { "" } else { "s" });
    match tree.limited_by() {
        Some("max_depth") => Error::param(
            "max_depth",
            format!(
                "{}: {what}: the tree stopped at this depth, coarser than the bound asks; allow a deeper tree (default {})",
                p.max_depth, defaults.max_depth
            ),
        ),
        Some(name) => Error::param(
            name,
            format!(
                "{}: {what}: cells this small (relative to the diagonal) are not split, so the tree is coarser than \
                 the bound asks; use a smaller size (default {})",
                shown(p.min_cell_size),
                shown(defaults.min_cell_size)
            ),
        ),
        None => {
            let advice = match p.metric {
                Metric::L2 => {
                    "the model is within this bound of too few planes; use a smaller bound (a flat model, within \
                     any bound of one plane, needs the density metric)"
                }
                Metric::L21 => {
                    "the model's normals vary within this bound over too few cells; use a smaller bound (a flat \
                     model, whose normals do not vary, needs the density metric)"
                }
                Metric::Density => "the model has too few samples for clusters this large; use a smaller count (at least 1)",
            };
            let bound = match p.metric {
                Metric::Density => format!("{} samples per cell", shown(p.error)),
                _ => shown(p.error),
            };
            Error::param("error", format!("{bound}: {what}: {advice}"))
        }
    }
}

/// Refuses a target the input cannot give: more triangles than it has, or any on a cloud.
fn check_target(triangles: usize, target: usize) -> Result<()> {
    if target == 0 {
        return Ok(());
    }
    if triangles == 0 {
        return Err(Error::param(
            "target_faces",
            format!("{target} triangles asked of a point cloud: a target needs a mesh (use the error bound)"),
        ));
    }
    if target > triangles {
        return Err(Error::param("target_faces", format!("{target}: more than the input's {triangles} triangles")));
    }
    Ok(())
}

/// How a clustering's vertices become the output's.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Merge {
    /// Triangles re-indexed to clusters (see [`KeepTopology::Off`]).
    Plain,
    /// By collapses that keep the topology; an `edge_manifold` input's disk clusters first by
    /// relabelling.
    KeepTopology { edge_manifold: bool },
}

/// Merges each cluster's vertices (`labels`: per vertex of `mesh`) as `merge` says. Returns
/// the mesh and the cluster of each of its vertices.
fn merge_clusters(
    mesh: &Mesh,
    labels: &[u32],
    representatives: &[Vec3],
    merge: Merge,
    threads: &Threads,
) -> Result<(Mesh, Vec<u32>)> {
    match merge {
        Merge::Plain => collapse(mesh, labels, representatives, threads),
        Merge::KeepTopology { edge_manifold } => {
            Ok(collapse_keeping_topology(mesh, labels, representatives, edge_manifold, threads))
        }
    }
}

/// Clusters asked for per triangle wanted: a closed triangle mesh has about twice as many
/// triangles as vertices (Euler: F = 2V - 4 + 4g), and each cluster gives one vertex.
const CLUSTERS_PER_TRIANGLE: f64 = 0.5;

/// Clusters asked for beyond Euler's estimate (a ratio): plain clustering loses a few
/// triangles to fused and repeated ones, so the tree is cut a little finer and the quadric
/// collapses remove the excess. 5% covers what the shared models lose, so one round suffices.
const CLUSTER_MARGIN: f64 = 1.05;

/// The L2 bound (relative, squared) a sized run builds its tree at before growing it to the
/// target by largest error: coarse, so the parallel build does the top levels and small targets
/// need no cut of a deep tree; any start gives the same result up to ties between equal errors
/// (tree::fit's tests).
const SEED_ERROR: f64 = 1e-2;

/// The tree a sized run builds before growing or cutting it to the target: `tree` with its
/// metric's seed bound in place of the bound, which a size ignores. Where it starts matters
/// only for ties.
fn seed_tree(tree: &TreeParams) -> TreeParams {
    let error = match tree.metric {
        Metric::L2 => SEED_ERROR,
        metric => metric.default_error(),
    };
    TreeParams { error, ..*tree }
}

/// Clusters per output vertex in a sized run that keeps the topology (unitless): the tree is cut into this many times
/// the clusters the target needs and quadric edge collapses remove the rest, choosing the
/// vertices by what removing them costs, where a cell of the tree halved by position gives one
/// point wherever it lies; 4 keeps most of the gain in distance to the input over 1, 2 and 8
/// at half the time of 8 (`cargo bench --bench simplify`, docs/benchmarks.md).
const CLUSTER_FACTOR: f64 = 4.0;

/// At most this many rounds of regrowing the tree when the clustering still gives too few
/// triangles (each round aims at the target from the count the last one gave).
const MAX_ROUNDS: usize = 4;

/// The clusters to ask of the tree for `target` triangles times `factor` (see
/// [`CLUSTER_FACTOR`]), or, after a round that gave `got` triangles from `clusters` clusters
/// (too few), for the next round, which aims at the target.
fn clusters_for(target: usize, last: Option<(usize, usize)>, factor: f64) -> usize {
    match last {
        None => (target as f64 * CLUSTERS_PER_TRIANGLE * CLUSTER_MARGIN * factor).ceil() as usize,
        Some((clusters, 0)) => 4 * clusters.max(1),
        Some((clusters, got)) => {
            let scaled = (clusters as f64 * target as f64 / got as f64 * CLUSTER_MARGIN).ceil() as usize;
            scaled.max(clusters + 1)
        }
    }
}

/// [`simplify`] with a target size: the tree fitted to `factor` times the target's clusters
/// (grown again while the clustering gives too few triangles), then quadric edge collapses to
/// the target.
fn simplify_to_size(
    mesh: &Mesh,
    params: &SimplifyParams,
    merge: Merge,
    factor: f64,
    threads: &Threads,
    progress: &mut Progress,
) -> Result<(Mesh, SimplifyStats)> {
    let target = params.target_faces;
    let t0 = Instant::now();
    let samples = SampleSet::from_mesh(mesh, params.sampling)?;
    let t1 = Instant::now();
    let mut tree = tree::build(&samples, &seed_tree(&params.tree), threads, &mut progress.stage(0.0, 0.6))?;
    let t2 = Instant::now();
    progress.report(0.6, "fitting the tree to the size")?;
    let mut want = clusters_for(target, None, factor);
    let mut last_leaves = 0;
    let mut round = 1;
    // The last round's clusters and their samples' sums.
    let mut last: (Clustering, Vec<CellStats>);
    let (out, out_clusters) = loop {
        let leaves = tree::fit(&mut tree, want, threads);
        last = cluster_with_stats(&tree, threads);
        let clusters = &last.0;
        let labels = vertex_labels(mesh, &samples, clusters, params.sampling, &tree);
        // The tree has no leaf left to split: more rounds would give the same clusters.
        let exhausted = leaves < want || leaves <= last_leaves;
        let last_round = exhausted || round == MAX_ROUNDS;
        last_leaves = leaves;
        round += 1;
        progress.report(0.7, "clustering")?;
        let out = merge_clusters(mesh, &labels, &clusters.representatives, merge, threads)?;
        if out.0.triangles.len() >= target || last_round {
            break out;
        }
        want = clusters_for(target, Some((leaves, out.0.triangles.len())), factor);
    };
    progress.report(0.9, "collapsing edges to the size")?;
    let mut out = out;
    out.origin = mesh.origin;
    let (clusters, cluster_stats) = last;
    let quadrics = threads.run(|| pieces::piece_quadrics(&out, &out_clusters, &cluster_stats, &tree, &clusters.leaves));
    let out = collapse_to_target(out, quadrics, &tree, target, threads, &mut progress.stage(0.9, 1.0))?;
    progress.report(1.0, "done")?;
    let stats = SimplifyStats {
        tree: tree.stats(),
        input_vertices: mesh.positions.len(),
        input_triangles: mesh.triangles.len(),
        output_vertices: out.positions.len(),
        output_triangles: out.triangles.len(),
        seconds_samples: (t1 - t0).as_secs_f64(),
        seconds_tree: (t2 - t1).as_secs_f64(),
        seconds_cluster: t2.elapsed().as_secs_f64(),
        kept_topology: merge != Merge::Plain,
    };
    Ok((out, stats))
}

/// Brings the clustered mesh `out` (vertex v with quadric `quadrics[v]`, relative to `tree`'s
/// root centre) to `target` triangles by quadric collapses; refused when nothing is left. The
/// result is in `out`'s frame, at `out`'s origin.
fn collapse_to_target(
    out: Mesh,
    quadrics: Vec<CellStats>,
    tree: &VsTree,
    target: usize,
    threads: &Threads,
    progress: &mut Progress,
) -> Result<Mesh> {
    let centre = tree.root().center.as_dvec3();
    let origin = out.origin;
    let mut out = if out.triangles.len() > target + 1 {
        decimate(&out, quadrics, centre, target, threads, progress)?.0
    } else {
        out
    };
    out.origin = origin;
    if out.triangles.is_empty() {
        return Err(Error::input(format!(
            "every triangle collapsed for a target of {target}: the model has only degenerate or repeated triangles at this size"
        )));
    }
    Ok(out)
}

/// The cluster of every mesh vertex ([`NO_CLUSTER`] for vertices no triangle uses). With face
/// samples, a vertex joins the cluster of its first incident face that gave a sample, or else
/// the leaf its position falls in.
pub fn vertex_labels(
    mesh: &Mesh,
    samples: &SampleSet,
    clusters: &Clustering,
    sampling: MeshSampling,
    tree: &VsTree,
) -> Vec<u32> {
    let mut labels = vec![NO_CLUSTER; mesh.positions.len()];
    match sampling {
        MeshSampling::Vertices => {
            for (s, &v) in samples.origin.iter().enumerate() {
                labels[v as usize] = clusters.sample_cluster[s];
            }
        }
        MeshSampling::FaceCenters => {
            for (s, &f) in samples.origin.iter().enumerate() {
                for &v in &mesh.triangles[f as usize] {
                    if labels[v as usize] == NO_CLUSTER {
                        labels[v as usize] = clusters.sample_cluster[s];
                    }
                }
            }
            let leaf_cluster = |node: usize| {
                let mut i = node;
                while !tree.nodes[i].is_leaf() {
                    i = tree.nodes[i].first_child as usize;
                }
                clusters.leaves.binary_search(&(i as u32)).map_or(NO_CLUSTER, |k| k as u32)
            };
            for tri in &mesh.triangles {
                for &v in tri {
                    if labels[v as usize] == NO_CLUSTER {
                        if let Some(node) = tree.locate(mesh.positions[v as usize]) {
                            labels[v as usize] = leaf_cluster(node);
                        }
                    }
                }
            }
        }
    }
    labels
}

mod chunks;
mod contract;
mod merge;
mod pieces;
mod stream;
pub use stream::simplify_ply_streaming;
#[cfg(test)]
mod tests;
