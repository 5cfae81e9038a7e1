//! Clustering simplification (paper §4, after Schaefer & Warren 2003): every leaf of the tree is
//! a cluster; each cluster is represented by the minimiser of its samples' quadric, kept inside
//! its cell; triangles are re-indexed to representatives, and those that collapse or repeat
//! are dropped. The input's winding is kept, and non-manifold input is fine.

use crate::collapse::Collapser;
use crate::error::{shown, Error, Result};
use crate::mesh::Mesh;
use crate::progress::{Progress, Threads};
use crate::quadric::CellStats;
use crate::samples::{MeshSampling, SampleSet};
use crate::tree::{self, NodeKind, TreeParams, TreeStats, VsTree};
use glam::{DVec3, Vec3};
use rayon::prelude::*;
use std::time::Instant;

/// Parameters of [`simplify`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SimplifyParams {
    pub tree: TreeParams,
    pub sampling: MeshSampling,
    /// Worker threads; 0 = all cores.
    pub threads: usize,
    /// Keep the topology: clusters are merged by edge collapses under the link condition
    /// ([`crate::collapse`]), so a closed 2-manifold gives a closed 2-manifold of the same
    /// genus and an open one keeps its borders manifold; a cluster the condition keeps in
    /// pieces keeps a vertex per piece. Off: plain vertex clustering, which may fuse sheets.
    pub keep_topology: bool,
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
    let leaves: Vec<u32> = tree.leaves().map(|i| i as u32).collect();
    let origin = tree.root().center.as_dvec3();
    let (representatives, normals): (Vec<Vec3>, Vec<Vec3>) =
        threads.run(|| leaves.par_iter().map(|&leaf| representative(tree, leaf as usize, origin)).unzip());
    let mut sample_cluster = vec![NO_CLUSTER; tree.samples.len()];
    for (k, &leaf) in leaves.iter().enumerate() {
        for s in tree.samples_of(&tree.nodes[leaf as usize]) {
            sample_cluster[s.index as usize] = k as u32;
        }
    }
    Clustering { representatives, normals, leaves, sample_cluster }
}

