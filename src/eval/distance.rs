//! Point-to-mesh, point-to-point-cloud and mesh-to-mesh distances.
//!
//! The searching is done by [`crate::spatial`]'s exact indexes.
//!
//! Conventions: distances are Euclidean, in the input's units, computed in `f32`. Anything
//! measured against an empty target (no usable triangles, no points) is `f32::INFINITY`; a query
//! point with a NaN coordinate gives NaN. Batch functions run in parallel and their output does
//! not depend on the thread count (each result depends on its own query only).

use crate::eval::shapes::sample_surface;
use crate::mesh::{Mesh, MAX_COORDINATE};
use crate::rng::stream_seed;
use crate::spatial::{KdTree, TriangleBvh};
use glam::Vec3;
use rayon::prelude::*;

/// Distance from each of `points` to the surface of `mesh` (its triangles), in parallel.
/// `f32::INFINITY` everywhere when the mesh has no usable triangles.
pub fn point_to_mesh_distances(points: &[Vec3], mesh: &Mesh) -> Vec<f32> {
    let bvh = TriangleBvh::new(mesh);
    points.par_iter().map(|&p| bvh.distance(p)).collect()
}

/// Distance from each of `points` to the nearest point of `cloud`, in parallel.
/// `f32::INFINITY` everywhere when `cloud` is empty. Points of `cloud` the index cannot hold
/// (not finite, or beyond [`MAX_COORDINATE`]) are left out.
pub fn point_to_points_distances(points: &[Vec3], cloud: &[Vec3]) -> Vec<f32> {
    let usable: Vec<Vec3> =
        cloud.iter().copied().filter(|p| p.is_finite() && p.abs().max_element() <= MAX_COORDINATE).collect();
    let index = KdTree::new(&usable).unwrap_or_default();
    points.par_iter().map(|&p| index.distance(p)).collect()
}

/// Summary of a set of distances.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DistanceStats {
    /// How many distances were summarised; all other fields are 0 when this is 0.
    pub count: usize,
    /// Arithmetic mean.
    pub mean: f32,
    /// Root mean square.
    pub rms: f32,
    /// Largest value.
    pub max: f32,
    /// 99th percentile by the nearest-rank method: the smallest value that at least 99% of the
    /// values do not exceed.
    pub p99: f32,
}

impl DistanceStats {
    /// Summarises `distances` (sums in double precision, in order, so the result is
    /// deterministic). Empty input gives all zeros with `count == 0`.
    pub fn from_distances(distances: &[f32]) -> DistanceStats {
        let count = distances.len();
        if count == 0 {
            return DistanceStats::default();
        }
        let (mut sum, mut sum_squares, mut max) = (0.0f64, 0.0f64, f32::NEG_INFINITY);
        for &d in distances {
            let d64 = f64::from(d);
            sum += d64;
            sum_squares += d64 * d64;
            max = max.max(d);
        }
        let rank = (count * 99).div_ceil(100).max(1) - 1;
        let mut scratch = distances.to_vec();
        let (_, p99, _) = scratch.select_nth_unstable_by(rank, f32::total_cmp);
        DistanceStats {
            count,
            mean: (sum / count as f64) as f32,
            rms: (sum_squares / count as f64).sqrt() as f32,
            max,
            p99: *p99,
        }
    }
}

