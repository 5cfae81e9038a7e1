//! Normals for point clouds: estimation where they are missing, consistent orientation where
//! they are not.
//!
//! **Estimation.** Each point's normal is the direction of least spread of its neighbourhood
//! (the point and its `k` nearest other points, from an exact k-d tree, [`crate::spatial::KdTree`]): the
//! eigenvector of the smallest eigenvalue of the neighbourhood's 3x3 covariance, in `f64`. Its
//! sign is arbitrary.
//!
//! **Orientation** (Hoppe, DeRose, Duchamp, McDonald, Stuetzle, "Surface reconstruction from
//! unorganized points", SIGGRAPH 1992, §3.3). Neighbouring points on a smooth surface have
//! nearly parallel normals, so a sign can travel from point to point. The symmetric graph of
//! each point's nearest neighbours (Hoppe's Riemannian graph) gets Hoppe's edge weights
//! `1 - |ni·nj|`, plus a term that keeps edges across thin gaps last (see
//! `Graph::sorted_edges`); its minimum spanning forest (Kruskal) propagates the sign along the
//! flattest paths first, where the decision "flip when `ni·nj < 0`" is least ambiguous, and
//! crosses creases and gaps last. Each connected component of the graph is oriented on its
//! own, and then given its global sign by the rule [`Orientation`] names.
//!
//! Everything runs in parallel except the spanning forest (union-find, linear time after a
//! linear-time bucket sort), and every result is the same for any thread count.

mod estimate;
mod orient;

use crate::error::{Error, Result};
use crate::mesh::{check_positions, Mesh};
use crate::progress::{Progress, Threads};
use estimate::{plane_through, Graph};
use glam::Vec3;

pub(crate) use estimate::refuse_flat;

/// Default neighbourhood size. Clean samples need few neighbours, but noisy scans need more:
/// on the 10 merged bunny range scans, normals within 10 degrees of the mesh reconstructed from
/// them were 75% with k = 10, 87% with 16, 91% with 24, while the time grows about linearly
/// with k and thin features blur. 16 is the compromise.
pub const DEFAULT_NEIGHBOURS: usize = 16;

/// Fewest neighbours a normal may be estimated from (a point and 3 others fit a plane).
pub const MIN_NEIGHBOURS: usize = 3;

/// Most neighbours (beyond this the neighbourhood is not local any more, and it gets slow).
pub const MAX_NEIGHBOURS: usize = 256;

/// How normals get their signs. Every rule but [`Orientation::Unoriented`] first makes the
/// normals consistent with Hoppe's spanning-tree propagation, then picks the sign of every
/// connected component of the neighbour graph as a whole.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Orientation {
    /// No orientation: estimated normals keep the arbitrary sign PCA gives them, and
    /// [`orient_normals`] leaves normals as they are.
    Unoriented,
    /// Hoppe's rule: the normal at each component's highest point (largest z) points up (+z);
    /// when it is horizontal, +x decides, then +y. Natural for terrain and for scans taken
    /// from above.
    Propagate,
    /// Each component keeps the sign most of its input normals already have. For given normals
    /// that are locally inconsistent but mostly right (e.g. `lion_takanawa.ply`). On freshly
    /// estimated normals the result's sign is arbitrary.
    PropagateMajority,
    /// Each component is turned to face outward: the sign that makes the flux of the field
    /// `p - c` through the oriented samples positive (`c` the component's centroid; each sample
    /// weighted by the area it covers). By the divergence theorem the flux through a closed
    /// surface is 3x its volume whatever its genus or concavity, so closed shapes come out
    /// outward; an open scan comes out facing its convex side, which for a scan of an object
    /// is the scanner's side. A component with no measurable flux (a flat patch) falls back to
    /// [`Orientation::Propagate`]'s rule. The default.
    #[default]
    PropagateOutward,
}

/// Parameters of normal estimation and orientation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NormalParams {
    /// Neighbours per point (the point itself not counted), in
    /// [`MIN_NEIGHBOURS`]`..=`[`MAX_NEIGHBOURS`]; default [`DEFAULT_NEIGHBOURS`]. A cloud with
    /// fewer than `neighbours + 1` (but at least 3) points uses all its other points.
    pub neighbours: usize,
    /// How signs are chosen; default [`Orientation::PropagateOutward`].
    pub orient: Orientation,
    /// [`ensure_normals`] only: re-orient normals the cloud already has with `orient`. By
    /// default (`false`) given normals are kept as they are.
    pub reorient_given: bool,
    /// Worker threads; 0 = all cores.
    pub threads: usize,
}

impl Default for NormalParams {
    fn default() -> Self {
        NormalParams {
            neighbours: DEFAULT_NEIGHBOURS,
            orient: Orientation::default(),
            reorient_given: false,
            threads: 0,
        }
    }
}

impl NormalParams {
    /// Checks `neighbours` (the thread count is checked when the threads are started).
    pub fn check(&self) -> Result<()> {
        crate::params::NORMALS_NEIGHBOURS.check(self.neighbours as f64, self.neighbours)
    }
}

/// What orientation did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OrientReport {
    /// Connected components of the neighbour graph, each oriented on its own.
    pub components: usize,
    /// Points in the largest component.
    pub largest_component: usize,
    /// Components the outward test could not decide (no measurable flux), oriented by
    /// Hoppe's +z rule instead.
    pub undecided_components: usize,
    /// Normals whose sign was changed.
    pub flipped: usize,
}

/// What [`ensure_normals`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct NormalsReport {
    /// Normals that were estimated (all of them when the cloud had none; the zero ones when
    /// only some were zero; 0 when the given normals were kept or only re-oriented).
    pub estimated: usize,
    /// Neighbours per point actually used (smaller than asked for tiny clouds).
    pub neighbours: usize,
    /// Estimated points whose neighbourhood spans no plane (all points equal or on a line);
    /// they took the normal of their nearest neighbour that has one.
    pub degenerate: usize,
    /// The orientation, when one was done.
    pub orient: Option<OrientReport>,
}

