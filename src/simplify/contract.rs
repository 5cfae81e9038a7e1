//! The fast part of the topology-keeping merge: a cluster whose contraction to one vertex
//! cannot change the topology is contracted by relabelling its vertices, as plain clustering
//! does, and only the others are left to the edge collapses.
//!
//! A cluster is contracted when (1) its vertices and the edges and triangles among them form
//! one piece with Euler characteristic 1 (a disk, not an annulus around a handle nor a handle
//! itself) off the mesh's border, and (2) after all contractions, the triangles around its
//! vertex form one disk: their far edges make one simple cycle. (2) is checked on every vertex
//! of the result, so two clusters that meet along two arcs (an edge with four triangles) or
//! three that meet at two points (a repeated triangle) are refused too (the lowest-numbered of
//! them); a vertex left as it was whose fan is broken by its neighbours' contraction refuses
//! the neighbours to blame. Refusals change the neighbours' fans, so the check runs again on
//! those fans until nothing more is refused. Before all this, a stray piece of a cluster joins
//! a cluster it touches, so that noise along the tree's cuts does not leave clusters in pieces.

use crate::mesh::Mesh;
use crate::rng::mix64;
use crate::union_find::SharedUnionFind;
use glam::Vec3;
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, AtomicU32, AtomicU64, AtomicUsize, Ordering};

/// Contracts, in `mesh` (an edge-manifold mesh without degenerate triangles, every vertex of a
/// triangle in a cluster of `labels`), every cluster the module's rules allow to its
/// representative. Returns the mesh left (the contracted clusters' vertices at their
/// representatives, the other vertices as they were) and the cluster of each of its vertices;
/// `None` when the mesh is too large for the vertex numbering.
pub(super) fn contract_disk_clusters(
    mesh: &Mesh,
    labels: &[u32],
    representatives: &[Vec3],
) -> Option<(Mesh, Vec<u32>)> {
    let clusters = representatives.len();
    if clusters + mesh.positions.len() >= u32::MAX as usize {
        return None;
    }
    let border = border_vertices(mesh);
    let labels = &join_stray_pieces(mesh, labels, clusters);
    let mut contract = disk_clusters(mesh, labels, &border, clusters);
    // The fans to check: all at first, then those that the last refusals changed, found
    // through the triangles of each cluster.
    let mut refused = refused_clusters(mesh, None, &border, &contract, &image_of(labels, &contract), None);
    let by_cluster = (!refused.is_empty()).then(|| ClusterTriangles::new(mesh, labels, clusters));
    let mut dirty = vec![false; clusters + mesh.positions.len()];
    while let (false, Some(by_cluster)) = (refused.is_empty(), &by_cluster) {
        for &c in &refused {
            contract[c as usize] = false;
        }
        let image = image_of(labels, &contract);
        let changed: Vec<u32> = sorted_unique(
            refused
                .par_iter()
                .flat_map_iter(|&c| by_cluster.of(c).iter().flat_map(|&t| mesh.triangles[t as usize].map(&image))),
        );
        // The triangles around every changed fan: its cluster's.
        let around = sorted_unique(
            sorted_unique(changed.par_iter().map(|&x| {
                if (x as usize) < clusters {
                    x
                } else {
                    labels[x as usize - clusters]
                }
            }))
            .into_par_iter()
            .flat_map_iter(|c| by_cluster.of(c).iter().copied()),
        );
        changed.iter().for_each(|&x| dirty[x as usize] = true);
        refused = refused_clusters(mesh, Some(&around), &border, &contract, &image, Some(&dirty));
        changed.iter().for_each(|&x| dirty[x as usize] = false);
    }
    // The mesh left: contracted clusters numbered by cluster, the other vertices after them.
    let id = image_of(labels, &contract);
    let mut triangles: Vec<[u32; 3]> = mesh
        .triangles
        .par_iter()
        .map(|t| t.map(&id))
        .filter(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2])
        .collect();
    let kept = crate::reconstruct::renumber_used_vertices(&mut triangles, clusters + mesh.positions.len());
    let (positions, out_labels) = kept
        .iter()
        .map(|&k| match k.checked_sub(clusters) {
            None => (representatives[k], k as u32),
            Some(v) => (mesh.positions[v], labels[v]),
        })
        .unzip();
    Some((Mesh::new(positions, None, triangles), out_labels))
}

