//! The figures every method's output gets against the ground truth, by the same code: size,
//! topology, distances to the true mesh, angles, valence, folds, and for open inputs how far
//! the output strays from the samples.

use crate::common::distance::{between, Distances};
use crate::common::reconstruction::smallest_angle;
use crate::inputs::Truth;
use glam::Vec3;
use rayon::prelude::*;
use vstree::eval::distance::Target;
use vstree::spatial::KdTree;
use vstree::{topology, Mesh};

pub use crate::common::folds::{folds, FOLD_DEGREES};
/// The sample spacing is the median nearest-neighbour distance over this many samples, evenly
/// spread.
const SPACING_SAMPLES: usize = 20_000;

/// The figures of one output mesh.
#[derive(Clone, Debug, Default)]
pub struct Quality {
    /// Vertices used by a triangle.
    pub vertices: usize,
    /// To and from the true mesh, relative to its bounding-box diagonal.
    pub distances: Distances,
    /// Share of the used vertices with exactly six neighbours.
    pub valence6: f64,
    /// Shares of the triangles with an angle under 10 and under 20 degrees (degenerate ones
    /// included).
    pub under10: f64,
    pub under20: f64,
    /// Edges whose two faces' normals differ by more than [`FOLD_DEGREES`].
    pub folds: usize,
    /// `None` unless the output is a closed manifold.
    pub genus: Option<u32>,
    pub components: usize,
    pub boundary_edges: usize,
    /// For open inputs: the largest distance from a face's centroid to the nearest sample, in
    /// sample spacings.
    pub farthest_face: Option<f64>,
}

impl Quality {
    /// The output has the truth's genus (closed truths only).
    pub fn genus_right(&self, truth_genus: Option<u32>) -> bool {
        truth_genus.is_some() && self.genus == truth_genus
    }

    pub fn is_open(&self) -> bool {
        self.boundary_edges > 0
    }
}

/// The samples of an input, for the open inputs' figure.
pub struct Samples {
    bvh: KdTree,
    /// Median nearest-neighbour distance.
    pub spacing: f32,
}

impl Samples {
    pub fn new(points: &[Vec3]) -> Samples {
        let bvh = KdTree::new(points).expect("the input passed the reconstruction's checks");
        let step = (points.len() / SPACING_SAMPLES).max(1);
        let mut gaps: Vec<f64> = (0..points.len())
            .into_par_iter()
            .step_by(step)
            .filter_map(|i| bvh.nearest_among(points[i], |j| j as usize != i).map(|(d, _)| f64::from(d)))
            .collect();
        gaps.sort_by(f64::total_cmp);
        let spacing = gaps.get(gaps.len() / 2).copied().unwrap_or(0.0) as f32;
        Samples { bvh, spacing }
    }
}

/// [`Quality`] of `output` (in the truth's frame) against `truth`; `samples` for open inputs.
pub fn quality(output: &Mesh, truth: &Truth, samples: Option<&Samples>) -> Quality {
    let report = topology::analyze(output);
    let used: Vec<u32> = vstree::eval::figures::valences(output).into_iter().filter(|&v| v > 0).collect();
    let six = used.iter().filter(|&&v| v == 6).count();
    let angles: Vec<f64> = output.triangles.par_iter().map(|t| smallest_angle(output, t)).collect();
    let share = |limit: f64| angles.iter().filter(|&&a| a < limit).count() as f64 / angles.len().max(1) as f64;
    let farthest_face = samples.filter(|s| s.spacing > 0.0 && !output.triangles.is_empty()).map(|s| {
        let p = &output.positions;
        let far = output
            .triangles
            .par_iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| p[i as usize]);
                s.bvh.distance((a + b + c) / 3.0)
            })
            .reduce(|| 0.0, f32::max);
        f64::from(far / s.spacing)
    });
    Quality {
        vertices: report.vertices,
        distances: between(output, Target::Triangles(&truth.mesh), &truth.points, truth.diagonal),
        valence6: six as f64 / used.len().max(1) as f64,
        under10: share(10.0),
        under20: share(20.0),
        folds: folds(output),
        genus: report.genus(),
        components: report.components,
        boundary_edges: report.boundary_edges,
        farthest_face,
    }
}
