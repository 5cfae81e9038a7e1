//! Folds, found and undone. A triangle is folded where it faces against the sum of its corners'
//! normals (a vertex slid over its neighbours), or where it and its neighbour across an edge
//! turn by more than [`FOLD_DEGREES`] (where the corners' normals turned with the fold). Folds
//! are undone by moving the vertices around them to their neighbours' mean and back onto the
//! samples' fit ([`unfold`]); the base mesh's and each level's new vertices also go back onto
//! the quadtree leaves under them (`Refiner::unfold_base` in [`super::refine`]).

use super::adjacency::Rows;
use super::mls::SampleSurface;
use super::refine::Surface;
use crate::progress::Threads;
use glam::Vec3;
use rayon::prelude::*;

/// Whether triangle `t` faces against the sum of its corners' normals.
pub(crate) fn is_folded(s: &Surface, t: &[u32; 3]) -> bool {
    let [a, b, c] = t.map(|v| s.positions[v as usize]);
    let corners: Vec3 = t.iter().map(|&v| s.normals[v as usize]).sum();
    (b - a).cross(c - a).dot(corners) < 0.0
}

/// Two faces sharing an edge are folded onto each other where their normals differ by more
/// than this many degrees (the benchmark's fold): a surface sampled finer than its triangles
/// rarely bends so sharply between two of them, so one of them most likely lies on the wrong side.
pub(crate) const FOLD_DEGREES: f32 = 150.0;

/// The corners of triangles whose normal points against the sum of their corners' normals.
pub(crate) fn folded_vertices(s: &Surface) -> Vec<usize> {
    let mut folded: Vec<usize> =
        s.triangles.par_iter().filter(|t| is_folded(s, t)).flat_map_iter(|t| t.map(|v| v as usize)).collect();
    folded.sort_unstable();
    folded.dedup();
    folded
}

/// [`folded_vertices`], and the corners of pairs of triangles folded onto each other across
/// their edge (see [`FOLD_DEGREES`]; `pairs` from [`crate::topology::adjacent_face_pairs`]):
/// where the corners' normals turned with their triangles, the first test alone misses the fold.
pub(crate) fn folded_or_creased_vertices(s: &Surface, pairs: &[[u32; 2]]) -> Vec<usize> {
    let mut folded = folded_vertices(s);
    for pair in crate::topology::folded_face_pairs(&s.positions, &s.triangles, pairs, FOLD_DEGREES) {
        folded.extend(pair.iter().flat_map(|&t| s.triangles[t as usize]).map(|v| v as usize));
    }
    folded.sort_unstable();
    folded.dedup();
    folded
}

/// Rounds of [`unfold`]; from the second on the region grows by a ring each round.
const UNFOLD_ROUNDS: usize = 4;

