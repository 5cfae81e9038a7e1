//! Normals for point clouds: estimation where they are missing, consistent orientation where
//! they are not.
//!
//! **Estimation.** Each point's normal is the direction of least spread of its neighbourhood
//! (the point and its `k` nearest other points, from an exact k-d tree, [`crate::knn`]): the
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

use crate::error::{Error, Result};
use crate::knn::KdTree;
use crate::linalg::Sym3;
use crate::mesh::{check_positions, Mesh};
use crate::progress::{Progress, Threads};
use crate::union_find::UnionFind;
use glam::{DVec3, Vec3};
use rayon::prelude::*;

/// Default neighbourhood size. Clean samples need few neighbours, but noisy scans need more:
/// on the 10 merged bunny range scans, normals within 10 degrees of the mesh reconstructed from
/// them were 75% with k = 10, 87% with 16, 91% with 24, while the time grows about linearly
/// with k and thin features blur. 16 is the compromise.
pub const DEFAULT_NEIGHBOURS: usize = 16;

/// Fewest neighbours a normal may be estimated from (a point and 3 others fit a plane).
pub const MIN_NEIGHBOURS: usize = 3;

/// Most neighbours (beyond this the neighbourhood is not local any more, and it gets slow).
pub const MAX_NEIGHBOURS: usize = 256;

/// Points per fixed-size chunk in reductions: sums in this order are the same for any thread
/// count.
const CHUNK: usize = 1 << 14;

/// Neighbours each point is linked to in the orientation graph (the nearest of its `k`).
/// Farther links more often jump across gaps between sheets; 10 keeps thin, sparsely sampled
/// features right (see `Graph::sorted_edges`) while the graph stays connected.
const GRAPH_NEIGHBOURS: usize = 10;

/// Low bits of an f32 weight dropped before ordering edges: 16 leaves the exponent and 7
/// mantissa bits, so weights are ordered to within a factor 1 + 2^-7.
const WEIGHT_SHIFT: u32 = 16;

/// Marks an edge number whose normals point to opposite sides (bit 31; edge numbers are below
/// 2^31).
const OPPOSITE: u32 = 1 << 31;

/// Queries answered between two progress reports (and cancellation checks).
const QUERY_SLICE: usize = 1 << 18;

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
        if !(MIN_NEIGHBOURS..=MAX_NEIGHBOURS).contains(&self.neighbours) {
            return Err(Error::param(
                "neighbours",
                format!("{}: must be from {MIN_NEIGHBOURS} to {MAX_NEIGHBOURS}", self.neighbours),
            ));
        }
        Ok(())
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

/// About two ulps of the cloud's largest coordinate: coordinate differences this small are f32
/// rounding noise, and spreads this small span nothing.
fn rounding_noise(points: &[Vec3]) -> f64 {
    let largest = points.iter().fold(0.0f32, |m, p| m.max(p.abs().max_element()));
    2.0 * f64::from(f32::EPSILON) * f64::from(largest)
}

/// Refuses a cloud with no volume to enclose: all at one place, on one line, or in one plane
/// (thinner than [`FLAT`] of its extent). Such a cloud has no closed surface, and the
/// reconstruction would fail later with a message about the wrong cause.
pub(crate) fn refuse_flat(points: &[Vec3], threads: &Threads) -> Result<()> {
    let (_, thickness) = plane_and_thickness(points, threads)?;
    if thickness <= FLAT {
        return Err(Error::input(format!(
            "all {} points lie in one plane (thickness {} of the cloud's extent): they enclose \
             no volume, so there is no closed surface to reconstruct",
            points.len(),
            crate::error::shown(thickness)
        )));
    }
    Ok(())
}

/// The thickness (smallest over largest spread, a ratio) below which a cloud counts as flat:
/// f32 positions of a plane spanning the cloud vary by about 1e-7 of its extent, and any
/// real object is much thicker than 1e-5 of its size.
const FLAT: f64 = 1e-5;

