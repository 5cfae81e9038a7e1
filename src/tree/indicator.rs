//! The height-field indicator k(Sᵢ) that turns a V-node into a T-node, and the T-node's frame
//! (paper §3.2).

use super::{Frame, TreeSample};
use crate::quadric::CellStats;
use glam::{DVec3, Vec2, Vec3};

/// k(Sᵢ): true when the samples can be seen as a height field over the plane through their
/// centroid `c` with normal n̄ (the normalised average normal):
/// every nⱼ·n̄ > d_a (normal cone), and max |(pⱼ − c)·n̄| < d_d · max ‖pₖ − c‖ + `allowance`
/// (displacement; the allowance is for the samples' noise).
/// Samples with a zero normal carry no orientation and are left out of the cone test.
///
/// `reach` bounds every ‖pₖ − c‖ from above (the distance from c to the cell's farthest corner,
/// with a margin for rounding), so a single height beyond d_d · reach decides the test: the pass
/// stops at the first sample that fails either condition, and the result is the same as the
/// full test's.
pub(super) fn is_height_field(
    samples: &[TreeSample],
    centroid: Vec3,
    mean_normal: DVec3,
    reach: f32,
    d_a: f32,
    d_d: f32,
    allowance: f32,
) -> bool {
    if mean_normal.length() < 1e-6 {
        return false; // normals cancel out: no plane to project on
    }
    let n = mean_normal.normalize().as_vec3();
    let too_high = d_d * reach + allowance;
    let mut max_height = 0.0f32;
    let mut max_radius_sq = 0.0f32;
    for s in samples {
        let d = s.position - centroid;
        let h = d.dot(n).abs();
        if h > too_high || (s.normal.dot(n) <= d_a && s.normal != Vec3::ZERO) {
            return false;
        }
        max_height = max_height.max(h);
        max_radius_sq = max_radius_sq.max(d.length_squared());
    }
    // All samples at one point: trivially flat.
    max_radius_sq == 0.0 || max_height < d_d * max_radius_sq.sqrt() + allowance
}

/// An upper bound of the distance from `p` (inside the cube `center ± half`) to any point of
/// the cube: the distance to its farthest corner, enlarged for rounding.
pub(super) fn reach(p: Vec3, center: Vec3, half: f32) -> f32 {
    ((p - center).abs() + half).length() * (1.0 + 1e-3)
}

