//! Cutting a mesh into chunks, regions of space whose edge collapses can run apart, each on its
//! own thread: a collapse reads and writes only the stars of its edge's two ends, so one between
//! vertices whose whole stars lie in a chunk decides as it would on the whole mesh. Vertices
//! whose star crosses from one chunk into another lie on a seam and wait for a serial pass.
//! Used by the topology-keeping merge of clusters and by the quadric decimation.

use crate::mesh::Mesh;
use glam::{UVec3, Vec3};
use rayon::prelude::*;

/// A mesh's triangles sorted by chunk, and the vertices on the seams.
pub(crate) struct Chunks {
    /// How many chunks (the seams' triangles come after the last).
    pub(crate) count: usize,
    /// Per vertex: whether its star is not whole in one chunk.
    pub(crate) seam: Vec<bool>,
    /// Triangle indices, chunk by chunk, then the seams'.
    by_chunk: Vec<u32>,
    /// Where each chunk's triangles start in `by_chunk`, and where the seams' do (`count + 2`
    /// entries).
    start: Vec<usize>,
}

impl Chunks {
    /// Sorts the triangles of `mesh` into the `count` chunks `chunk_of` gives their vertices
    /// (a triangle whose corners lie in different chunks is a seam's).
    pub(crate) fn new(mesh: &Mesh, count: usize, chunk_of: impl Fn(u32) -> u32 + Sync) -> Chunks {
        let chunk_of_triangle: Vec<u32> = mesh
            .triangles
            .par_iter()
            .map(|t| {
                let c = chunk_of(t[0]);
                if chunk_of(t[1]) == c && chunk_of(t[2]) == c {
                    c
                } else {
                    count as u32
                }
            })
            .collect();
        let mut seam = vec![false; mesh.positions.len()];
        for (t, _) in chunk_of_triangle.iter().enumerate().filter(|(_, &c)| c as usize == count) {
            for v in mesh.triangles[t] {
                seam[v as usize] = true;
            }
        }
        // A counting sort.
        let mut start = vec![0usize; count + 3];
        for &c in &chunk_of_triangle {
            start[c as usize + 2] += 1;
        }
        for c in 2..start.len() {
            start[c] += start[c - 1];
        }
        let mut by_chunk = vec![0u32; chunk_of_triangle.len()];
        for (t, &c) in chunk_of_triangle.iter().enumerate() {
            by_chunk[start[c as usize + 1]] = t as u32;
            start[c as usize + 1] += 1;
        }
        start.pop();
        Chunks { count, seam, by_chunk, start }
    }

    /// The triangles of chunk `c` (of the seams for `c == count`).
    pub(crate) fn triangles(&self, c: usize) -> &[u32] {
        &self.by_chunk[self.start[c]..self.start[c + 1]]
    }

    /// The triangles of every chunk, one slice each (the seams' not included).
    pub(crate) fn runs(&self) -> Vec<&[u32]> {
        (0..self.count).map(|c| self.triangles(c)).collect()
    }
}

/// The shift of a second cut's grid (a fraction of the box, see [`morton_chunks`]): far from a
/// power of two, so the second cut's chunk boundaries, which lie on the grid's power-of-two
/// planes, miss the first's.
pub(crate) const SECOND_CUT: f32 = 0.37;

/// The chunk of each of `points` when the points, in Morton order (a curve through space that
/// keeps nearby points together), are cut into `count` runs of equal length. `shift` moves the
/// grid the order is taken on (as a fraction of the points' box), so a second cut puts its
/// seams elsewhere.
pub(crate) fn morton_chunks(points: &[Vec3], count: usize, shift: f32) -> Vec<u32> {
    let (low, high) = points.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(l, h), &p| (l.min(p), h.max(p)));
    let extent = (high - low).max_element().max(f32::MIN_POSITIVE);
    // Shifted points stay on the grid: it is as much wider as the shift.
    let scale = 1023.0 / (extent * (1.0 + shift));
    let offset = Vec3::splat(shift * extent);
    let mut order: Vec<(u32, u32)> = points
        .par_iter()
        .enumerate()
        .map(|(i, &p)| (morton(((p - low + offset) * scale).as_uvec3()), i as u32))
        .collect();
    order.par_sort_unstable();
    let mut chunk = vec![0u32; points.len()];
    for (rank, &(_, i)) in order.iter().enumerate() {
        chunk[i as usize] = (rank * count / points.len().max(1)) as u32;
    }
    chunk
}

