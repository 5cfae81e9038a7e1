//! Small dense linear algebra in `f64`: symmetric 3x3 eigen-decomposition, by Jacobi rotations
//! (for solving quadrics and fitting planes) and in closed form for the smallest eigenvector
//! (for PCA of normals). Precision matters here, so nothing is `f32`.

use glam::{DMat3, DVec3};

/// A symmetric 3x3 matrix stored as its upper triangle: `[xx, xy, xz, yy, yz, zz]`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sym3(pub [f64; 6]);

impl Sym3 {
    /// `v vᵀ`.
    pub fn outer(v: DVec3) -> Sym3 {
        Sym3([v.x * v.x, v.x * v.y, v.x * v.z, v.y * v.y, v.y * v.z, v.z * v.z])
    }

    pub fn add(&mut self, other: &Sym3) {
        for (a, b) in self.0.iter_mut().zip(other.0) {
            *a += b;
        }
    }

    pub fn scaled(&self, s: f64) -> Sym3 {
        Sym3(self.0.map(|a| a * s))
    }

    pub fn sub(&self, other: &Sym3) -> Sym3 {
        let mut out = *self;
        for (a, b) in out.0.iter_mut().zip(other.0) {
            *a -= b;
        }
        out
    }

    pub fn mul_vec(&self, v: DVec3) -> DVec3 {
        let [xx, xy, xz, yy, yz, zz] = self.0;
        DVec3::new(xx * v.x + xy * v.y + xz * v.z, xy * v.x + yy * v.y + yz * v.z, xz * v.x + yz * v.y + zz * v.z)
    }

    /// Eigenvalues (descending) and the matching unit eigenvectors (as matrix columns),
    /// by cyclic Jacobi rotations: robust and exact enough for 3x3, and deterministic.
    pub fn eigen(&self) -> ([f64; 3], [DVec3; 3]) {
        let [xx, xy, xz, yy, yz, zz] = self.0;
        let mut a = [[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]];
        let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        for _sweep in 0..32 {
            let off = a[0][1].abs() + a[0][2].abs() + a[1][2].abs();
            let scale = a[0][0].abs() + a[1][1].abs() + a[2][2].abs();
            if off <= 1e-15 * scale || off == 0.0 {
                break;
            }
            for (p, q) in [(0, 1), (0, 2), (1, 2)] {
                if a[p][q] == 0.0 {
                    continue;
                }
                // The rotation angle that zeroes a[p][q] (Golub & Van Loan, sym.schur2).
                let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for row in a.iter_mut() {
                    let (akp, akq) = (row[p], row[q]);
                    row[p] = c * akp - s * akq;
                    row[q] = s * akp + c * akq;
                }
                let (row_p, row_q) = (a[p], a[q]);
                for k in 0..3 {
                    a[p][k] = c * row_p[k] - s * row_q[k];
                    a[q][k] = s * row_p[k] + c * row_q[k];
                }
                for row in v.iter_mut() {
                    let (vkp, vkq) = (row[p], row[q]);
                    row[p] = c * vkp - s * vkq;
                    row[q] = s * vkp + c * vkq;
                }
            }
        }
        let mut order = [0usize, 1, 2];
        order.sort_by(|&i, &j| a[j][j].total_cmp(&a[i][i]));
        let values = order.map(|i| a[i][i]);
        let vectors = order.map(|i| DVec3::new(v[0][i], v[1][i], v[2][i]).normalize_or_zero());
        (values, vectors)
    }

