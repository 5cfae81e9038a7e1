//! Estimation: each point's `k` nearest neighbours (the graph that orientation walks too) and
//! the PCA plane fitted to them; the plane through the whole cloud, which fills in where no
//! neighbourhood spans a plane and tells a flat cloud from a solid one.

use crate::error::{Error, Result};
use crate::linalg::Sym3;
use crate::progress::{Progress, Threads};
use crate::spatial::KdTree;
use glam::{DVec3, Vec3};
use rayon::prelude::*;

/// Points per fixed-size chunk in reductions: sums in this order are the same for any thread
/// count.
const CHUNK: usize = 1 << 14;

/// Queries answered between two progress reports (and cancellation checks).
const QUERY_SLICE: usize = 1 << 18;

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
pub(super) fn plane_through(points: &[Vec3], threads: &Threads) -> Result<Vec3> {
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
pub(super) struct Graph {
    pub(super) tree: KdTree,
    /// Neighbours per point.
    pub(super) k: usize,
    /// Row `t`: tree positions of point `t`'s `k` nearest other points, nearest first.
    pub(super) rows: Vec<u32>,
    /// Tree position of every input point.
    position_of: Vec<u32>,
    /// The cloud's [`rounding_noise`].
    noise: f64,
}

impl Graph {
    /// The k-d tree and every point's `min(k, n - 1)` nearest neighbours.
    pub(super) fn build(points: &[Vec3], k: usize, threads: &Threads, progress: &mut Progress) -> Result<Graph> {
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

    pub(super) fn len(&self) -> usize {
        self.position_of.len()
    }

    pub(super) fn row(&self, t: usize) -> &[u32] {
        &self.rows[t * self.k..][..self.k]
    }

    /// Per-point values given in input order, in tree order.
    pub(super) fn to_tree_order(&self, values: &[Vec3]) -> Vec<Vec3> {
        (0..self.len()).into_par_iter().map(|t| values[self.tree.index(t) as usize]).collect()
    }

    /// Per-point values given in tree order, in input order.
    pub(super) fn to_input_order(&self, values: &[Vec3]) -> Vec<Vec3> {
        self.position_of.par_iter().map(|&t| values[t as usize]).collect()
    }

    /// Unoriented PCA normals in tree order, and how many points had a degenerate
    /// neighbourhood (filled from their neighbours, or `fallback` when none has a normal).
    pub(super) fn estimate(
        &self,
        fallback: Vec3,
        threads: &Threads,
        progress: &mut Progress,
    ) -> Result<(Vec<Vec3>, usize)> {
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
    pub(super) fn fill_from_given(&self, given: &mut [Vec3], estimated: &[Vec3], threads: &Threads) {
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
}
