//! Merging each cluster's vertices into one: keeping the topology (disk clusters by
//! relabelling, the rest by edge collapses), or plainly, re-indexing the triangles to clusters.

use super::{chunks, contract, NO_CLUSTER};
use crate::chunks::SECOND_CUT;
use crate::collapse::Collapser;
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::progress::Threads;
use glam::Vec3;
use rayon::prelude::*;

/// Merges each cluster's vertices by edge collapses that keep the topology (see
/// [`SimplifyParams::keep_topology`]): on an `edge_manifold` mesh the clusters that are disks
/// first by relabelling ([`contract::contract_disk_clusters`]); then the rest inside chunks of
/// clusters in parallel ([`chunks::collapse_inside_chunks`]), and serially along the chunks'
/// seams. A cluster left
/// with one vertex puts it at the cluster's representative; a cluster kept in pieces leaves each
/// at the mean of what it absorbed.
/// Returns the mesh and the cluster of each of its vertices.
pub(in crate::simplify) fn collapse_keeping_topology(
    mesh: &Mesh,
    labels: &[u32],
    representatives: &[Vec3],
    edge_manifold: bool,
    threads: &Threads,
) -> (Mesh, Vec<u32>) {
    // Degenerate triangles, and those with a vertex in no cluster, take no part.
    let proper: Vec<[u32; 3]> = mesh
        .triangles
        .iter()
        .filter(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2] && t.iter().all(|&v| labels[v as usize] != NO_CLUSTER))
        .copied()
        .collect();
    let proper = Mesh::new(mesh.positions.clone(), None, proper);
    let contracted = edge_manifold
        .then(|| threads.run(|| contract::contract_disk_clusters(&proper, labels, representatives)))
        .flatten();
    let (proper, labels) = contracted.unwrap_or_else(|| (proper, labels.to_vec()));
    let labels = labels.as_slice();
    let first = threads.run(|| chunks::collapse_inside_chunks(&proper, labels, representatives, 0.0));
    // A second cut, its seams elsewhere, takes most of what the first left along its seams.
    let second = first.map(|(rest, rest_labels)| {
        threads
            .run(|| chunks::collapse_inside_chunks(&rest, &rest_labels, representatives, SECOND_CUT))
            .unwrap_or((rest, rest_labels))
    });
    let (mut out, out_labels) = match second {
        // The seams and borders the chunks left.
        Some((rest, rest_labels)) => {
            let mut collapser = Collapser::new(&rest);
            collapser.collapse_within(&rest_labels);
            collapser.finish(&rest_labels)
        }
        None => {
            let mut used = vec![false; proper.positions.len()];
            for &v in proper.triangles.iter().flatten() {
                used[v as usize] = true;
            }
            let mut collapser = Collapser::new(&proper);
            for (v, _) in used.iter().enumerate().filter(|(_, &used)| !used) {
                collapser.remove_vertex(v);
            }
            collapser.collapse_within(labels);
            collapser.finish(labels)
        }
    };
    let mut pieces = vec![0u32; representatives.len()];
    for &label in &out_labels {
        pieces[label as usize] += 1;
    }
    for (p, &label) in out.positions.iter_mut().zip(&out_labels) {
        if pieces[label as usize] == 1 {
            *p = representatives[label as usize];
        }
    }
    (out, out_labels)
}

/// Re-indexes triangles to clusters, drops collapsed ones and repeats (the first of a repeated
/// triangle is kept, with its winding), and keeps only the representatives still used.
/// Returns the mesh and the cluster of each of its vertices.
pub(super) fn collapse(
    mesh: &Mesh,
    labels: &[u32],
    representatives: &[Vec3],
    threads: &Threads,
) -> Result<(Mesh, Vec<u32>)> {
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
    let mut clusters = Vec::new();
    for (c, _) in used.iter().enumerate().filter(|(_, &u)| u) {
        new_index[c] = positions.len() as u32;
        positions.push(representatives[c]);
        clusters.push(c as u32);
    }
    let triangles: Vec<[u32; 3]> = triangles.into_iter().map(|t| t.map(|c| new_index[c as usize])).collect();
    if positions.len() > u32::MAX as usize {
        return Err(Error::TooLarge("output vertices".into()));
    }
    Ok((Mesh::new(positions, None, triangles), clusters))
}