/// Whether each vertex is on the border: its fan's far edges, each hashed by its ends, XOR to
/// nonzero (in a closed fan every far vertex is the end of two far edges; in an open one the
/// fan's two ends are left).
fn border_vertices(mesh: &Mesh) -> Vec<bool> {
    let fan: Vec<AtomicU64> = (0..mesh.positions.len()).map(|_| AtomicU64::new(0)).collect();
    let hash = |v: u32| mix64(u64::from(v) + 1);
    mesh.triangles.par_iter().for_each(|t| {
        for k in 0..3 {
            fan[t[k] as usize].fetch_xor(hash(t[(k + 1) % 3]) ^ hash(t[(k + 2) % 3]), Ordering::Relaxed);
        }
    });
    fan.into_par_iter().map(|f| f.into_inner() != 0).collect()
}

/// `labels` with each cluster in one piece where it can be: a piece of a cluster apart from
/// its largest (vertices that noise put across a cut of the tree, off the cluster's cell)
/// joins the lowest-numbered cluster whose largest piece it touches by an edge. Every vertex
/// of a triangle has a cluster.
fn join_stray_pieces(mesh: &Mesh, labels: &[u32], clusters: usize) -> Vec<u32> {
    let n = mesh.positions.len();
    let joined = pieces(mesh, labels);
    let size: Vec<AtomicU32> = (0..n).map(|_| AtomicU32::new(0)).collect();
    mesh.triangles.par_iter().for_each(|t| {
        // A piece's size in corners: it orders pieces much as vertices would, in one pass.
        for &v in t {
            size[joined.find(v) as usize].fetch_add(1, Ordering::Relaxed);
        }
    });
    // Each cluster's largest piece, by corners then by the lowest root.
    let largest: Vec<AtomicU64> = (0..clusters).map(|_| AtomicU64::new(0)).collect();
    (0..n as u32).into_par_iter().filter(|&v| joined.is_root(v)).for_each(|root| {
        let corners = size[root as usize].load(Ordering::Relaxed);
        if corners > 0 {
            let key = u64::from(corners) << 32 | u64::from(u32::MAX - root);
            largest[labels[root as usize] as usize].fetch_max(key, Ordering::Relaxed);
        }
    });
    let stray = |v: u32| {
        let root = u32::MAX - (largest[labels[v as usize] as usize].load(Ordering::Relaxed) as u32);
        joined.find(v) != root
    };
    let proposal: Vec<AtomicU32> = (0..n).map(|_| AtomicU32::new(u32::MAX)).collect();
    mesh.triangles.par_iter().for_each(|t| {
        for k in 0..3 {
            let (v, w) = (t[k], t[(k + 1) % 3]);
            for (a, b) in [(v, w), (w, v)] {
                if labels[a as usize] != labels[b as usize] && stray(a) && !stray(b) {
                    proposal[joined.find(a) as usize].fetch_min(labels[b as usize], Ordering::Relaxed);
                }
            }
        }
    });
    (0..n as u32)
        .into_par_iter()
        .map(|v| match proposal[joined.find(v) as usize].load(Ordering::Relaxed) {
            u32::MAX => labels[v as usize],
            to => to,
        })
        .collect()
}

/// The pieces of each cluster: vertices joined by the edges inside clusters.
fn pieces(mesh: &Mesh, labels: &[u32]) -> SharedUnionFind {
    let joined = SharedUnionFind::new(mesh.positions.len());
    mesh.triangles.par_iter().for_each(|t| {
        for k in 0..3 {
            let (v, w) = (t[k], t[(k + 1) % 3]);
            if labels[v as usize] == labels[w as usize] {
                joined.union(v, w);
            }
        }
    });
    joined
}