/// A leaf's representative (see [`tree::representative`]) and its mean normal.
fn representative(tree: &VsTree, leaf: usize, origin: DVec3) -> (Vec3, Vec3) {
    let node = &tree.nodes[leaf];
    let mut stats = CellStats::default();
    for s in tree.samples_of(node) {
        stats.add(s.position.as_dvec3() - origin, s.normal.as_dvec3());
    }
    let frame = (node.kind == NodeKind::Surface).then(|| &tree.frames[node.frame as usize]);
    let x = tree::representative(node, frame, &stats, origin);
    let first = tree.samples_of(node).first().map_or(Vec3::Z, |s| s.normal);
    (x.as_vec3(), cluster_normal(&stats, first))
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
/// describe. Returns the simplified mesh and what was done.
pub fn simplify(mesh: &Mesh, params: &SimplifyParams, progress: &mut Progress) -> Result<(Mesh, SimplifyStats)> {
    let threads = Threads::new(params.threads)?;
    let Clustered { samples, tree, clusters, seconds_samples, seconds_tree, seconds_cluster } =
        cluster_mesh(mesh, params, &threads, progress)?;
    let t = Instant::now();
    let stats = tree.stats();
    let mut out = if mesh.is_point_cloud() {
        Mesh::from_points(clusters.representatives, Some(clusters.normals))
    } else {
        let labels = vertex_labels(mesh, &samples, &clusters, params.sampling, &tree);
        if params.keep_topology {
            collapse_keeping_topology(mesh, &labels, &clusters.representatives)
        } else {
            collapse(mesh, &labels, &clusters.representatives, &threads)?
        }
    };
    out.origin = mesh.origin;
    if !mesh.triangles.is_empty() && out.triangles.is_empty() {
        return Err(Error::param(
            "error",
            format!(
                "{}: every triangle collapsed ({} cluster{} for the whole model): the model is within \
                 this bound of too few planes; use a smaller bound (a flat model, within any bound of one \
                 plane, needs the density metric)",
                shown(params.tree.error),
                stats.leaves,
                if stats.leaves == 1 { "" } else { "s" }
            ),
        ));
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
    };
    Ok((out, stats))
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

/// Merges each cluster's vertices by edge collapses that keep the topology (see
/// [`SimplifyParams::keep_topology`]). A cluster left with one vertex puts it at the cluster's
/// representative; a cluster kept in pieces leaves each at the mean of what it absorbed.
fn collapse_keeping_topology(mesh: &Mesh, labels: &[u32], representatives: &[Vec3]) -> Mesh {
    // Degenerate triangles, and those with a vertex in no cluster, take no part.
    let proper: Vec<[u32; 3]> = mesh
        .triangles
        .iter()
        .filter(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2] && t.iter().all(|&v| labels[v as usize] != NO_CLUSTER))
        .copied()
        .collect();
    let mut used = vec![false; mesh.positions.len()];
    for &v in proper.iter().flatten() {
        used[v as usize] = true;
    }
    let mut collapser = Collapser::new(&Mesh::new(mesh.positions.clone(), None, proper));
    for (v, _) in used.iter().enumerate().filter(|(_, &used)| !used) {
        collapser.remove_vertex(v);
    }
    collapser.collapse_within(labels);
    let (mut out, out_labels) = collapser.finish(labels);
    let mut pieces = vec![0u32; representatives.len()];
    for &label in &out_labels {
        pieces[label as usize] += 1;
    }
    for (p, &label) in out.positions.iter_mut().zip(&out_labels) {
        if pieces[label as usize] == 1 {
            *p = representatives[label as usize];
        }
    }
    out
}

/// Re-indexes triangles to clusters, drops collapsed ones and repeats (the first of a repeated
/// triangle is kept, with its winding), and keeps only the representatives still used.
fn collapse(mesh: &Mesh, labels: &[u32], representatives: &[Vec3], threads: &Threads) -> Result<Mesh> {
    let (triangles, used) = threads.run(|| {
        let mut keyed: Vec<([u32; 3], u32)> = mesh
            .triangles
            .par_iter()
            .enumerate()
            .filter_map(|(t, tri)| {
                let m = tri.map(|v| labels[v as usize]);
                let distinct = m[0] != m[1] && m[1] != m[2] && m[0] != m[2];
                (distinct && !m.contains(&NO_CLUSTER)).then(|| {
                    let mut key = m;
                    key.sort_unstable();
                    (key, t as u32)
                })
            })
            .collect();
        keyed.par_sort_unstable();
        let mut kept: Vec<u32> = keyed
            .iter()
            .enumerate()
            .filter(|(k, (key, _))| *k == 0 || keyed[k - 1].0 != *key)
            .map(|(_, (_, t))| *t)
            .collect();
        kept.par_sort_unstable();
        let triangles: Vec<[u32; 3]> =
            kept.iter().map(|&t| mesh.triangles[t as usize].map(|v| labels[v as usize])).collect();
        let mut used = vec![false; representatives.len()];
        for tri in &triangles {
            for &c in tri {
                used[c as usize] = true;
            }
        }
        (triangles, used)
    });
    let mut new_index = vec![u32::MAX; representatives.len()];
    let mut positions = Vec::new();
    for (c, _) in used.iter().enumerate().filter(|(_, &u)| u) {
        new_index[c] = positions.len() as u32;
        positions.push(representatives[c]);
    }
    let triangles: Vec<[u32; 3]> = triangles.into_iter().map(|t| t.map(|c| new_index[c as usize])).collect();
    if positions.len() > u32::MAX as usize {
        return Err(Error::TooLarge("output vertices".into()));
    }
    Ok(Mesh::new(positions, None, triangles))
}
