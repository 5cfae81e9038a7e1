//! The first, parallel pass of the topology-keeping merge: the clusters, in Morton order of
//! their representatives, are cut into chunks (each one region of space), and each chunk's
//! collapses run on its own, on its own threads. A collapse there takes
//! only an edge between two vertices of one cluster whose whole star lies in the chunk and off
//! any border: the link condition (`Collapser::can_collapse`) reads nothing but the two stars,
//! so it decides as it would on the whole mesh. What is left (the vertices along the chunks'
//! seams and the borders, and the clusters' survivors) is a fraction of the input, which the
//! serial pass then finishes.

use crate::chunks::{morton_chunks, submesh, Chunks};
use crate::collapse::Collapser;
use crate::mesh::Mesh;
use glam::Vec3;
use rayon::prelude::*;

/// Input triangles per chunk: chunks as large as this cost little in seams (the vertices along
/// them wait for the serial pass), and a mesh of a million triangles still makes 20 of them for
/// the threads to share. The count of chunks depends on the mesh alone, so the result is the
/// same whatever the number of threads.
const CHUNK_TRIANGLES: usize = 50_000;

/// Collapses, chunk by chunk in parallel, the edges inside `clusters` clusters (`labels`: per
/// vertex of `mesh`) that a chunk holds whole (see the module's comment). Returns the mesh
/// left, each survivor at the mean of what it absorbed, and the label of each of its vertices;
/// `None` when the mesh is too small for more than one chunk.
pub(super) fn collapse_inside_chunks(
    mesh: &Mesh,
    labels: &[u32],
    representatives: &[Vec3],
    shift: f32,
) -> Option<(Mesh, Vec<u32>)> {
    let chunks = mesh.triangles.len() / CHUNK_TRIANGLES;
    let clusters = representatives.len();
    if chunks < 2 || clusters == 0 {
        return None;
    }
    let chunk_of_cluster = morton_chunks(representatives, chunks, shift);
    let parts = Chunks::new(mesh, chunks, |v| chunk_of_cluster[labels[v as usize] as usize]);
    let runs = parts.runs();
    let merged: Vec<(Vec<u32>, Mesh)> =
        runs.par_iter().map(|run| collapse_chunk(mesh, labels, &parts.seam, run)).collect();
    // The survivors, with the seams' triangles as they were.
    let mut positions = mesh.positions.clone();
    let mut triangles: Vec<[u32; 3]> = parts.triangles(chunks).iter().map(|&t| mesh.triangles[t as usize]).collect();
    for (global, part) in &merged {
        for (&g, &p) in global.iter().zip(&part.positions) {
            positions[g as usize] = p;
        }
        triangles.extend(part.triangles.iter().map(|t| t.map(|v| global[v as usize])));
    }
    let kept = crate::reconstruct::renumber_used_vertices(&mut triangles, positions.len());
    let out_labels = kept.iter().map(|&v| labels[v]).collect();
    let positions = kept.iter().map(|&v| positions[v]).collect();
    Some((Mesh::new(positions, None, triangles), out_labels))
}