/// Rule (1) of the module for each of `clusters` clusters: one piece, Euler characteristic
/// V - E + F = 1, no vertex on the border (so each edge inside has two triangles, E = H / 2
/// for H the triangles' sides inside).
fn disk_clusters(mesh: &Mesh, labels: &[u32], border: &[bool], clusters: usize) -> Vec<bool> {
    let counter = || (0..clusters).map(|_| AtomicU32::new(0)).collect::<Vec<_>>();
    let (vertices, sides, faces, pieces) = (counter(), counter(), counter(), counter());
    let open: Vec<AtomicBool> = (0..clusters).map(|_| AtomicBool::new(false)).collect();
    let used: Vec<AtomicBool> = (0..mesh.positions.len()).map(|_| AtomicBool::new(false)).collect();
    let joined = SharedUnionFind::new(mesh.positions.len());
    mesh.triangles.par_iter().for_each(|t| {
        let c = t.map(|v| labels[v as usize]);
        for k in 0..3 {
            used[t[k] as usize].store(true, Ordering::Relaxed);
            if c[k] == c[(k + 1) % 3] {
                sides[c[k] as usize].fetch_add(1, Ordering::Relaxed);
                joined.union(t[k], t[(k + 1) % 3]);
            }
        }
        if c[0] == c[1] && c[1] == c[2] {
            faces[c[0] as usize].fetch_add(1, Ordering::Relaxed);
        }
    });
    (0..mesh.positions.len()).into_par_iter().filter(|&v| used[v].load(Ordering::Relaxed)).for_each(|v| {
        let c = labels[v] as usize;
        vertices[c].fetch_add(1, Ordering::Relaxed);
        if joined.is_root(v as u32) {
            pieces[c].fetch_add(1, Ordering::Relaxed);
        }
        if border[v] {
            open[c].store(true, Ordering::Relaxed);
        }
    });
    (0..clusters)
        .into_par_iter()
        .map(|c| {
            let get = |n: &[AtomicU32]| i64::from(n[c].load(Ordering::Relaxed));
            let h = get(&sides);
            !open[c].load(Ordering::Relaxed)
                && get(&pieces) == 1
                && h % 2 == 0
                && get(&vertices) - h / 2 + get(&faces) == 1
        })
        .collect()
}

/// The number of each vertex in the mesh left: its cluster's when `contract` says the cluster
/// is contracted, else its own, after the clusters'.
fn image_of<'a>(labels: &'a [u32], contract: &'a [bool]) -> impl Fn(u32) -> u32 + Sync + 'a {
    move |v: u32| {
        let c = labels[v as usize];
        if contract[c as usize] {
            c
        } else {
            contract.len() as u32 + v
        }
    }
}

/// The numbers, sorted, once each.
fn sorted_unique(numbers: impl ParallelIterator<Item = u32>) -> Vec<u32> {
    let mut numbers: Vec<u32> = numbers.collect();
    numbers.par_sort_unstable();
    numbers.dedup();
    numbers
}

/// The triangles of each cluster: those with a vertex in it (a triangle across clusters is in
/// each of them).
struct ClusterTriangles {
    start: Vec<usize>,
    triangles: Vec<u32>,
}

impl ClusterTriangles {
    fn new(mesh: &Mesh, labels: &[u32], clusters: usize) -> ClusterTriangles {
        let clusters_of = |t: &[u32; 3]| {
            let [a, b, c] = t.map(|v| labels[v as usize]);
            [Some(a), (b != a).then_some(b), (c != a && c != b).then_some(c)]
        };
        let counts: Vec<AtomicU32> = (0..clusters).map(|_| AtomicU32::new(0)).collect();
        mesh.triangles.par_iter().for_each(|t| {
            clusters_of(t).into_iter().flatten().for_each(|c| {
                counts[c as usize].fetch_add(1, Ordering::Relaxed);
            })
        });
        let mut start = Vec::with_capacity(clusters + 1);
        start.push(0);
        for count in counts {
            start.push(start.last().unwrap() + count.into_inner() as usize);
        }
        // Filled in parallel, so a cluster's triangles come in any order.
        let next: Vec<AtomicUsize> = start[..clusters].iter().map(|&s| AtomicUsize::new(s)).collect();
        let triangles: Vec<AtomicU32> = (0..*start.last().unwrap()).map(|_| AtomicU32::new(0)).collect();
        mesh.triangles.par_iter().enumerate().for_each(|(t, tri)| {
            for c in clusters_of(tri).into_iter().flatten() {
                triangles[next[c as usize].fetch_add(1, Ordering::Relaxed)].store(t as u32, Ordering::Relaxed);
            }
        });
        ClusterTriangles { start, triangles: triangles.into_par_iter().map(AtomicU32::into_inner).collect() }
    }

