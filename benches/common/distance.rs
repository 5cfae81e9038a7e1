//! Distances between an output mesh and its input, relative to the input's bounding-box
//! diagonal, measured with `vstree::eval::distance` the same way for every method.

use glam::Vec3;
use vstree::eval::distance::{one_sided, Target};
use vstree::eval::shapes::sample_surface;
use vstree::Mesh;

/// Points sampled uniformly by area on an output's surface to measure its distance to the input.
pub const SURFACE_SAMPLES: usize = 200_000;
const SURFACE_SEED: u64 = 31;

/// Mean and max distance from an output to its input and back, over the input's diagonal.
/// `None` where a side is empty.
#[derive(Clone, Copy, Debug, Default)]
pub struct Distances {
    /// From [`SURFACE_SAMPLES`] points uniform on the output's surface to the input.
    pub out_in: Option<(f64, f64)>,
    /// From the input's points to the output's triangles: catches what the output lost
    /// (holes, thin parts).
    pub in_out: Option<(f64, f64)>,
}

impl Distances {
    /// Two-sided Chamfer distance: the mean of the two one-sided mean distances (not squared).
    pub fn chamfer(&self) -> Option<f64> {
        Some(0.5 * (self.out_in?.0 + self.in_out?.0))
    }

    /// Hausdorff distance, estimated on the samples: the larger of the two one-sided maxima.
    pub fn hausdorff(&self) -> Option<f64> {
        Some(self.out_in?.1.max(self.in_out?.1))
    }
}

/// [`Distances`] between `output` and an input given as `input` (its triangles, or its points)
/// and `input_points` (the points measured to the output), relative to `diagonal`.
pub fn between(output: &Mesh, input: Target, input_points: &[Vec3], diagonal: f32) -> Distances {
    let relative = |from: &[Vec3], to: Target| {
        let s = one_sided(from, to);
        (s.count > 0 && s.max.is_finite()).then(|| {
            let d = f64::from(diagonal);
            (f64::from(s.mean) / d, f64::from(s.max) / d)
        })
    };
    let on_output = sample_surface(output, SURFACE_SAMPLES, SURFACE_SEED).positions;
    Distances {
        out_in: relative(&on_output, input),
        in_out: if output.triangles.is_empty() { None } else { relative(input_points, Target::Triangles(output)) },
    }
}