/// One chunk's collapses, on the submesh of its `triangles`: vertices on a `seam` or a border
/// get labels of their own, so no collapse takes them. Returns the submesh left and, per vertex
/// of it, its index in `mesh`.
fn collapse_chunk(mesh: &Mesh, labels: &[u32], seam: &[bool], triangles: &[u32]) -> (Vec<u32>, Mesh) {
    let (vertices, sub) = submesh(mesh, triangles);
    let mut collapser = Collapser::new(&sub);
    // A vertex off the seams has its whole star here, so a border here is the mesh's border.
    // Labels of their own: above every cluster's, one per vertex.
    let sub_labels: Vec<u32> =
        vertices
            .iter()
            .enumerate()
            .map(|(i, &v)| {
                if seam[v as usize] || collapser.is_border(i as u32) {
                    u32::MAX - i as u32
                } else {
                    labels[v as usize]
                }
            })
            .collect();
    collapser.collapse_within(&sub_labels);
    let survivors: Vec<u32> =
        (0..vertices.len() as u32).filter(|&v| collapser.is_alive(v)).map(|v| vertices[v as usize]).collect();
    let (left, _) = collapser.finish(&sub_labels);
    (survivors, left)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::chunks::SECOND_CUT;
    use crate::eval::shapes;
    use crate::topology::analyze;

    /// Clusters of `mesh`: the cells of a grid `cells` across, with their centres.
    fn grid_clusters(mesh: &Mesh, cells: f32) -> (Vec<u32>, Vec<Vec3>) {
        let mut ids = std::collections::HashMap::new();
        let labels = mesh
            .positions
            .iter()
            .map(|p| {
                let key = ((*p + 2.0) * cells / 4.0).as_ivec3();
                let next = ids.len() as u32;
                *ids.entry((key.x, key.y, key.z)).or_insert(next)
            })
            .collect();
        let mut centres = vec![Vec3::ZERO; ids.len()];
        for ((x, y, z), id) in ids {
            centres[id as usize] = (Vec3::new(x as f32, y as f32, z as f32) + 0.5) * 4.0 / cells - 2.0;
        }
        (labels, centres)
    }

    /// The chunks' pass and then the serial one, as `collapse_keeping_topology` runs them.
    fn both_passes(mesh: &Mesh, cells: f32) -> Mesh {
        let (labels, centres) = grid_clusters(mesh, cells);
        let (rest, rest_labels) = collapse_inside_chunks(mesh, &labels, &centres, 0.0).expect("several chunks");
        assert!(
            rest.positions.len() < mesh.positions.len() / 4,
            "{} of {} left",
            rest.positions.len(),
            mesh.positions.len()
        );
        let mut collapser = Collapser::new(&rest);
        collapser.collapse_within(&rest_labels);
        collapser.finish(&rest_labels).0
    }

    #[test]
    fn chunks_collapse_apart_and_keep_the_genus_and_the_holes() {
        // A torus of 262k triangles (five chunks) in grid clusters: closed with genus 1 after;
        // its upper half (an open band, two border loops) keeps both borders manifold.
        let torus = shapes::torus(1.0, 0.3, 512, 256);
        let r = analyze(&both_passes(&torus, 40.0));
        assert!(r.is_watertight() && r.genus() == Some(1) && r.components == 1, "{r:?}");
        let band = shapes::upper_half(&torus);
        assert!(band.triangles.len() >= 2 * CHUNK_TRIANGLES);
        let r = analyze(&both_passes(&band, 40.0));
        assert_eq!((r.non_manifold_edges, r.non_manifold_vertices, r.components), (0, 0, 1), "{r:?}");
        assert!(r.boundary_edges >= 6, "{r:?}");
        assert_eq!(r.euler_characteristic, 0, "an annulus: {r:?}");
    }

    #[test]
    fn a_second_cut_takes_what_the_first_left_on_its_seams() {
        // A torus of 1M triangles in small clusters: the first cut's seams leave enough for a
        // second cut, whose chunks take most of it; genus and closure hold after both.
        let torus = shapes::torus(1.0, 0.3, 1024, 512);
        let (labels, centres) = grid_clusters(&torus, 400.0);
        let (rest, rest_labels) = collapse_inside_chunks(&torus, &labels, &centres, 0.0).expect("chunks");
        let (again, again_labels) =
            collapse_inside_chunks(&rest, &rest_labels, &centres, SECOND_CUT).expect("chunks again");
        let excess = |m: &Mesh| m.positions.len() - centres.len();
        assert!(excess(&again) < excess(&rest) / 2, "{} then {} beyond one per cluster", excess(&rest), excess(&again));
        let mut collapser = Collapser::new(&again);
        collapser.collapse_within(&again_labels);
        let r = analyze(&collapser.finish(&again_labels).0);
        assert!(r.is_watertight() && r.genus() == Some(1) && r.components == 1, "{r:?}");
    }
}