    fn of(&self, cluster: u32) -> &[u32] {
        &self.triangles[self.start[cluster as usize]..self.start[cluster as usize + 1]]
    }
}

/// The clusters rule (2) refuses with the vertices numbered by `image` (a cluster that
/// `contract` says is contracted has its vertices share its number; the others have their
/// own, above the cluster count): a contracted cluster whose fan is not one simple cycle (or
/// that no triangle is left around: the whole piece of surface would vanish), and the
/// contracted clusters around a vertex left alone whose fan is broken (not one simple cycle,
/// or one simple path on the border), unless its own fan is. Only the fans `dirty` marks (by
/// number) when it is given, from the triangles `around` them (by index) when that is given.
/// Sorted, without repeats.
fn refused_clusters(
    mesh: &Mesh,
    around: Option<&[u32]>,
    border: &[bool],
    contract: &[bool],
    image: &(impl Fn(u32) -> u32 + Sync),
    dirty: Option<&[bool]>,
) -> Vec<u32> {
    let clusters = contract.len();
    let check = |x: u32| dirty.is_none_or(|d| d[x as usize]);
    // Each corner of each triangle left: (the vertex, the far edge's two ends).
    let left = |t: &[u32; 3]| {
        let i = t.map(image);
        (i[0] != i[1] && i[1] != i[2] && i[0] != i[2] && i.iter().any(|&x| check(x))).then_some(i)
    };
    let corners_of = |i: [u32; 3]| (0..3).map(move |k| [i[k], i[(k + 1) % 3], i[(k + 2) % 3]]).filter(|c| check(c[0]));
    let mut corners: Vec<[u32; 3]> = match around {
        None => mesh.triangles.par_iter().filter_map(left).flat_map_iter(corners_of).collect(),
        Some(around) => {
            around.par_iter().filter_map(|&t| left(&mesh.triangles[t as usize])).flat_map_iter(corners_of).collect()
        }
    };
    corners.par_sort_unstable();
    let starts: Vec<usize> =
        (0..corners.len()).into_par_iter().filter(|&k| k == 0 || corners[k - 1][0] != corners[k][0]).collect();
    let contracted = |x: u32| (x as usize) < clusters;
    let mut refused: Vec<u32> = starts
        .par_iter()
        .enumerate()
        .flat_map_iter(|(s, &start)| {
            let end = starts.get(s + 1).copied().unwrap_or(corners.len());
            let fan = &corners[start..end];
            let x = fan[0][0];
            let open = !contracted(x) && border[(x as usize) - clusters];
            let Some(culprits) = broken_fan(fan, open) else { return Vec::new().into_iter() };
            let contracted_culprits: Vec<u32> = culprits.into_iter().filter(|&y| contracted(y)).collect();
            let refuse = if contracted(x) {
                // Two clusters that meet along two arcs, or three at two points, see the same
                // culprits: the lowest-numbered of them goes back, once.
                if contracted_culprits.iter().all(|&y| x < y) {
                    vec![x]
                } else {
                    Vec::new()
                }
            } else if contracted_culprits.is_empty() {
                // Broken with every end in its place (two cycles): every contracted cluster
                // around goes back, unless none was (the input's own fan is broken there).
                fan.iter().flat_map(|c| [c[1], c[2]]).filter(|&y| contracted(y)).collect()
            } else {
                contracted_culprits
            };
            refuse.into_iter()
        })
        .collect();
    let mut seen = vec![false; clusters];
    for &start in &starts {
        if contracted(corners[start][0]) {
            seen[corners[start][0] as usize] = true;
        }
    }
    refused.extend((0..clusters as u32).filter(|&c| contract[c as usize] && !seen[c as usize] && check(c)));
    refused.par_sort_unstable();
    refused.dedup();
    refused
}

