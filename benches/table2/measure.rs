//! vstree's timed reconstructions, and the figures every method's output gets: size, distances
//! to the input points, valence, angles, topology.

use crate::common::distance::{between, Distances};
use crate::common::stats::median;
use glam::Vec3;
use std::time::Instant;
use vstree::distance::Target;
use vstree::reconstruct::{reconstruct, ReconstructParams, ReconstructStats};
use vstree::{topology, Mesh, Progress};

/// Triangles whose smallest angle is below this many degrees count as badly shaped.
pub const SMALL_ANGLE_DEGREES: f64 = 20.0;

/// Seconds per stage of a reconstruction (medians over the runs, each stage on its own). Trimming
/// is off in the table (closed output), so it has no column.
#[derive(Clone, Copy, Debug, Default)]
pub struct Stages {
    pub normals: f64,
    pub tree: f64,
    /// The base mesh M0: implicit function, polygonisation, clustering at the T-layer.
    pub base: f64,
    pub refine: f64,
    /// The whole `reconstruct` call, timed outside it.
    pub total: f64,
}

/// vstree's reconstruction of one input.
pub struct Reconstruction {
    pub mesh: Mesh,
    /// The last run's figures (every run gives the same mesh).
    pub stats: ReconstructStats,
    pub seconds: Stages,
}

/// Reconstructs `cloud` `runs` times; the median time of each stage and the last output.
pub fn reconstruction(cloud: &Mesh, params: &ReconstructParams, runs: usize) -> vstree::Result<Reconstruction> {
    let mut times: [Vec<f64>; 5] = Default::default();
    let mut last = None;
    for _ in 0..runs.max(1) {
        let start = Instant::now();
        let (mesh, stats) = reconstruct(cloud, params, &mut Progress::none())?;
        let total = start.elapsed().as_secs_f64();
        let stages = [stats.seconds_normals, stats.seconds_tree, stats.seconds_base, stats.seconds_refine, total];
        for (t, s) in times.iter_mut().zip(stages) {
            t.push(s);
        }
        last = Some((mesh, stats)); // the previous run's output is dropped outside the timed span
    }
    let [normals, tree, base, refine, total] = times.map(|t| median(&t));
    let (mesh, stats) = last.expect("at least one run");
    Ok(Reconstruction { mesh, stats, seconds: Stages { normals, tree, base, refine, total } })
}

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
    let used: Vec<u32> = topology::valences(mesh).into_iter().filter(|&v| v > 0).collect();
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

/// The smallest angle of a triangle in degrees; 0 for a degenerate one (bad index, repeated
/// vertex, zero-length side).
fn smallest_angle(mesh: &Mesh, t: &[u32; 3]) -> f64 {
    let p = &mesh.positions;
    if t.iter().any(|&v| v as usize >= p.len()) {
        return 0.0;
    }
    let [a, b, c] = t.map(|v| p[v as usize].as_dvec3());
    let angle = |o: glam::DVec3, u: glam::DVec3, v: glam::DVec3| {
        let (u, v) = (u - o, v - o);
        let lengths = u.length() * v.length();
        if lengths > 0.0 {
            (u.dot(v) / lengths).clamp(-1.0, 1.0).acos().to_degrees()
        } else {
            0.0
        }
    };
    angle(a, b, c).min(angle(b, c, a)).min(angle(c, a, b))
}
