//! The surface over one quadtree leaf as a quadratic height field in its T-node's frame, fitted
//! to the leaf's samples by least squares.
//!
//! Refinement puts vertices onto the surface a leaf describes. A leaf's tangent plane through
//! its average sample misses a curved patch by up to its sag (the plane runs through the
//! patch's mean height, under a convex patch's middle and over its rim). A quadratic leaves an
//! error of the third order in the leaf's size, and still averages out the samples' noise: it
//! has six coefficients, a leaf holds tens of samples.

use crate::tree::{Frame, TreeSample};
use glam::{Vec2, Vec3};

/// Fewer samples than this leave a quadratic too free: the plane is used instead.
const MIN_SAMPLES: usize = 12;
/// A pivot below this share of the largest diagonal entry means the samples do not span the
/// leaf in both directions (a line of samples): no quadratic.
const MIN_PIVOT: f64 = 1e-6;

/// h(x, y) = c₀ + c₁x + c₂y + c₃x² + c₄xy + c₅y², with (x, y) the plane coordinates relative to
/// `center`, in units of `half` (so the leaf's square is [-1, 1]²).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct QuadraticPatch {
    center: Vec2,
    half: f32,
    coefficients: [f32; 6],
}

fn basis(x: f64, y: f64) -> [f64; 6] {
    [1.0, x, y, x * x, x * y, y * y]
}

impl QuadraticPatch {
    /// The least-squares quadratic through `samples` over the square `center ± half` of
    /// `frame`'s plane; `None` when the samples are too few or too thin to determine one.
    pub fn fit(samples: &[TreeSample], frame: &Frame, center: Vec2, half: f32) -> Option<QuadraticPatch> {
        if samples.len() < MIN_SAMPLES || half <= 0.0 {
            return None;
        }
        let mut normal_matrix = [[0.0f64; 6]; 6];
        let mut rhs = [0.0f64; 6];
        for s in samples {
            let q = (frame.project(s.position) - center) / half;
            let phi = basis(f64::from(q.x), f64::from(q.y));
            let h = f64::from(frame.height(s.position));
            for i in 0..6 {
                rhs[i] += phi[i] * h;
                for j in 0..6 {
                    normal_matrix[i][j] += phi[i] * phi[j];
                }
            }
        }
        let coefficients = solve(normal_matrix, rhs)?;
        Some(QuadraticPatch { center, half, coefficients: coefficients.map(|c| c as f32) })
    }

    /// The patch's height at plane coordinates `uv` (clamped into the leaf's square: beyond it
    /// a quadratic is an extrapolation).
    pub fn height_at(&self, uv: Vec2) -> f32 {
        let q = ((uv - self.center) / self.half).clamp(Vec2::splat(-1.0), Vec2::splat(1.0));
        let c = &self.coefficients;
        c[0] + c[1] * q.x + c[2] * q.y + c[3] * q.x * q.x + c[4] * q.x * q.y + c[5] * q.y * q.y
    }

    /// `p` moved along `frame`'s normal onto the patch.
    pub fn project(&self, frame: &Frame, p: Vec3) -> Vec3 {
        p + frame.normal * (self.height_at(frame.project(p)) - frame.height(p))
    }
}

/// Solves the symmetric system `a x = b` by Gaussian elimination with partial pivoting; `None`
/// when it is (nearly) singular.
pub(super) fn solve(mut a: [[f64; 6]; 6], mut b: [f64; 6]) -> Option<[f64; 6]> {
    let scale = (0..6).map(|i| a[i][i].abs()).fold(0.0, f64::max);
    if !(scale > 0.0 && scale.is_finite()) {
        return None;
    }
    for col in 0..6 {
        let pivot = (col..6).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[pivot][col].abs() < MIN_PIVOT * scale {
            return None;
        }
        a.swap(col, pivot);
        b.swap(col, pivot);
        let pivot_row = a[col];
        for row in col + 1..6 {
            let f = a[row][col] / pivot_row[col];
            for (x, p) in a[row][col..].iter_mut().zip(&pivot_row[col..]) {
                *x -= f * p;
            }
            b[row] -= f * b[col];
        }
    }
    let mut x = [0.0f64; 6];
    for row in (0..6).rev() {
        let tail: f64 = (row + 1..6).map(|k| a[row][k] * x[k]).sum();
        x[row] = (b[row] - tail) / a[row][row];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame() -> Frame {
        Frame {
            origin: Vec3::ZERO,
            normal: Vec3::Z,
            u: Vec3::X,
            v: Vec3::Y,
            square_center: Vec2::ZERO,
            square_half: 1.0,
        }
    }

    fn grid_samples(height: impl Fn(f32, f32) -> f32) -> Vec<TreeSample> {
        (0..49)
            .map(|i| {
                let (x, y) = ((i % 7) as f32 / 3.0 - 1.0, (i / 7) as f32 / 3.0 - 1.0);
                TreeSample { position: Vec3::new(x, y, height(x, y)), normal: Vec3::Z, index: i }
            })
            .collect()
    }

    #[test]
    fn a_quadratic_surface_is_recovered_where_the_plane_misses_its_sag() {
        // A sphere cap of radius 4 over the square [-1, 1]²: sag about 1/4 at the corners.
        let cap = |x: f32, y: f32| (16.0 - x * x - y * y).sqrt() - 4.0;
        let samples = grid_samples(cap);
        let patch = QuadraticPatch::fit(&samples, &frame(), Vec2::ZERO, 1.0).expect("a patch");
        let mean_height = samples.iter().map(|s| s.position.z).sum::<f32>() / samples.len() as f32;
        for (x, y) in [(0.0, 0.0), (0.5, -0.5), (0.9, 0.9), (-1.0, 0.3)] {
            let exact = cap(x, y);
            let quadratic = patch.height_at(Vec2::new(x, y));
            assert!((quadratic - exact).abs() < 3e-3, "({x}, {y}): {quadratic} vs {exact}");
            // The plane through the mean height misses by far more somewhere.
            if x == 0.0 {
                assert!((mean_height - exact).abs() > 0.05);
            }
        }
        let p = patch.project(&frame(), Vec3::new(0.5, 0.5, 3.0));
        assert!((p - Vec3::new(0.5, 0.5, cap(0.5, 0.5))).length() < 3e-3, "{p}");
    }

    #[test]
    fn too_few_or_collinear_samples_give_no_patch() {
        let samples = grid_samples(|_, _| 0.0);
        assert!(QuadraticPatch::fit(&samples[..MIN_SAMPLES - 1], &frame(), Vec2::ZERO, 1.0).is_none());
        let line: Vec<TreeSample> = samples.iter().copied().filter(|s| s.position.y == -1.0).collect();
        assert!(QuadraticPatch::fit(&line, &frame(), Vec2::ZERO, 1.0).is_none());
        // A line of samples repeated: enough samples, still only one direction.
        let thick_line: Vec<TreeSample> = line.iter().cycle().take(30).copied().collect();
        assert!(QuadraticPatch::fit(&thick_line, &frame(), Vec2::ZERO, 1.0).is_none());
        assert!(QuadraticPatch::fit(&samples, &frame(), Vec2::ZERO, 0.0).is_none());
    }
}