/// What distances are measured to: a mesh's triangles, or a set of points.
#[derive(Clone, Copy, Debug)]
pub enum Target<'a> {
    /// The surface of the mesh's triangles.
    Triangles(&'a Mesh),
    /// The nearest of these points.
    Points(&'a [Vec3]),
}

impl<'a> Target<'a> {
    /// The triangles of `mesh` when it has any, else its points.
    pub fn of(mesh: &'a Mesh) -> Target<'a> {
        if mesh.triangles.is_empty() {
            Target::Points(&mesh.positions)
        } else {
            Target::Triangles(mesh)
        }
    }

    /// Distance from each of `points` to this target, in parallel.
    pub fn distances(&self, points: &[Vec3]) -> Vec<f32> {
        match *self {
            Target::Triangles(mesh) => point_to_mesh_distances(points, mesh),
            Target::Points(cloud) => point_to_points_distances(points, cloud),
        }
    }
}

/// Statistics of the distances from each of `from` to `to` (one-sided).
pub fn one_sided(from: &[Vec3], to: Target) -> DistanceStats {
    DistanceStats::from_distances(&to.distances(from))
}

/// The points that stand for `mesh` in a two-sided comparison: `samples` points sampled
/// uniformly by area on its triangles, or all its points when it is a point cloud.
fn representative_points(mesh: &Mesh, samples: usize, seed: u64) -> Vec<Vec3> {
    if mesh.triangles.is_empty() {
        mesh.positions.clone()
    } else {
        sample_surface(mesh, samples, seed).positions
    }
}

/// One-sided statistics in both directions: (a to b, b to a).
///
/// Each side is represented by `samples_per_mesh` points sampled uniformly by area on its
/// surface (seeded from `seed`; the two sides use different streams) or, for a point cloud, by
/// all its points. Those points are measured to the other side's triangles, or to its points
/// when it is a cloud. A side with no representative points (empty, or zero area) gives
/// `count == 0` statistics in its direction, and measuring to it gives infinite distances.
pub fn two_sided(a: &Mesh, b: &Mesh, samples_per_mesh: usize, seed: u64) -> (DistanceStats, DistanceStats) {
    let from_a = representative_points(a, samples_per_mesh, stream_seed(seed, 0));
    let from_b = representative_points(b, samples_per_mesh, stream_seed(seed, 1));
    (one_sided(&from_a, Target::of(b)), one_sided(&from_b, Target::of(a)))
}

/// The symmetric Chamfer and Hausdorff distances between `a` and `b`, from [`two_sided`]:
/// chamfer = (mean(a to b) + mean(b to a)) / 2, the mean of the two one-sided mean distances
/// (not squared); hausdorff = max(max(a to b), max(b to a)), estimated on the samples. Both are 0
/// when neither side has points, and infinite when exactly one side is empty.
pub fn chamfer_and_hausdorff(a: &Mesh, b: &Mesh, samples_per_mesh: usize, seed: u64) -> (f32, f32) {
    let (ab, ba) = two_sided(a, b, samples_per_mesh, seed);
    (0.5 * (ab.mean + ba.mean), ab.max.max(ba.max))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn empty_targets_and_stats() {
        let p = [Vec3::ONE];
        assert_eq!(point_to_mesh_distances(&p, &Mesh::default()), vec![f32::INFINITY]);
        assert_eq!(point_to_points_distances(&p, &[]), vec![f32::INFINITY]);
        assert_eq!(point_to_points_distances(&p, &[Vec3::NAN, Vec3::ZERO]), vec![3f32.sqrt()]);

        assert_eq!(DistanceStats::from_distances(&[]), DistanceStats::default());
        let values: Vec<f32> = (1..=200).map(|i| i as f32).collect();
        let s = DistanceStats::from_distances(&values);
        assert_eq!((s.count, s.max, s.p99), (200, 200.0, 198.0));
        assert!((s.mean - 100.5).abs() < 1e-4);
        let s = DistanceStats::from_distances(&[3.0]);
        assert_eq!((s.mean, s.rms, s.max, s.p99), (3.0, 3.0, 3.0, 3.0));

        let cloud = Mesh::from_points(vec![Vec3::ZERO, Vec3::X * 10.0], None);
        assert_eq!(chamfer_and_hausdorff(&Mesh::default(), &Mesh::default(), 10, 1), (0.0, 0.0));
        let (c, h) = chamfer_and_hausdorff(&cloud, &Mesh::default(), 10, 1);
        assert!(c.is_infinite() && h.is_infinite());
        let shifted = Mesh::from_points(vec![Vec3::Y, Vec3::X * 10.0 + Vec3::Y * 3.0], None);
        let (c, h) = chamfer_and_hausdorff(&cloud, &shifted, 10, 1);
        assert!((c - 2.0).abs() < 1e-6 && (h - 3.0).abs() < 1e-6, "{c} {h}");
    }
}
