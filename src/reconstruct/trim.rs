//! Stage 4: an open output trimmed back to its samples: the polygonisation carries the
//! surface past the last samples by up to the support's reach.

use super::lookup::Lookup;
use super::{adjacency, renumber_used_vertices, support};
use crate::mesh::Mesh;
use crate::progress::Threads;
use crate::spatial::KdTree;
use crate::topology;
use glam::Vec3;
use rayon::prelude::*;

/// An open output's border is cut back to this many sample spacings from the samples (see
/// [`border`]): the samples cannot place a border more finely than their spacing, and within
/// one spacing of the last samples the cut would wander with each gap between them.
pub(super) const BORDER_TRIM: f32 = 2.0;
/// Bisection steps when a border corner slides back (see [`border`]): to 1/256 of its edge.
const BORDER_SLIDE_STEPS: usize = 8;

/// Trims an open output: an explicit `trim` (in `grid_cell`s) removes every face farther than
/// it from the samples; otherwise the border is cut back to [`BORDER_TRIM`] sample spacings
/// past the last samples. How many faces went.
pub(super) fn open_output(mesh: &mut Mesh, near: &Lookup, trim: f32, grid_cell: f32, threads: &Threads) -> usize {
    if trim > 0.0 {
        far_faces(mesh, near.index(), trim * grid_cell, threads)
    } else {
        border(mesh, near.index(), BORDER_TRIM * near.spacing, threads)
    }
}

/// Removes the faces whose centroid is farther than `distance` from every sample; how many.
fn far_faces(mesh: &mut Mesh, samples: &KdTree, distance: f32, threads: &Threads) -> usize {
    let far: Vec<bool> = threads.run(|| {
        mesh.triangles
            .par_iter()
            .map(|t| {
                let centre = t.iter().map(|&v| mesh.positions[v as usize]).sum::<Vec3>() / 3.0;
                !samples.any_within(centre, distance)
            })
            .collect()
    });
    let before = mesh.triangles.len();
    remove_faces(mesh, &far);
    before - mesh.triangles.len()
}

/// Cuts an open output's border back to `distance` from the samples; how many faces went.
/// The polygonisation carries the border past the last samples by up to the support's reach.
/// Faces whose corners are all farther than `distance` go where they reach the border
/// (farther inside, the surface only strays from sparse or noisy samples, and a hole there
/// would be wrong); then each border corner still farther slides along the surface towards
/// its near neighbours until it is `distance` away. Removing faces alone leaves the border
/// ragged by a face's size, which is many sample spacings on a smooth, densely sampled part.
fn border(mesh: &mut Mesh, samples: &KdTree, distance: f32, threads: &Threads) -> usize {
    let near = |p: Vec3| samples.any_within(p, distance);
    let vertex_near: Vec<bool> = threads.run(|| mesh.positions.par_iter().map(|&p| near(p)).collect());
    let far: Vec<bool> = mesh.triangles.iter().map(|t| t.iter().all(|&v| !vertex_near[v as usize])).collect();
    let (region, regions) = support::regions(mesh, &far);
    let cut: Vec<bool> = region.iter().map(|&r| r != u32::MAX && regions[r as usize].touches_border).collect();
    let before = mesh.triangles.len();
    let kept = remove_faces(mesh, &cut);
    let removed = before - mesh.triangles.len();
    let vertex_near: Vec<bool> = kept.iter().map(|&v| vertex_near[v]).collect();
    let border = topology::border_vertices(&mesh.triangles, mesh.positions.len());
    let neighbours = adjacency::Rows::neighbours(&mesh.triangles, mesh.positions.len());
    let moved: Vec<(usize, Vec3)> = threads.run(|| {
        (0..mesh.positions.len())
            .into_par_iter()
            .filter(|&v| border[v] && !vertex_near[v])
            .filter_map(|v| {
                let inner: Vec<Vec3> = neighbours
                    .of(v as u32)
                    .iter()
                    .filter(|&&w| vertex_near[w as usize])
                    .map(|&w| mesh.positions[w as usize])
                    .collect();
                if inner.is_empty() {
                    return None;
                }
                let (from, to) = (mesh.positions[v], inner.iter().sum::<Vec3>() / inner.len() as f32);
                // Bisection on the segment for where it comes within `distance`.
                let (mut out, mut inside) = (0.0f32, 1.0f32);
                for _ in 0..BORDER_SLIDE_STEPS {
                    let mid = 0.5 * (out + inside);
                    if near(from.lerp(to, mid)) {
                        inside = mid;
                    } else {
                        out = mid;
                    }
                }
                Some((v, from.lerp(to, inside)))
            })
            .collect()
    });
    for (v, p) in moved {
        mesh.positions[v] = p;
    }
    removed
}

/// Removes the faces `gone` marks, and the vertices left unused; the old index of each vertex
/// kept.
fn remove_faces(mesh: &mut Mesh, gone: &[bool]) -> Vec<usize> {
    let mut g = gone.iter();
    mesh.triangles.retain(|_| !*g.next().unwrap_or(&false));
    let kept = renumber_used_vertices(&mut mesh.triangles, mesh.positions.len());
    mesh.positions = kept.iter().map(|&v| mesh.positions[v]).collect();
    mesh.normals = mesh.normals.as_ref().map(|n| kept.iter().map(|&v| n[v]).collect());
    kept
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_border_is_cut_back_to_the_samples_not_a_face_short_of_them() {
        // Faces 0.1 wide over [0, 1]², samples on x <= 0.43 only: the border goes to 0.45
        // (0.02 past the samples) on the whole right side, where removing faces alone would
        // leave it at 0.4 or 0.5.
        let mut mesh = crate::eval::shapes::square_grid(10);
        let samples: Vec<Vec3> =
            (0..=43).flat_map(|i| (0..=100).map(move |j| Vec3::new(i as f32 * 0.01, j as f32 * 0.01, 0.0))).collect();
        let near = KdTree::new(&samples).unwrap();
        let removed = border(&mut mesh, &near, 0.02, &Threads::new(1).unwrap());
        assert_eq!(removed, 100, "the five columns of faces wholly past 0.45");
        let right = mesh.positions.iter().map(|p| p.x).fold(0.0f32, f32::max);
        assert!((right - 0.45).abs() < 0.005, "border at x = {right}");
        let on_border = mesh.positions.iter().filter(|p| p.x > 0.44).count();
        assert_eq!(on_border, 11, "every vertex of the column past the samples slid back");
    }
}