/// The normal of the plane through the whole cloud (the fallback for points none of whose
/// neighbours has a normal), or an error when all points are at one place or on one line.
/// Checked before any neighbour search, so such input fails fast.
fn plane_through(points: &[Vec3], threads: &Threads) -> Result<Vec3> {
    plane_and_thickness(points, threads).map(|(normal, _)| normal)
}

/// [`plane_through`], with the cloud's thickness: the spread along the plane's normal over the
/// largest spread (standard deviations), 0 for a plane.
fn plane_and_thickness(points: &[Vec3], threads: &Threads) -> Result<(Vec3, f64)> {
    let n = points.len();
    let origin = points[0].as_dvec3();
    let partial: Vec<(DVec3, Sym3)> = threads.run(|| {
        points
            .par_chunks(CHUNK)
            .map(|chunk| {
                chunk.iter().fold((DVec3::ZERO, Sym3::default()), |(s, mut c), p| {
                    let d = p.as_dvec3() - origin;
                    c.add(&Sym3::outer(d));
                    (s + d, c)
                })
            })
            .collect()
    });
    // Chunks are summed in order: the same result for any thread count.
    let (sum, second) = partial.iter().fold((DVec3::ZERO, Sym3::default()), |(s, mut c), (ps, pc)| {
        c.add(pc);
        (s + *ps, c)
    });
    let mean = sum / n as f64;
    let scatter = second.sub(&Sym3::outer(mean).scaled(n as f64));
    let (values, vectors) = scatter.eigen();
    let noise = rounding_noise(points);
    let floor = noise * noise * n as f64;
    if values[0] <= floor {
        return Err(Error::input(format!("all {n} points are at the same place: no surface passes through them")));
    }
    if values[1] <= floor.max(1e-12 * values[0]) {
        return Err(Error::input(format!("all {n} points lie on one line: no surface passes through them")));
    }
    Ok((vectors[2].as_vec3(), (values[2].max(0.0) / values[0]).sqrt()))
}

/// The k-NN graph of a cloud, in the k-d tree's point order (neighbouring points are close in
/// memory there); converted from and to the input order at the edges of the pipeline.
struct Graph {
    tree: KdTree,
    /// Neighbours per point.
    k: usize,
    /// Row `t`: tree positions of point `t`'s `k` nearest other points, nearest first.
    rows: Vec<u32>,
    /// Tree position of every input point.
    position_of: Vec<u32>,
    /// The cloud's [`rounding_noise`].
    noise: f64,
}

impl Graph {
    /// The k-d tree and every point's `min(k, n - 1)` nearest neighbours.
    fn build(points: &[Vec3], k: usize, threads: &Threads, progress: &mut Progress) -> Result<Graph> {
        let n = points.len();
        let k = k.min(n - 1);
        // Edge numbers t * k + slot fit in 31 bits (the 32nd carries a sign, see
        // `sorted_edges`), and so, with k >= 2, do point indices.
        if (n as u64) * (k as u64) >= 1 << 31 {
            return Err(Error::TooLarge(format!("{n} points x {k} neighbours (at most 2^31 neighbour links)")));
        }
        progress.report(0.0, "normals: k-d tree")?;
        let tree = threads.run(|| KdTree::new(points))?;
        tree.check_k(k)?;
        let mut rows = vec![0u32; n * k];
        for (slice, out) in rows.chunks_mut(QUERY_SLICE * k).enumerate() {
            progress.report(0.05 + 0.45 * (slice * QUERY_SLICE) as f32 / n as f32, "normals: neighbours")?;
            threads.run(|| tree.knn_positions(k, slice * QUERY_SLICE, out));
        }
        let mut position_of = vec![0u32; n];
        for t in 0..n {
            position_of[tree.index(t) as usize] = t as u32;
        }
        Ok(Graph { tree, k, rows, position_of, noise: rounding_noise(points) })
    }

