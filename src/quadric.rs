//! Running sums over a set of oriented samples (position + normal). From them come everything
//! a cell needs: centroid, average normal, the normals' covariance (for the T-node frame), the
//! L2 quadric error and its minimiser (the cluster representative), and the L2,1 normal
//! deviation. Sums are `f64` over positions taken relative to a fixed origin, so cancellation
//! stays far below the thresholds users ask for.

use crate::linalg::Sym3;
use glam::DVec3;

/// Eigenvalues of the quadric's matrix below this fraction of the largest are treated as zero
/// when minimising: along those directions the samples' tangent planes do not pin the point
/// down, so it stays at the centroid (Lindstrom 2000; Schaefer & Warren 2003).
const QUADRIC_TRUNCATION: f64 = 0.1;

/// Sums of a sample set that make every per-cell figure O(1) once accumulated.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CellStats {
    pub count: u64,
    pub sum_p: DVec3,
    pub sum_n: DVec3,
    /// Σ n nᵀ: the quadric's matrix and the normals' second moment.
    pub nn: Sym3,
    /// Σ n (n·p).
    pub b: DVec3,
    /// Σ (n·p)².
    pub c: f64,
}

impl CellStats {
    /// Adds one sample; `p` relative to the tree's origin.
    #[inline]
    pub fn add(&mut self, p: DVec3, n: DVec3) {
        let d = n.dot(p);
        self.count += 1;
        self.sum_p += p;
        self.sum_n += n;
        self.nn.add(&Sym3::outer(n));
        self.b += n * d;
        self.c += d * d;
    }

    pub fn merge(&mut self, other: &CellStats) {
        self.count += other.count;
        self.sum_p += other.sum_p;
        self.sum_n += other.sum_n;
        self.nn.add(&other.nn);
        self.b += other.b;
        self.c += other.c;
    }

    pub fn centroid(&self) -> DVec3 {
        self.sum_p / self.count.max(1) as f64
    }

    /// The mean of the normals (not normalised: its length says how much they agree).
    pub fn mean_normal(&self) -> DVec3 {
        self.sum_n / self.count.max(1) as f64
    }

    /// Σ (n·(x − p))²: the sum of squared distances from `x` to the samples' tangent planes.
    pub fn quadric_at(&self, x: DVec3) -> f64 {
        (x.dot(self.nn.mul_vec(x)) - 2.0 * self.b.dot(x) + self.c).max(0.0)
    }

    /// The point that minimises the quadric, solved around the centroid with a truncated
    /// pseudo-inverse, so a singular quadric (a flat or cylindrical cell) falls back to the
    /// centroid along the directions it leaves free.
    pub fn quadric_minimizer(&self) -> DVec3 {
        let m = self.centroid();
        let (values, vectors) = self.nn.eigen();
        let residual = self.b - self.nn.mul_vec(m);
        let mut x = m;
        if values[0] > 0.0 {
            for (lambda, v) in values.iter().zip(vectors) {
                if *lambda > QUADRIC_TRUNCATION * values[0] {
                    x += v * (v.dot(residual) / lambda);
                }
            }
        }
        x
    }

    /// [`CellStats::quadric_minimizer`] when the truncation would keep every direction, by a
    /// plain solve without the eigen-decomposition; `None` when that cannot be proved cheaply.
    /// The smallest eigenvalue must be above [`QUADRIC_TRUNCATION`] times the largest: the
    /// smallest is at least det / m₂ (m₂ the sum of the principal 2x2 minors, at least the
    /// product of the two largest) and the largest at most the trace, so det / m₂ > truncation
    /// × trace proves it. For the many trial points of edge collapses.
    pub fn quadric_minimizer_if_regular(&self) -> Option<DVec3> {
        let [xx, xy, xz, yy, yz, zz] = self.nn.0;
        let trace = xx + yy + zz;
        let minors = (xx * yy - xy * xy) + (xx * zz - xz * xz) + (yy * zz - yz * yz);
        let a = self.nn.to_mat3();
        let det = a.determinant();
        if trace > 0.0 && minors > 0.0 && det / minors > QUADRIC_TRUNCATION * trace {
            let m = self.centroid();
            return Some(m + a.inverse() * (self.b - self.nn.mul_vec(m)));
        }
        None
    }

    /// The L2 error: the quadric's value at its minimiser, i.e. the sum over the samples of the
    /// squared distance from the minimiser to each sample's tangent plane (absolute units,
    /// squared; the tree divides it by the squared bounding-box diagonal). Because it is a sum,
    /// a bound `e` on it also bounds every single sample's plane distance by √e.
    pub fn l2_error(&self) -> f64 {
        self.quadric_at(self.quadric_minimizer())
    }