/// Unfolds `s` where a triangle faces against its corners' normals or folds onto its neighbour
/// ([`folded_or_creased_vertices`]: a displaced vertex slid over its neighbours, or two fits of
/// a thin part disagree): each corner of such a triangle
/// goes to the mean of its neighbours and back onto the samples' surface, in rounds. From the
/// second round on, the ring around the vertices still folded moves too: a fold pinned by
/// its own neighbours needs room. Vertices `border` marks stay. Returns the vertices still
/// folded.
pub(crate) fn unfold(
    s: &mut Surface,
    border: &[bool],
    onto: &SampleSurface,
    reach: f32,
    threads: &Threads,
) -> Vec<usize> {
    // The triangles stay the same while their corners move: which faces meet is found once.
    let pairs = threads.run(|| crate::topology::adjacent_face_pairs(&s.triangles));
    let mut folded = threads.run(|| folded_or_creased_vertices(s, &pairs));
    if folded.is_empty() {
        return folded;
    }
    let neighbours = Rows::neighbours(&s.triangles, s.positions.len());
    for round in 0..UNFOLD_ROUNDS {
        if round > 0 {
            let ring: Vec<usize> = folded.iter().flat_map(|&v| neighbours.of(v as u32)).map(|&w| w as usize).collect();
            folded.extend(ring);
            folded.sort_unstable();
            folded.dedup();
        }
        let moved: Vec<(usize, Vec3, Vec3)> = threads.run(|| {
            folded
                .par_iter()
                .filter(|&&v| !border[v] && !neighbours.of(v as u32).is_empty())
                .map(|&v| {
                    let ring = neighbours.of(v as u32);
                    let mean = ring.iter().map(|&w| s.positions[w as usize]).sum::<Vec3>() / ring.len() as f32;
                    let normal = ring.iter().map(|&w| s.normals[w as usize]).sum::<Vec3>().normalize_or_zero();
                    let normal = if normal == Vec3::ZERO { s.normals[v] } else { normal };
                    match onto.project(mean, normal) {
                        Some((p, n)) if p.distance(mean) <= reach => (v, p, n),
                        _ => (v, mean, normal),
                    }
                })
                .collect()
        });
        for (v, p, n) in moved {
            s.positions[v] = p;
            s.normals[v] = n;
        }
        folded = threads.run(|| folded_or_creased_vertices(s, &pairs));
        if folded.is_empty() {
            break;
        }
    }
    folded
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reconstruct::mls::tests::sphere_samples;

    #[test]
    fn a_triangle_folded_back_onto_its_neighbour_is_found_whatever_its_corners_normals() {
        // Two triangles across the edge (a, b), the second folded back over the first (their
        // normals 179 degrees apart), each corner's normal turned with its own triangle: no
        // triangle faces against its corners, yet the pair is a fold.
        let s = Surface {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::new(0.5, 1.0, 0.0), Vec3::new(0.5, 0.8, 0.01)],
            normals: vec![Vec3::ZERO, Vec3::ZERO, Vec3::Z, -Vec3::Z],
            labels: vec![0; 4],
            triangles: vec![[0, 1, 2], [1, 0, 3]],
        };
        let pairs = crate::topology::adjacent_face_pairs(&s.triangles);
        assert!(folded_vertices(&s).is_empty());
        assert_eq!(folded_or_creased_vertices(&s, &pairs), vec![0, 1, 2, 3]);
        // Opened out to a flat pair, it is no fold.
        let flat = Surface {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::new(0.5, 1.0, 0.0), Vec3::new(0.5, -1.0, 0.0)],
            normals: vec![Vec3::Z; 4],
            ..s
        };
        assert!(folded_or_creased_vertices(&flat, &pairs).is_empty());
    }

    /// An icosphere on sphere samples with three vertices slid along the sphere past their
    /// whole ring, so triangles around them face inward; normals radial.
    fn pushed_icosphere() -> Surface {
        let sphere = crate::eval::shapes::icosphere(1.0, 3);
        let mut s = Surface {
            normals: sphere.positions.clone(),
            labels: vec![0; sphere.positions.len()],
            positions: sphere.positions.clone(),
            triangles: sphere.triangles.clone(),
        };
        for v in [10, 200, 400] {
            let p = s.positions[v];
            let (u, _) = p.any_orthonormal_pair();
            s.positions[v] = (p + 0.4 * u).normalize();
        }
        s
    }

    /// Unfolds `s` onto samples of the unit sphere; returns the largest distance of a vertex
    /// from the sphere.
    fn unfold_onto_the_sphere(s: &mut Surface) -> f32 {
        let threads = Threads::new(1).unwrap();
        let samples = sphere_samples(20_000, 1.0);
        let onto = SampleSurface::new(&samples, &threads).unwrap();
        let border = vec![false; s.positions.len()];
        unfold(s, &border, &onto, 0.2, &threads);
        s.positions.iter().map(|p| (p.length() - 1.0).abs()).fold(0.0f32, f32::max)
    }

    #[test]
    fn a_vertex_pushed_over_its_neighbours_is_unfolded_back_onto_the_sphere() {
        // Unfolding leaves no triangle folded and every vertex on the sphere.
        let mut s = pushed_icosphere();
        assert!(folded_vertices(&s).len() >= 9, "the push folds triangles");
        let off = unfold_onto_the_sphere(&mut s);
        assert!(folded_vertices(&s).is_empty(), "still folded: {:?}", folded_vertices(&s));
        assert!(off < 1e-3, "a vertex {off} off the sphere");
    }

    #[test]
    fn a_fold_whose_corner_normals_turned_with_it_is_unfolded_too() {
        // As above, but every vertex's normal is its faces' mean, as a fit's normal turns with a
        // fold: the corners' normals no longer tell the folded triangles, their dihedral angles do.
        let mut s = pushed_icosphere();
        let mut normals = vec![Vec3::ZERO; s.positions.len()];
        for t in &s.triangles {
            let [a, b, c] = t.map(|v| s.positions[v as usize]);
            for &v in t {
                normals[v as usize] += (b - a).cross(c - a);
            }
        }
        s.normals = normals.into_iter().map(Vec3::normalize_or_zero).collect();
        let off = unfold_onto_the_sphere(&mut s);
        let left = folded_or_creased_vertices(&s, &crate::topology::adjacent_face_pairs(&s.triangles));
        assert!(left.is_empty(), "still folded: {left:?}");
        assert!(off < 1e-3, "a vertex {off} off the sphere");
    }
}