/// The T-node frame: n = the average normal; u, v = the normalised projections onto the plane
/// of the two eigenvectors of the normals' covariance least aligned with n. The normals vary
/// most along the direction of highest curvature, so u follows the surface's main direction
/// and the quadtree cells line up with the surface's anisotropy (the source of the VS-Tree's
/// better clustering). Also computes the bounding square of the projected samples.
pub(super) fn frame(samples: &[TreeSample], stats: &CellStats, origin: DVec3) -> Frame {
    let normal = stats.mean_normal().normalize_or(DVec3::Z);
    let (_, vectors) = stats.normal_covariance().eigen();
    // The eigenvector most aligned with n is dropped; of the other two, the one with the larger
    // eigenvalue (the eigenvectors come sorted by decreasing eigenvalue) becomes u.
    let most_aligned = (0..3).max_by(|&a, &b| vectors[a].dot(normal).abs().total_cmp(&vectors[b].dot(normal).abs()));
    let candidate = (0..3).find(|&i| Some(i) != most_aligned).map(|i| vectors[i]).unwrap_or(DVec3::X);
    let mut u = candidate - normal * candidate.dot(normal);
    if u.length() < 1e-6 {
        u = normal.any_orthonormal_vector();
    }
    let u = u.normalize();
    let v = normal.cross(u);
    let mut frame = Frame {
        origin: (stats.centroid() + origin).as_vec3(),
        normal: normal.as_vec3(),
        u: u.as_vec3(),
        v: v.as_vec3(),
        square_center: Vec2::ZERO,
        square_half: 0.0,
    };
    let (mut lo, mut hi) = (Vec2::splat(f32::MAX), Vec2::splat(f32::MIN));
    for s in samples {
        let q = frame.project(s.position);
        lo = lo.min(q);
        hi = hi.max(q);
    }
    frame.square_center = 0.5 * (lo + hi);
    // Slightly enlarged so samples on the border are inside, in proportion to the cell's own
    // scale (not the units'); never zero.
    let half = 0.5 * (hi - lo).max_element();
    frame.square_half = half * (1.0 + 1e-4) + 1e-7 * (half + frame.square_center.abs().max_element()) + 1e-30;
    frame
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(p: Vec3, n: Vec3) -> TreeSample {
        TreeSample { position: p, normal: n.normalize(), index: 0 }
    }

    fn stats_of(samples: &[TreeSample]) -> CellStats {
        let mut st = CellStats::default();
        for s in samples {
            st.add(s.position.as_dvec3(), s.normal.as_dvec3());
        }
        st
    }

    #[test]
    fn flat_patch_is_a_height_field_and_a_fold_is_not() {
        let flat: Vec<_> = (0..25).map(|i| sample(Vec3::new((i % 5) as f32, (i / 5) as f32, 0.0), Vec3::Z)).collect();
        let st = stats_of(&flat);
        assert!(is_height_field(&flat, st.centroid().as_vec3(), st.mean_normal(), f32::INFINITY, 0.0, 1.0 / 6.0, 0.0));
        let mut folded = flat.clone();
        folded.push(sample(Vec3::new(2.0, 2.0, 0.1), -Vec3::Z));
        let st = stats_of(&folded);
        assert!(!is_height_field(
            &folded,
            st.centroid().as_vec3(),
            st.mean_normal(),
            f32::INFINITY,
            0.0,
            1.0 / 6.0,
            0.0
        ));
    }

    #[test]
    fn displacement_test_rejects_a_tall_spike() {
        let mut s: Vec<_> = (0..25).map(|i| sample(Vec3::new((i % 5) as f32, (i / 5) as f32, 0.0), Vec3::Z)).collect();
        s.push(sample(Vec3::new(2.0, 2.0, 1.5), Vec3::Z));
        let st = stats_of(&s);
        assert!(!is_height_field(&s, st.centroid().as_vec3(), st.mean_normal(), f32::INFINITY, 0.0, 1.0 / 6.0, 0.0));
        assert!(is_height_field(&s, st.centroid().as_vec3(), st.mean_normal(), f32::INFINITY, 0.0, 1.0, 0.0));
    }

    #[test]
    fn stopping_early_on_a_tall_sample_gives_the_full_test_s_answer() {
        // Bumps of growing height on a patch filling the cube [0, 4]³: the bound from the cube's
        // corners only shortens the pass, never changes the answer.
        for bump in 0..40 {
            let s: Vec<_> = (0..25)
                .map(|i| {
                    let (x, y) = ((i % 5) as f32, (i / 5) as f32);
                    let z = 2.0 + 0.05 * bump as f32 * ((x - 2.0).powi(2) + (y - 2.0).powi(2)) / 8.0;
                    sample(Vec3::new(x, y, z), Vec3::new(2.0 - x, 2.0 - y, 20.0))
                })
                .collect();
            let st = stats_of(&s);
            let c = st.centroid().as_vec3();
            let r = reach(c, Vec3::splat(2.0), 2.0);
            for d_d in [0.0, 0.05, 1.0 / 6.0, 0.3, 1.0] {
                let full = is_height_field(&s, c, st.mean_normal(), f32::INFINITY, 0.0, d_d, 0.0);
                assert_eq!(is_height_field(&s, c, st.mean_normal(), r, 0.0, d_d, 0.0), full, "bump {bump}, d_d {d_d}");
            }
        }
    }

    #[test]
    fn frame_follows_the_curved_direction_of_a_cylinder() {
        // A cylinder patch around the y axis: normals vary along x, so u ≈ ±x and v ≈ ±y.
        let s: Vec<_> = (0..50)
            .map(|i| {
                let a = -0.45 + (i % 10) as f32 * 0.1;
                let y = (i / 10) as f32 * 0.2;
                let n = Vec3::new(a.sin(), 0.0, a.cos());
                sample(n * 3.0 + Vec3::Y * y, n)
            })
            .collect();
        let st = stats_of(&s);
        let f = frame(&s, &st, DVec3::ZERO);
        assert!(f.u.x.abs() > 0.99, "u = {}", f.u);
        assert!(f.v.y.abs() > 0.99, "v = {}", f.v);
        assert!((f.normal - Vec3::Z).length() < 1e-3);
        for t in &s {
            let q = f.project(t.position) - f.square_center;
            assert!(q.abs().max_element() <= f.square_half);
        }
    }
}