    fn len(&self) -> usize {
        self.position_of.len()
    }

    fn row(&self, t: usize) -> &[u32] {
        &self.rows[t * self.k..][..self.k]
    }

    /// Per-point values given in input order, in tree order.
    fn to_tree_order(&self, values: &[Vec3]) -> Vec<Vec3> {
        (0..self.len()).into_par_iter().map(|t| values[self.tree.index(t) as usize]).collect()
    }

    /// Per-point values given in tree order, in input order.
    fn to_input_order(&self, values: &[Vec3]) -> Vec<Vec3> {
        self.position_of.par_iter().map(|&t| values[t as usize]).collect()
    }

    /// Unoriented PCA normals in tree order, and how many points had a degenerate
    /// neighbourhood (filled from their neighbours, or `fallback` when none has a normal).
    fn estimate(&self, fallback: Vec3, threads: &Threads, progress: &mut Progress) -> Result<(Vec<Vec3>, usize)> {
        progress.report(0.5, "normals: PCA")?;
        let mut normals: Vec<Vec3> =
            threads.run(|| (0..self.len()).into_par_iter().map(|t| self.pca_normal(t).unwrap_or(Vec3::ZERO)).collect());
        let degenerate = threads.run(|| self.fill_degenerate(&mut normals, fallback));
        Ok((normals, degenerate))
    }

    /// The PCA normal at tree position `t`, or `None` when its neighbourhood spans no plane.
    fn pca_normal(&self, t: usize) -> Option<Vec3> {
        // Offsets from the point itself are exact in f64, so duplicates give exact zeros.
        let p = self.tree.point(t).as_dvec3();
        let row = self.row(t);
        let count = (row.len() + 1) as f64;
        let mut mean = DVec3::ZERO;
        for &q in row {
            mean += self.tree.point(q as usize).as_dvec3() - p;
        }
        mean /= count;
        let mut cov = Sym3::outer(mean);
        for &q in row {
            cov.add(&Sym3::outer(self.tree.point(q as usize).as_dvec3() - p - mean));
        }
        let (values, normal) = cov.eigen_smallest();
        let floor = self.noise * self.noise * count;
        if values[0] <= floor || values[1] <= floor.max(1e-12 * values[0]) {
            return None;
        }
        Some(normal.as_vec3())
    }

    /// Gives every zero normal the normal of its nearest neighbour that has one, repeatedly
    /// (so a run of degenerate points fills from its ends); points in a part of the cloud
    /// with no normal at all get `fallback`. Returns how many were filled.
    fn fill_degenerate(&self, normals: &mut [Vec3], fallback: Vec3) -> usize {
        let mut todo: Vec<u32> = (0..normals.len() as u32).filter(|&t| normals[t as usize] == Vec3::ZERO).collect();
        let count = todo.len();
        while !todo.is_empty() {
            // Jacobi-style rounds (read the previous round, then write) keep it deterministic.
            let found: Vec<Option<Vec3>> = todo
                .par_iter()
                .map(|&t| self.row(t as usize).iter().map(|&q| normals[q as usize]).find(|&n| n != Vec3::ZERO))
                .collect();
            let before = todo.len();
            let mut left = Vec::new();
            for (&t, f) in todo.iter().zip(found) {
                match f {
                    Some(n) => normals[t as usize] = n,
                    None => left.push(t),
                }
            }
            if left.len() == before {
                for &t in &left {
                    normals[t as usize] = fallback;
                }
                break;
            }
            todo = left;
        }
        count
    }

    /// Fills the zero normals of `given` (tree order) with `estimated` ones, each signed to
    /// agree with the sum of its neighbours' given normals.
    fn fill_from_given(&self, given: &mut [Vec3], estimated: &[Vec3], threads: &Threads) {
        let filled: Vec<Vec3> = threads.run(|| {
            (0..given.len())
                .into_par_iter()
                .map(|t| {
                    if given[t] != Vec3::ZERO {
                        return given[t];
                    }
                    let around: Vec3 = self.row(t).iter().map(|&q| given[q as usize]).sum();
                    if estimated[t].dot(around) < 0.0 {
                        -estimated[t]
                    } else {
                        estimated[t]
                    }
                })
                .collect()
        });
        given.copy_from_slice(&filled);
    }