    /// The L2,1 error (Cohen-Steiner, Alliez, Desbrun 2004): the mean of ‖nⱼ − n̂‖² over the
    /// samples, n̂ the normalised average normal. For unit normals that is 2(1 − ‖mean n‖):
    /// 0 for a flat cell, up to 4 for opposing normals. Unitless.
    ///
    /// Cohen-Steiner et al. weight each term by its area. Here every sample weighs the same,
    /// which is that weighting when the samples are spread evenly over the surface (clouds
    /// drawn by area, the vertices of an even mesh): point clouds carry no areas, and one
    /// weight per sample would cost every metric memory and time. On meshes with very uneven
    /// triangles, face-centre sampling with a fine bound comes closer.
    pub fn normal_deviation(&self) -> f64 {
        if self.count == 0 {
            return 0.0;
        }
        2.0 * (1.0 - self.mean_normal().length()).max(0.0)
    }

    /// Covariance of the normals: Σ n nᵀ / k − m mᵀ.
    pub fn normal_covariance(&self) -> Sym3 {
        let k = self.count.max(1) as f64;
        let m = self.mean_normal();
        self.nn.scaled(1.0 / k).sub(&Sym3::outer(m))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stats(samples: &[(DVec3, DVec3)]) -> CellStats {
        let mut s = CellStats::default();
        for (p, n) in samples {
            s.add(*p, n.normalize());
        }
        s
    }

    #[test]
    fn corner_of_a_cube_is_recovered() {
        // Three faces meeting at (1,1,1): the minimiser is the corner, the error zero.
        let s = stats(&[
            (DVec3::new(1.0, 0.2, 0.3), DVec3::X),
            (DVec3::new(0.1, 1.0, 0.7), DVec3::Y),
            (DVec3::new(0.4, 0.5, 1.0), DVec3::Z),
        ]);
        assert!((s.quadric_minimizer() - DVec3::ONE).length() < 1e-12);
        assert!(s.l2_error() < 1e-9);
    }

    #[test]
    fn the_fast_minimiser_is_the_truncated_one() {
        let corner = stats(&[
            (DVec3::new(1.0, 0.2, 0.3), DVec3::X),
            (DVec3::new(0.1, 1.0, 0.7), DVec3::new(0.1, 1.0, 0.0)),
            (DVec3::new(0.4, 0.5, 1.0), DVec3::new(0.0, 0.2, 1.0)),
        ]);
        let flat = stats(&[(DVec3::ZERO, DVec3::Z), (DVec3::X, DVec3::new(0.0, 0.05, 1.0)), (DVec3::Y, DVec3::Z)]);
        let crease = stats(&[(DVec3::ZERO, DVec3::Z), (DVec3::X, DVec3::Y), (DVec3::Y, DVec3::new(0.0, 1.0, 0.3))]);
        let x = corner.quadric_minimizer_if_regular().unwrap();
        assert!((x - corner.quadric_minimizer()).length() < 1e-9);
        assert_eq!((flat.quadric_minimizer_if_regular(), crease.quadric_minimizer_if_regular()), (None, None));
    }

    #[test]
    fn flat_cell_falls_back_to_centroid_in_plane() {
        let s = stats(&[
            (DVec3::new(0.0, 0.0, 2.0), DVec3::Z),
            (DVec3::new(1.0, 0.0, 2.0), DVec3::Z),
            (DVec3::new(0.0, 3.0, 2.0), DVec3::Z),
        ]);
        let x = s.quadric_minimizer();
        assert!((x - DVec3::new(1.0 / 3.0, 1.0, 2.0)).length() < 1e-12);
        assert_eq!(s.normal_deviation(), 0.0);
    }

    #[test]
    fn two_parallel_sheets_have_half_gap_error() {
        let s = stats(&[(DVec3::new(0.0, 0.0, 0.0), DVec3::Z), (DVec3::new(0.0, 0.0, 1.0), DVec3::Z)]);
        assert!((s.l2_error() - 0.5).abs() < 1e-12); // 2 × 0.5²
    }

    #[test]
    fn sphere_samples_have_radius_error_and_centre_minimiser() {
        let dirs = [DVec3::X, -DVec3::X, DVec3::Y, -DVec3::Y, DVec3::Z, -DVec3::Z];
        let s = stats(&dirs.map(|d| (d * 2.0, d)));
        assert!(s.quadric_minimizer().length() < 1e-12);
        assert!((s.l2_error() - 24.0).abs() < 1e-12); // 6 × 2²
        assert!((s.normal_deviation() - 2.0).abs() < 1e-12);
    }
}