/// The submesh of `mesh`'s `triangles`: its vertices (indices in `mesh`, ascending) and the
/// mesh over them.
pub(crate) fn submesh(mesh: &Mesh, triangles: &[u32]) -> (Vec<u32>, Mesh) {
    let triangles: Vec<[u32; 3]> = triangles.iter().map(|&t| mesh.triangles[t as usize]).collect();
    let mut vertices: Vec<u32> = triangles.iter().flatten().copied().collect();
    vertices.sort_unstable();
    vertices.dedup();
    let local = |v: u32| vertices.binary_search(&v).unwrap_or(0) as u32;
    let sub = Mesh::new(
        vertices.iter().map(|&v| mesh.positions[v as usize]).collect(),
        None,
        triangles.iter().map(|t| t.map(local)).collect(),
    );
    (vertices, sub)
}

/// The Morton code of a point of a 1024-cell grid: its coordinates' bits interleaved.
fn morton(p: UVec3) -> u32 {
    let spread = |x: u32| {
        let mut x = x.min(1023);
        x = (x | x << 16) & 0x0300_00ff;
        x = (x | x << 8) & 0x0300_f00f;
        x = (x | x << 4) & 0x030c_30c3;
        (x | x << 2) & 0x0924_9249
    };
    spread(p.x) | spread(p.y) << 1 | spread(p.z) << 2
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::shapes;

    #[test]
    fn chunks_are_regions_and_the_seams_are_their_edges() {
        let sphere = shapes::icosphere(1.0, 5);
        let chunk = morton_chunks(&sphere.positions, 8, 0.0);
        let chunks = Chunks::new(&sphere, 8, |v| chunk[v as usize]);
        let mut seen = 0;
        for c in 0..8 {
            let run = chunks.triangles(c);
            seen += run.len();
            // Equal runs of vertices, and compact: a chunk's triangles far outnumber its seam.
            assert!(run.len() > sphere.triangles.len() / 16, "chunk {c}: {}", run.len());
            for &t in run {
                assert!(sphere.triangles[t as usize].iter().all(|&v| chunk[v as usize] == c as u32));
            }
        }
        let seams = chunks.triangles(8);
        assert_eq!(seen + seams.len(), sphere.triangles.len());
        assert!(seams.len() < sphere.triangles.len() / 5, "{} seam triangles", seams.len());
        // A seam vertex has triangles in two chunks; any other has all of its in one.
        for (v, &on_seam) in chunks.seam.iter().enumerate() {
            let mut theirs: Vec<u32> = sphere
                .triangles
                .iter()
                .filter(|t| t.contains(&(v as u32)))
                .flat_map(|t| t.map(|w| chunk[w as usize]))
                .collect();
            theirs.dedup();
            theirs.sort_unstable();
            theirs.dedup();
            assert_eq!(on_seam, theirs.len() > 1, "vertex {v}");
        }
        // Shifted, the grid puts the seams elsewhere.
        let shifted = morton_chunks(&sphere.positions, 8, SECOND_CUT);
        let again = Chunks::new(&sphere, 8, |v| shifted[v as usize]);
        let both = (0..chunks.seam.len()).filter(|&v| chunks.seam[v] && again.seam[v]).count();
        let first = chunks.seam.iter().filter(|&&s| s).count();
        assert!(both < first / 2, "{both} of {first} seam vertices on both");
    }

    #[test]
    fn a_submesh_keeps_its_triangles_over_its_own_vertices() {
        let sphere = shapes::icosphere(1.0, 2);
        let (vertices, sub) = submesh(&sphere, &[3, 10, 11]);
        assert_eq!(sub.triangles.len(), 3);
        for (t, &g) in sub.triangles.iter().zip(&[3usize, 10, 11]) {
            assert_eq!(t.map(|v| vertices[v as usize]), sphere.triangles[g]);
        }
        assert!(vertices.windows(2).all(|w| w[0] < w[1]));
    }
}
