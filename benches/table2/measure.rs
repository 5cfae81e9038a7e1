//! vstree's timed reconstructions, and the figures every method's output gets: size, distances
//! to the input points, valence, angles, topology.

use crate::common::distance::{between, Distances};
use crate::common::reconstruction::smallest_angle;
pub use crate::common::reconstruction::{reconstruction, Stages};
use glam::Vec3;
use vstree::eval::distance::Target;
use vstree::{topology, Mesh};

/// Triangles whose smallest angle is below this many degrees count as badly shaped.
pub const SMALL_ANGLE_DEGREES: f64 = 20.0;

/// The figures of one output mesh.
#[derive(Clone, Debug, Default)]
pub struct Quality {
    /// Vertices used by a triangle.
    pub vertices: usize,
    pub triangles: usize,
    /// To and from the input points, relative to their bounding-box diagonal.
    pub distances: Distances,
    /// Share of the used vertices with exactly six neighbours.
    pub valence6: f64,
    /// Share of the triangles with an angle below [`SMALL_ANGLE_DEGREES`] (degenerate ones
    /// included).
    pub small_angles: f64,
    pub watertight: bool,
    pub genus: Option<u32>,
    pub components: usize,
    pub boundary_edges: usize,
}

/// [`Quality`] of `mesh` against the input `points` (box diagonal `diagonal`).
pub fn quality(mesh: &Mesh, points: &[Vec3], diagonal: f32) -> Quality {
    let report = topology::analyze(mesh);
    let used: Vec<u32> = vstree::eval::figures::valences(mesh).into_iter().filter(|&v| v > 0).collect();
    let six = used.iter().filter(|&&v| v == 6).count();
    let small = mesh.triangles.iter().filter(|t| smallest_angle(mesh, t) < SMALL_ANGLE_DEGREES).count();
    Quality {
        vertices: report.vertices,
        triangles: mesh.triangles.len(),
        distances: between(mesh, Target::Points(points), points, diagonal),
        valence6: six as f64 / used.len().max(1) as f64,
        small_angles: small as f64 / mesh.triangles.len().max(1) as f64,
        watertight: report.is_watertight(),
        genus: report.genus(),
        components: report.components,
        boundary_edges: report.boundary_edges,
    }
}