    /// Orients `normals` (tree order) in place as `rule` says; `None` for `Unoriented`.
    fn orient(
        &self,
        normals: &mut [Vec3],
        rule: Orientation,
        threads: &Threads,
        progress: &mut Progress,
    ) -> Result<Option<OrientReport>> {
        if rule == Orientation::Unoriented {
            return Ok(None);
        }
        progress.report(0.6, "normals: orientation graph")?;
        // Signs are decided on unit normals; the flips are applied to the normals as given.
        let unit: Vec<Vec3> = threads.run(|| normals.par_iter().map(|n| n.normalize_or_zero()).collect());
        let edges = self.sorted_edges(&unit, threads);
        progress.report(0.75, "normals: spanning forest")?;
        let parts = self.spanning_forest(&edges, &mut progress.stage(0.75, 0.95))?;
        drop(edges);
        progress.report(0.95, "normals: signs")?;
        let (root_flip, undecided) = self.component_signs(&parts, &unit, rule, threads);
        let flips: Vec<bool> =
            (0..normals.len()).map(|t| parts.flip[t] ^ root_flip[parts.component[t] as usize]).collect();
        let flipped = threads
            .run(|| normals.par_iter_mut().zip(flips.par_iter()).filter(|(_, &f)| f).map(|(n, _)| *n = -*n).count());
        let mut sizes = vec![0usize; root_flip.len()];
        for &c in &parts.component {
            sizes[c as usize] += 1;
        }
        Ok(Some(OrientReport {
            components: root_flip.len(),
            largest_component: sizes.iter().copied().max().unwrap_or(0),
            undecided_components: undecided,
            flipped,
        }))
    }

    /// The edges of the orientation graph as edge numbers `t * k + slot` (the edge from `t` to
    /// its neighbour in `slot`), cheapest first, with [`OPPOSITE`] set when `nt·nu < 0` (the
    /// propagation flips across that edge).
    ///
    /// The graph links every point to its [`GRAPH_NEIGHBOURS`] nearest, both ways (Hoppe's
    /// Riemannian graph). The weight of edge (t, u) with unit direction `e` is
    /// `(1 - |nt·nu|) / 2 + (|e·nt| + |e·nu|) / 4`: Hoppe's term, small between parallel
    /// normals, plus one that is small only when the edge lies in both tangent planes. Hoppe's
    /// term alone is 0 for an edge across a thin gap between two sheets, whose normals are
    /// antiparallel, so the propagation would cross early and wrongly; the second term puts
    /// such edges last. (Measured on `oni.pwn`, a sparse model: re-orienting its given normals
    /// keeps 99.7% of them instead of 87% with Hoppe's term alone.)
    ///
    /// The weights are ordered to about 1% (the f32's exponent and top 7 mantissa bits, see
    /// [`WEIGHT_SHIFT`]), which is a counting sort over a few thousand buckets instead of a
    /// comparison sort, and leaves the edges of one bucket in tree order, so the union-find
    /// that follows walks memory nearly in order. The order is a pure function of the input.
    fn sorted_edges(&self, normals: &[Vec3], threads: &Threads) -> Vec<u32> {
        const SKIP: u16 = u16::MAX;
        let (k, g) = (self.k, self.k.min(GRAPH_NEIGHBOURS));
        let buckets: Vec<u16> = threads.run(|| {
            (0..self.len() * g)
                .into_par_iter()
                .map(|i| {
                    let t = i / g;
                    let u = self.rows[t * k + i % g] as usize;
                    // An edge found from both ends is kept once, from the smaller end.
                    if u < t && self.row(u)[..g].contains(&(t as u32)) {
                        return SKIP;
                    }
                    let (nt, nu) = (normals[t], normals[u]);
                    let e = (self.tree.point(u) - self.tree.point(t)).normalize_or_zero();
                    let dot = nt.dot(nu);
                    let w = 0.5 * (1.0 - dot.abs()).max(0.0) + 0.25 * (e.dot(nt).abs() + e.dot(nu).abs());
                    // Weights are below 1.5, whose bucket 0x3FC0 leaves bit 15 free.
                    ((w.to_bits() >> WEIGHT_SHIFT) as u16) | if dot < 0.0 { 1 << 15 } else { 0 }
                })
                .collect()
        });
        let mut start = vec![0u32; 1 << 15];
        for &b in &buckets {
            start[(b & 0x7FFF) as usize] += 1;
        }
        let mut total = 0;
        for s in start.iter_mut() {
            (*s, total) = (total, total + *s);
        }
        // SKIP's bucket is the last one: everything before it is kept.
        let skip = (SKIP & 0x7FFF) as usize;
        let mut edges = vec![0u32; start[skip] as usize];
        for (i, &b) in buckets.iter().enumerate() {
            let bucket = (b & 0x7FFF) as usize;
            if bucket != skip {
                let sign = if b >> 15 == 1 { OPPOSITE } else { 0 };
                edges[start[bucket] as usize] = ((i / g) * k + i % g) as u32 | sign;
                start[bucket] += 1;
            }
        }
        edges
    }