    /// The eigenvalues (descending) and the unit eigenvector of the smallest: for a
    /// covariance, the direction of least spread.
    ///
    /// Closed form (the trigonometric solution of the characteristic cubic, then the eigenvector
    /// as the largest cross product of two rows of `A - λI`), about five times faster than the
    /// Jacobi iteration of [`Sym3::eigen`]. The eigenvector's error grows like rounding / (gap to
    /// the middle eigenvalue), so when that gap is below 1e-6 of the largest eigenvalue (for a
    /// covariance, a neighbourhood that is nearly a line or a ball, where the answer is unstable
    /// anyway) the Jacobi iteration decides instead.
    pub fn eigen_smallest(&self) -> ([f64; 3], DVec3) {
        let [xx, xy, xz, yy, yz, zz] = self.0;
        let q = (xx + yy + zz) / 3.0;
        let (a, b, c) = (xx - q, yy - q, zz - q);
        let p2 = (a * a + b * b + c * c + 2.0 * (xy * xy + xz * xz + yz * yz)) / 6.0;
        if p2 > 0.0 {
            let p = p2.sqrt();
            // det((A - qI) / p) / 2 = cos(3 phi).
            let det = a * (b * c - yz * yz) - xy * (xy * c - yz * xz) + xz * (xy * yz - b * xz);
            let phi = (det / (2.0 * p2 * p)).clamp(-1.0, 1.0).acos() / 3.0;
            let largest = q + 2.0 * p * phi.cos();
            let smallest = q + 2.0 * p * (phi + 2.0 * std::f64::consts::FRAC_PI_3).cos();
            let middle = 3.0 * q - largest - smallest;
            if middle - smallest > 1e-6 * largest {
                let rows = [
                    DVec3::new(xx - smallest, xy, xz),
                    DVec3::new(xy, yy - smallest, yz),
                    DVec3::new(xz, yz, zz - smallest),
                ];
                let best = [rows[0].cross(rows[1]), rows[0].cross(rows[2]), rows[1].cross(rows[2])]
                    .into_iter()
                    .max_by(|u, v| u.length_squared().total_cmp(&v.length_squared()))
                    .unwrap_or_default();
                if let Some(normal) = best.try_normalize() {
                    return ([largest, middle, smallest.max(0.0)], normal);
                }
            }
        }
        let (values, vectors) = self.eigen();
        (values, vectors[2])
    }

    pub fn to_mat3(self) -> DMat3 {
        let [xx, xy, xz, yy, yz, zz] = self.0;
        DMat3::from_cols(DVec3::new(xx, xy, xz), DVec3::new(xy, yy, yz), DVec3::new(xz, yz, zz))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    #[test]
    fn eigen_reconstructs_the_matrix() {
        let m = Sym3([4.0, 1.0, -2.0, 3.0, 0.5, 1.0]);
        let (values, vectors) = m.eigen();
        assert!(values[0] >= values[1] && values[1] >= values[2]);
        for (lambda, v) in values.iter().zip(vectors) {
            let residual = m.mul_vec(v) - v * *lambda;
            assert!(residual.length() < 1e-10, "residual {residual}");
            assert!((v.length() - 1.0).abs() < 1e-12);
        }
        assert!(vectors[0].dot(vectors[1]).abs() < 1e-10);
        assert!(vectors[1].dot(vectors[2]).abs() < 1e-10);
    }

    #[test]
    fn eigen_of_diagonal_and_zero() {
        let (values, _) = Sym3([1.0, 0.0, 0.0, 3.0, 0.0, 2.0]).eigen();
        assert_eq!(values, [3.0, 2.0, 1.0]);
        let (values, vectors) = Sym3::default().eigen();
        assert_eq!(values, [0.0; 3]);
        assert!(vectors.iter().all(|v| (v.length() - 1.0).abs() < 1e-12));
    }

    #[test]
    fn eigen_smallest_agrees_with_jacobi() {
        let mut rng = Rng::new(1);
        for case in 0..20_000 {
            // Random frames with spreads from isotropic to nearly flat and nearly linear.
            let axis = |rng: &mut Rng| DVec3::new(rng.normal_f64(), rng.normal_f64(), rng.normal_f64()).normalize();
            let u = axis(&mut rng);
            let v = u.cross(axis(&mut rng)).normalize();
            let w = u.cross(v);
            let scale = 10f64.powi(case % 13 - 6);
            let s = [1.0, 10f64.powf(-4.0 * rng.f64()), 10f64.powf(-9.0 * rng.f64())];
            let mut cov = Sym3::default();
            for (e, spread) in [u, v, w].into_iter().zip(s) {
                cov.add(&Sym3::outer(e).scaled(spread * scale));
            }
            let (values, normal) = cov.eigen_smallest();
            let (want_values, want) = cov.eigen();
            let want = want[2];
            assert!(normal.dot(want).abs() > 1.0 - 1e-9, "{case}: {normal} vs {want}");
            for (a, b) in values.iter().zip(want_values) {
                assert!((a - b).abs() <= 1e-9 * want_values[0], "{values:?} {want_values:?}");
            }
        }
        // Isotropic and zero matrices fall back to Jacobi.
        assert_eq!(Sym3([2.0, 0.0, 0.0, 2.0, 0.0, 2.0]).eigen_smallest().0, [2.0; 3]);
        assert_eq!(Sym3::default().eigen_smallest().0, [0.0; 3]);
    }
}