/// Estimates a unit normal for every point, oriented as `params.orient` says.
///
/// Errors: fewer than 3 points, a NaN or infinite coordinate (naming the point), all points
/// equal or on one line (no plane to fit), a bad parameter, or [`Error::Cancelled`]. Points on
/// one plane get that plane's normal, consistently signed. Duplicate points are fine.
pub fn estimate_normals(points: &[Vec3], params: &NormalParams, progress: &mut Progress) -> Result<Vec<Vec3>> {
    let threads = prepare(points, params)?;
    let fallback = plane_through(points, &threads)?;
    let graph = Graph::build(points, params.neighbours, &threads, progress)?;
    let (mut normals, _) = graph.estimate(fallback, &threads, progress)?;
    graph.orient(&mut normals, params.orient, &threads, progress)?;
    progress.report(1.0, "normals: done")?;
    Ok(graph.to_input_order(&normals))
}

/// Makes `normals` (one per point, any length) consistent and signed as `params.orient` says,
/// in place; `params.orient == Unoriented` leaves them as they are. Zero normals stay zero and
/// carry no sign from one neighbour to another.
///
/// Errors: as [`estimate_normals`] (except that collinear points are fine), and a normal count
/// that differs from the point count or a non-finite normal (named).
pub fn orient_normals(
    points: &[Vec3],
    normals: &mut [Vec3],
    params: &NormalParams,
    progress: &mut Progress,
) -> Result<OrientReport> {
    let threads = prepare(points, params)?;
    check_normals(points, normals)?;
    if params.orient == Orientation::Unoriented {
        return Ok(OrientReport::default());
    }
    let graph = Graph::build(points, params.neighbours, &threads, progress)?;
    let mut ordered = graph.to_tree_order(normals);
    let report = graph.orient(&mut ordered, params.orient, &threads, progress)?;
    normals.copy_from_slice(&graph.to_input_order(&ordered));
    progress.report(1.0, "normals: done")?;
    Ok(report.unwrap_or_default())
}

/// Gives a point cloud usable normals: the entry point reconstruction calls.
///
/// - No normals, or all of them zero: estimated and oriented as `params.orient` says.
/// - Normals given: kept, or re-oriented with `params.orient` when `params.reorient_given`.
/// - Some normals zero: those are estimated; they take the sign of their given neighbours
///   (or, with `reorient_given`, everything is re-oriented together).
///
/// Normals this function writes are unit length; given normals it keeps are left untouched.
/// Triangles, if any, are ignored: the positions are treated as a cloud.
pub fn ensure_normals(cloud: &mut Mesh, params: &NormalParams, progress: &mut Progress) -> Result<NormalsReport> {
    cloud.check()?;
    let missing: Vec<u32> = match &cloud.normals {
        None => (0..cloud.positions.len() as u32).collect(),
        Some(given) => (0..given.len() as u32).filter(|&i| given[i as usize] == Vec3::ZERO).collect(),
    };
    let n = cloud.positions.len();
    if missing.len() == n {
        let threads = prepare(&cloud.positions, params)?;
        let fallback = plane_through(&cloud.positions, &threads)?;
        let graph = Graph::build(&cloud.positions, params.neighbours, &threads, progress)?;
        let (mut normals, degenerate) = graph.estimate(fallback, &threads, progress)?;
        let orient = graph.orient(&mut normals, params.orient, &threads, progress)?;
        progress.report(1.0, "normals: done")?;
        cloud.normals = Some(graph.to_input_order(&normals));
        return Ok(NormalsReport { estimated: n, neighbours: graph.k, degenerate, orient });
    }
    if missing.is_empty() && !params.reorient_given {
        return Ok(NormalsReport::default());
    }
    let given = cloud.normals.as_mut().expect("normals checked above");
    let threads = prepare(&cloud.positions, params)?;
    let fallback = if missing.is_empty() { Vec3::ZERO } else { plane_through(&cloud.positions, &threads)? };
    let graph = Graph::build(&cloud.positions, params.neighbours, &threads, progress)?;
    let mut degenerate = 0;
    let mut ordered = graph.to_tree_order(given);
    if !missing.is_empty() {
        let (estimated, bad) = graph.estimate(fallback, &threads, progress)?;
        degenerate = bad;
        graph.fill_from_given(&mut ordered, &estimated, &threads);
    }
    let orient =
        if params.reorient_given { graph.orient(&mut ordered, params.orient, &threads, progress)? } else { None };
    progress.report(1.0, "normals: done")?;
    let unit: Vec<Vec3> = graph.to_input_order(&ordered).iter().map(|n| n.normalize_or_zero()).collect();
    *given = unit;
    Ok(NormalsReport { estimated: missing.len(), neighbours: graph.k, degenerate, orient })
}

/// Checks the parameters and the points every entry point needs, and makes the thread pool.
fn prepare(points: &[Vec3], params: &NormalParams) -> Result<Threads> {
    params.check()?;
    if points.len() < 3 {
        return Err(Error::input(format!("{} points: normals need at least 3", points.len())));
    }
    check_positions(points, "point")?;
    Threads::new(params.threads)
}

fn check_normals(points: &[Vec3], normals: &[Vec3]) -> Result<()> {
    if normals.len() != points.len() {
        return Err(Error::input(format!("{} normals for {} points", normals.len(), points.len())));
    }
    if let Some(i) = normals.iter().position(|n| !n.is_finite()) {
        return Err(Error::input(format!("normal {i} has a NaN or infinite component")));
    }
    Ok(())
}