    /// Kruskal's minimum spanning forest over `edges`, propagating signs as it joins trees:
    /// a union-find where every point also stores whether its normal must flip relative to its
    /// parent's, so joining two trees over edge (t, u) fixes the relative sign of the two
    /// whole trees so that `t` and `u` agree (Hoppe's traversal, without building the tree).
    fn spanning_forest(&self, edges: &[u32], progress: &mut Progress) -> Result<Parts> {
        let n = self.len();
        let mut forest = UnionFind::new(n);
        let mut joined = 0;
        for (e, &id) in edges.iter().enumerate() {
            if e % (1 << 22) == 0 {
                progress.report(e as f32 / edges.len() as f32, "normals: spanning forest")?;
            }
            let differ = id & OPPOSITE != 0;
            let id = (id & !OPPOSITE) as usize;
            let (t, u) = (id / self.k, self.rows[id] as usize);
            if forest.union_signed(t as u32, u as u32, differ) {
                joined += 1;
                if joined == n - 1 {
                    break;
                }
            }
        }
        let mut component = vec![0u32; n];
        let mut flip = vec![false; n];
        let mut numbering = vec![u32::MAX; n];
        let mut components = 0u32;
        for t in 0..n {
            let (root, parity) = forest.find_signed(t as u32);
            if numbering[root as usize] == u32::MAX {
                numbering[root as usize] = components;
                components += 1;
            }
            component[t] = numbering[root as usize];
            flip[t] = parity;
        }
        Ok(Parts { component, flip, count: components as usize })
    }