/// Whether the far edges of a fan (`fan[k][1]`-`fan[k][2]`, the same centre) make one simple
/// cycle, or one simple path when `open`: `None` when they do, else the ends to blame (those of
/// an edge there twice, those of more than two edges, or of one where a cycle was due), empty
/// when every end is in place but the edges make more than one piece.
fn broken_fan(fan: &[[u32; 3]], open: bool) -> Option<Vec<u32>> {
    let n = fan.len();
    let mut edges: Vec<(u32, u32)> = fan.iter().map(|c| (c[1].min(c[2]), c[1].max(c[2]))).collect();
    edges.sort_unstable();
    let mut culprits: Vec<u32> = edges.windows(2).filter(|w| w[0] == w[1]).flat_map(|w| [w[0].0, w[0].1]).collect();
    let mut ends: Vec<u32> = edges.iter().flat_map(|&(a, b)| [a, b]).collect();
    ends.sort_unstable();
    let mut singles = Vec::new();
    for run in ends.chunk_by(|a, b| a == b) {
        match run.len() {
            1 => singles.push(run[0]),
            2 => {}
            _ => culprits.push(run[0]),
        }
    }
    if singles.len() != if open { 2 } else { 0 } {
        culprits.extend(&singles);
    }
    if !culprits.is_empty() {
        culprits.sort_unstable();
        culprits.dedup();
        return Some(culprits);
    }
    // One piece: walk from an end (or anywhere on a cycle) along unused edges.
    let mut used = vec![false; n];
    let mut at = singles.first().copied().unwrap_or(edges[0].0);
    let mut walked = 0;
    while let Some(e) = (0..n).find(|&e| !used[e] && (edges[e].0 == at || edges[e].1 == at)) {
        used[e] = true;
        walked += 1;
        at = if edges[e].0 == at { edges[e].1 } else { edges[e].0 };
    }
    (walked != n).then(Vec::new)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::shapes;
    use crate::progress::Threads;
    use crate::rng::Rng;
    use crate::simplify::merge::collapse_keeping_topology;
    use crate::topology::{analyze, TopologyReport};

    /// Clusters of `mesh` by the nearest of `count` random vertices (Euclidean, so coarse ones
    /// hold both sides of a hole, wrap around tubes and meet along several arcs), with
    /// `stray` of the vertices then moved to a neighbour's cluster, as noise does.
    fn random_clusters(mesh: &Mesh, count: usize, stray: f64, seed: u64) -> (Vec<u32>, Vec<Vec3>) {
        let mut rng = Rng::new(seed);
        let n = mesh.positions.len();
        let seeds: Vec<Vec3> = (0..count).map(|_| mesh.positions[(rng.next_u64() % n as u64) as usize]).collect();
        let nearest = |p: Vec3| {
            (0..count).min_by(|&a, &b| p.distance_squared(seeds[a]).total_cmp(&p.distance_squared(seeds[b]))).unwrap()
        };
        let mut labels: Vec<u32> = mesh.positions.iter().map(|&p| nearest(p) as u32).collect();
        for t in &mesh.triangles {
            if (rng.next_u64() % 1_000_000) as f64 / 1e6 < stray * 3.0 {
                labels[t[0] as usize] = labels[t[1] as usize];
            }
        }
        (labels, seeds)
    }

    fn shape_of(r: &TopologyReport) -> (usize, usize, usize, i64, bool) {
        (r.non_manifold_edges, r.non_manifold_vertices, r.components, r.euler_characteristic, r.boundary_edges > 0)
    }

    #[test]
    fn contraction_keeps_the_topology_of_any_clustering() {
        // Closed shapes of genus 0, 1 and 3 and an open band (the torus's upper half), in
        // clusters from a handful (which wrap around handles) to thousands, with strays: the
        // merge keeps manifoldness, components and the Euler characteristic every time.
        let torus = shapes::torus(1.0, 0.3, 96, 48);
        let band = shapes::upper_half(&torus);
        let threads = Threads::new(0).unwrap();
        for (name, mesh) in [
            ("sphere", shapes::icosphere(1.0, 4)),
            ("torus", torus.clone()),
            ("pretzel", shapes::genus_n_pretzel(3)),
            ("band", band),
        ] {
            let input = shape_of(&analyze(&mesh));
            for (k, count) in [3, 6, 20, 100, 1000].into_iter().enumerate() {
                let (labels, seeds) = random_clusters(&mesh, count, 0.02, k as u64 + 1);
                let (out, _) = collapse_keeping_topology(&mesh, &labels, &seeds, true, &threads);
                let mut r = analyze(&out);
                r.unreferenced_vertices = 0;
                assert_eq!(shape_of(&r), input, "{name} in {count} clusters: {r:?}");
            }
        }
    }

    #[test]
    fn a_cluster_holding_a_handle_is_not_contracted() {
        // A torus in one big cluster but for a cap on its outer side cut into 8 sectors and a
        // centre: the big cluster is a punctured torus whose fan (the 8 sectors) is one simple
        // cycle, so only its Euler characteristic (-1) keeps it from swallowing the handle.
        let torus = shapes::torus(1.0, 0.3, 96, 48);
        let labels: Vec<u32> = torus
            .positions
            .iter()
            .map(|p| match p.x {
                x if x > 1.28 => 9,
                x if x > 1.15 => 1 + ((p.z.atan2(p.y) + std::f32::consts::PI) / std::f32::consts::TAU * 8.0) as u32 % 8,
                _ => 0,
            })
            .collect();
        let representatives = vec![Vec3::ZERO; 10];
        let (out, _) = collapse_keeping_topology(&torus, &labels, &representatives, true, &Threads::new(0).unwrap());
        let r = analyze(&out);
        assert!(r.is_watertight() && r.genus() == Some(1), "{r:?}");
    }

    #[test]
    fn most_clusters_of_a_noisy_torus_contract_by_relabelling() {
        // A fine torus in a grid's clusters, one vertex in 20 put in the cell of a point up to
        // two edges away (so islands of one cluster inside another): at least 90% of the
        // clusters come out as one vertex without a collapse.
        let torus = shapes::torus(1.0, 0.3, 256, 128);
        let mut rng = Rng::new(3);
        let mut ids = std::collections::HashMap::new();
        let labels: Vec<u32> = torus
            .positions
            .iter()
            .map(|&p| {
                let jitter = Vec3::new(rng.normal(), rng.normal(), rng.normal()) * 0.025;
                let p = if rng.next_u64() % 20 == 0 { p + jitter } else { p };
                let key = ((p + 2.0) * 10.0).as_ivec3();
                let next = ids.len() as u32;
                *ids.entry((key.x, key.y, key.z)).or_insert(next)
            })
            .collect();
        let representatives = vec![Vec3::ZERO; ids.len()];
        let (left, left_labels) = contract_disk_clusters(&torus, &labels, &representatives).unwrap();
        let mut vertices_per_cluster = vec![0; ids.len()];
        left_labels.iter().for_each(|&c| vertices_per_cluster[c as usize] += 1);
        let single = vertices_per_cluster.iter().filter(|&&n| n == 1).count();
        assert!(single * 10 >= ids.len() * 9, "{single} of {} clusters", ids.len());
        let r = analyze(&left);
        assert!(r.is_watertight() && r.genus() == Some(1), "{r:?}");
    }

    #[test]
    fn broken_fans_name_their_culprits() {
        let fan = |edges: &[(u32, u32)]| edges.iter().map(|&(a, b)| [0, a, b]).collect::<Vec<_>>();
        assert_eq!(broken_fan(&fan(&[(1, 2), (2, 3), (3, 1)]), false), None);
        assert_eq!(broken_fan(&fan(&[(1, 2), (2, 3)]), true), None);
        // An open fan where a closed one was due: its ends.
        assert_eq!(broken_fan(&fan(&[(1, 2), (2, 3)]), false), Some(vec![1, 3]));
        // A neighbour met twice (two arcs): the one with four edges.
        assert_eq!(broken_fan(&fan(&[(1, 2), (2, 3), (3, 1), (1, 4), (4, 5), (5, 1)]), false), Some(vec![1]));
        // An edge twice (three clusters meeting at two points).
        assert_eq!(broken_fan(&fan(&[(1, 2), (2, 1)]), false), Some(vec![1, 2]));
        // Two cycles, every end in place: no one to blame.
        assert_eq!(broken_fan(&fan(&[(1, 2), (2, 3), (3, 1), (4, 5), (5, 6), (6, 4)]), false), Some(vec![]));
    }
}