    /// Whether each component must be flipped as a whole (after `parts.flip`), by `rule`, and
    /// how many components the outward test left undecided.
    fn component_signs(
        &self,
        parts: &Parts,
        normals: &[Vec3],
        rule: Orientation,
        threads: &Threads,
    ) -> (Vec<bool>, usize) {
        let oriented = |t: usize| -> Vec3 {
            if parts.flip[t] {
                -normals[t]
            } else {
                normals[t]
            }
        };
        let count = parts.count;
        match rule {
            Orientation::Unoriented => (vec![false; count], 0),
            Orientation::Propagate => (self.highest_point_rule(parts, &oriented), 0),
            Orientation::PropagateMajority => {
                // Votes of points flipped by the propagation minus points kept.
                let mut votes = vec![0i64; count];
                for t in 0..normals.len() {
                    votes[parts.component[t] as usize] += if parts.flip[t] { 1 } else { -1 };
                }
                (votes.iter().map(|&v| v > 0).collect(), 0)
            }
            Orientation::PropagateOutward => {
                let area = threads.run(|| self.sample_areas());
                let mut centroid = vec![DVec3::ZERO; count];
                let mut weight = vec![0.0f64; count];
                for (t, &a) in area.iter().enumerate() {
                    let c = parts.component[t] as usize;
                    centroid[c] += a * self.tree.point(t).as_dvec3();
                    weight[c] += a;
                }
                for (c, w) in centroid.iter_mut().zip(&weight) {
                    *c /= w.max(f64::MIN_POSITIVE);
                }
                let mut flux = vec![0.0f64; count];
                let mut scale = vec![0.0f64; count];
                for (t, &a) in area.iter().enumerate() {
                    let c = parts.component[t] as usize;
                    let r = self.tree.point(t).as_dvec3() - centroid[c];
                    flux[c] += a * r.dot(oriented(t).as_dvec3());
                    scale[c] += a * r.length();
                }
                let fallback = self.highest_point_rule(parts, &oriented);
                let mut undecided = 0;
                let flip = (0..count)
                    .map(|c| {
                        // A flat patch has flux ~0 (only noise): no inside to point away from.
                        if flux[c].abs() <= 1e-3 * scale[c] {
                            undecided += 1;
                            fallback[c]
                        } else {
                            flux[c] < 0.0
                        }
                    })
                    .collect();
                (flip, undecided)
            }
        }
    }

    /// Hoppe's rule per component: flip when the normal at the highest point (largest z, ties
    /// to the smaller input index) points down; a horizontal one decides by x, then y.
    fn highest_point_rule(&self, parts: &Parts, oriented: &dyn Fn(usize) -> Vec3) -> Vec<bool> {
        let mut top: Vec<Option<usize>> = vec![None; parts.count];
        for t in 0..self.len() {
            let c = parts.component[t] as usize;
            let higher = match top[c] {
                None => true,
                Some(s) => {
                    let (zt, zs) = (self.tree.point(t).z, self.tree.point(s).z);
                    zt > zs || (zt == zs && self.tree.index(t) < self.tree.index(s))
                }
            };
            if higher {
                top[c] = Some(t);
            }
        }
        top.iter()
            .map(|&s| {
                let n = oriented(s.expect("every component has a point"));
                let decisive = [n.z, n.x, n.y].into_iter().find(|v| v.abs() > 1e-6).unwrap_or(0.0);
                decisive < 0.0
            })
            .collect()
    }

    /// The surface area each sample stands for, up to a common factor: the squared distance to
    /// its farthest neighbour (k neighbours cover a disc of that radius), capped at 16 times
    /// the median so that stray outliers, whose normals mean little, weigh little.
    fn sample_areas(&self) -> Vec<f64> {
        let k = self.k;
        let mut area: Vec<f64> = (0..self.len())
            .into_par_iter()
            .map(|t| {
                let far = self.rows[t * k + k - 1] as usize;
                f64::from(self.tree.point(t).distance_squared(self.tree.point(far)))
            })
            .collect();
        let mut sorted = area.clone();
        let mid = sorted.len() / 2;
        let median = *sorted.select_nth_unstable_by(mid, f64::total_cmp).1;
        // All-duplicate neighbourhoods have no area: give them the median (or 1 if that is 0).
        let typical = if median > 0.0 { median } else { 1.0 };
        area.par_iter_mut().for_each(|a| *a = if *a > 0.0 { a.min(16.0 * typical) } else { typical });
        area
    }
}

/// The spanning forest's result: every point's component (numbered densely in tree order)
/// and whether its normal must flip to agree with its component's root.
struct Parts {
    component: Vec<u32>,
    flip: Vec<bool>,
    count: usize,
}
