//! Projection of mesh vertices onto the samples' moving-least-squares surface.
//!
//! The quadtree displacement moves a vertex only where it is alone in an S-node with a free
//! leaf; the others stay on PN patches of coarser vertices, off by the curvature those missed,
//! and even a displaced one sits on one leaf's fit. Each vertex is therefore projected onto a
//! local fit of the samples nearest to it: a plane iterated to its foot point (the weighted
//! centroid and mean normal of its nearest samples on the same side, as in point set surfaces),
//! then a weighted quadratic height field over that plane, which removes the plane's sag on
//! curved parts while still averaging the samples' noise.

use super::folds::folded_vertices;
use super::leaf_fit::solve;
use super::refine::Surface;
use crate::progress::Threads;
use crate::spatial::{KdTree, Neighbour};
use crate::tree::TreeSample;
use glam::{DVec3, Vec3};
use rayon::prelude::*;

/// Samples per fit on a clean cloud: a quadratic has six coefficients, so it needs a few times
/// more to average noise; more blur detail smaller than their spread.
pub(crate) const NEIGHBOURS: usize = 24;
/// Samples whose tangent planes vote for the side of a point next to them: a few, so that one
/// noisy normal does not decide, and few enough to stay on one side of a thin part.
const SIDE_NEIGHBOURS: usize = 8;
/// Plane iterations towards the foot point: each one moves along the plane's normal only, and a
/// second one corrects for the neighbourhood having changed with the first.
const PLANE_ITERATIONS: usize = 2;
/// A sample whose normal makes more than 90 degrees with the vertex's (cosine below this)
/// belongs to the other side of a thin part and is left out of the fit.
const SAME_SIDE: f32 = 0.0;

/// The samples, indexed for nearest-neighbour queries.
pub(crate) struct SampleSurface<'a> {
    samples: &'a [TreeSample],
    index: KdTree,
    /// On a noisy cloud, what the fits are made of: the averages of small groups of samples
    /// (see [`AVERAGED_PER_FIT`]); empty where the fits are made of the samples themselves.
    points: Vec<FitPoint>,
    /// Over `points` where they are averages (else `index` serves).
    fit_index: Option<KdTree>,
    /// Points per fit.
    neighbours: usize,
}

/// A point of the fits: a sample, or the average of a few nearby samples facing the same way
/// (mean position, mean normal), weighted by how many.
#[derive(Clone, Copy, Debug)]
struct FitPoint {
    position: Vec3,
    normal: Vec3,
    weight: f64,
}

/// Fits of at least twice this many samples (noisy clouds: see `fit_neighbours` in the parent
/// module) are made of the averages of groups of nearby samples instead, each group at most
/// neighbours / this many samples (the nodes of the samples' k-d tree at that size, each side
/// of a thin part averaged apart): the fit spans the same samples and averages the same noise
/// with fewer points, and costs as much less. Measured on bull, dino and lucy at 200k points
/// with 0.25% and 0.5% noise: 48 left Chamfer within 2.5% at 0.25% (better at 0.5%) and the
/// refinement 1.5-3.5x cheaper; 24 (groups of about 6-8) made it 4-13x cheaper but Chamfer
/// 6-10% worse on two of the three 0.25% rows.
const AVERAGED_PER_FIT: usize = 48;

impl<'a> SampleSurface<'a> {
    /// The surface of `samples`, each fit made over [`NEIGHBOURS`] of them (see
    /// [`Self::with_neighbours`]).
    pub fn new(samples: &'a [TreeSample], threads: &Threads) -> crate::error::Result<SampleSurface<'a>> {
        let positions: Vec<Vec3> = samples.iter().map(|s| s.position).collect();
        let index = threads.run(|| KdTree::new(&positions))?;
        Ok(SampleSurface { samples, index, points: Vec::new(), fit_index: None, neighbours: NEIGHBOURS })
    }

    /// The same surface with each fit made over `neighbours` samples (at least [`NEIGHBOURS`];
    /// more average more noise away), or as many averages of groups of them (see
    /// [`AVERAGED_PER_FIT`]).
    pub fn with_neighbours(mut self, neighbours: usize, threads: &Threads) -> crate::error::Result<Self> {
        let neighbours = neighbours.clamp(NEIGHBOURS, crate::spatial::MAX_K);
        let group = neighbours / AVERAGED_PER_FIT;
        if group < 2 {
            (self.points, self.fit_index, self.neighbours) = (Vec::new(), None, neighbours);
            return Ok(self);
        }
        let (samples, index) = (self.samples, &self.index);
        let points: Vec<FitPoint> = threads.run(|| {
            index
                .groups(group)
                .par_iter()
                .flat_map_iter(|range| {
                    // Samples facing against the group's first one (the other side of a thin
                    // part) are averaged apart.
                    let first = samples[index.index(range.start) as usize].normal;
                    let mut sides = [(DVec3::ZERO, DVec3::ZERO, 0usize); 2];
                    for position in range.clone() {
                        let s = &samples[index.index(position) as usize];
                        let side = &mut sides[usize::from(s.normal.dot(first) <= 0.0)];
                        side.0 += s.position.as_dvec3();
                        side.1 += s.normal.as_dvec3();
                        side.2 += 1;
                    }
                    sides.into_iter().filter(|side| side.2 > 0 && side.1 != DVec3::ZERO).map(|(p, n, count)| FitPoint {
                        position: (p / count as f64).as_vec3(),
                        normal: n.normalize().as_vec3(),
                        weight: count as f64,
                    })
                })
                .collect()
        });
        let centres: Vec<Vec3> = points.iter().map(|p| p.position).collect();
        self.fit_index = Some(threads.run(|| KdTree::new(&centres))?);
        // As many points as stand for `neighbours` samples.
        let per_point = samples.len() as f64 / points.len().max(1) as f64;
        self.neighbours = ((neighbours as f64 / per_point).round() as usize).clamp(NEIGHBOURS, crate::spatial::MAX_K);
        self.points = points;
        Ok(self)
    }

    /// What the fits are made of: the `i`th sample, or the `i`th average where they are averages.
    fn point(&self, i: u32) -> FitPoint {
        if self.fit_index.is_some() {
            return self.points[i as usize];
        }
        let s = &self.samples[i as usize];
        FitPoint { position: s.position, normal: s.normal, weight: 1.0 }
    }

    fn fit_index(&self) -> &KdTree {
        self.fit_index.as_ref().unwrap_or(&self.index)
    }

    /// The samples' positions, indexed (in the order of the samples given to [`Self::new`]).
    pub fn index(&self) -> &KdTree {
        &self.index
    }

    /// The mean signed distance from `p` to the tangent planes of its [`SIDE_NEIGHBOURS`]
    /// nearest samples: positive on their normals' side.
    pub fn plane_side(&self, p: Vec3) -> f32 {
        let found = self.index.knn(p, SIDE_NEIGHBOURS);
        let sum: f32 = found
            .iter()
            .map(|f| {
                let s = &self.samples[f.index as usize];
                s.normal.dot(p - s.position)
            })
            .sum();
        sum / found.len().max(1) as f32
    }

    /// `p` (with normal `n`) projected onto the local fit, and the fit's normal there; `None`
    /// where too few samples face the same way.
    pub fn project(&self, p: Vec3, n: Vec3) -> Option<(Vec3, Vec3)> {
        let mut q = p;
        let mut normal = n;
        let mut neighbours = Vec::with_capacity(self.neighbours);
        // The fits' three neighbourhoods are nearly the same (q moves a little along the normal
        // each time): the first search takes a wider one, which the later ones select from
        // where it provably holds their nearest samples (see `Nearby`).
        let mut nearby = Nearby::default();
        for _ in 0..PLANE_ITERATIONS {
            self.same_side(q, n, &mut nearby, &mut neighbours);
            let (centroid, mean_normal) = plane(&neighbours)?;
            normal = mean_normal;
            q -= normal * (q - centroid).dot(normal);
        }
        self.same_side(q, n, &mut nearby, &mut neighbours);
        let (centroid, mean_normal) = plane(&neighbours)?;
        let height = quadratic_height(&neighbours, q, centroid, mean_normal);
        let (h, slope) = height.unwrap_or(((q - centroid).dot(mean_normal), DVec3::ZERO));
        let foot = q - mean_normal * ((q - centroid).dot(mean_normal) - h);
        let fit_normal = (mean_normal.as_dvec3() - slope).normalize_or_zero().as_vec3();
        Some((foot, if fit_normal == Vec3::ZERO { normal } else { fit_normal }))
    }

    /// The [`SampleSurface::neighbours`] nearest samples to `q`, nearest first (ties: the
    /// smaller index), as [`KdTree::knn`] gives them: selected from `nearby` where that holds
    /// them all, else searched (and `nearby` made around `q`).
    fn nearest(&self, q: Vec3, nearby: &mut Nearby) -> Vec<Neighbour> {
        let k = self.neighbours;
        if let Some(found) = nearby.select(q, k, |i| self.point(i).position) {
            return found;
        }
        let wide = ((k as f32 * WIDER) as usize).min(crate::spatial::MAX_K);
        let found = self.fit_index().knn(q, wide);
        if !q.is_finite() {
            return found;
        }
        *nearby = Nearby {
            centre: q,
            // Every sample not found is at least this far from the centre; all were found when
            // fewer came back than asked for.
            beyond: if found.len() < wide {
                f32::INFINITY
            } else {
                found.last().map_or(0.0, |f| f.distance_squared.sqrt())
            },
            keys: found.iter().map(|f| f.index).collect(),
            valid: true,
        };
        let mut found = found;
        found.truncate(k);
        found
    }

    /// The nearest samples to `q` whose normals agree with `n`, with weights that fall to zero
    /// at the farthest one (Wendland's (1 - r²)²).
    fn same_side(&self, q: Vec3, n: Vec3, nearby: &mut Nearby, out: &mut Vec<(Vec3, Vec3, f64)>) {
        out.clear();
        let found = self.nearest(q, nearby);
        let reach2 = found.last().map_or(0.0, |f| f.distance_squared) * 1.1 + f32::MIN_POSITIVE;
        for f in found {
            let s = self.point(f.index);
            if s.normal.dot(n) > SAME_SIDE {
                let r2 = f64::from(f.distance_squared / reach2);
                out.push((s.position, s.normal, (1.0 - r2).powi(2) * s.weight));
            }
        }
    }
}

/// How many times more samples than a fit needs the first search of a projection takes, for
/// the later searches to select from (see [`Nearby`]).
const WIDER: f32 = 1.5;

/// The samples nearest to a centre, found once per projection: every other sample is at least
/// `beyond` from `centre`. The k nearest to a point q are among them when the k-th nearest of
/// them to q is closer than `beyond - |q - centre|` (the triangle inequality), and then they
/// are exactly what a search from q gives; otherwise q is searched afresh.
#[derive(Default)]
struct Nearby {
    centre: Vec3,
    beyond: f32,
    keys: Vec<u32>,
    valid: bool,
}

/// Squared distance in the order [`KdTree`] computes it, so that selections and searches agree
/// to the bit.
#[inline(always)]
fn distance_squared(a: Vec3, b: Vec3) -> f32 {
    let (x, y, z) = (a.x - b.x, a.y - b.y, a.z - b.z);
    x * x + y * y + z * z
}

/// A relative allowance for rounding in the test of [`Nearby::select`].
const SELECT_MARGIN: f32 = 1e-4;

impl Nearby {
    fn select(&self, q: Vec3, k: usize, position: impl Fn(u32) -> Vec3) -> Option<Vec<Neighbour>> {
        if !self.valid || self.keys.len() < k || !q.is_finite() {
            return None;
        }
        let mut keyed: Vec<(u64, u32)> = self
            .keys
            .iter()
            .map(|&i| {
                let d2 = distance_squared(q, position(i));
                ((u64::from(d2.to_bits()) << 32) | u64::from(i), i)
            })
            .collect();
        if keyed.len() > k {
            keyed.select_nth_unstable_by_key(k - 1, |e| e.0);
            keyed.truncate(k);
        }
        keyed.sort_unstable_by_key(|e| e.0);
        let kth = f32::from_bits((keyed[k - 1].0 >> 32) as u32).sqrt();
        let room = self.beyond - q.distance(self.centre);
        // (False for NaN too.)
        let holds_them_all = kth * (1.0 + SELECT_MARGIN) < room * (1.0 - SELECT_MARGIN);
        if !holds_them_all {
            return None;
        }
        Some(
            keyed
                .iter()
                .map(|&(key, i)| Neighbour { index: i, distance_squared: f32::from_bits((key >> 32) as u32) })
                .collect(),
        )
    }
}

/// Weighted centroid and mean unit normal of `points`; `None` when fewer than three, or the
/// normals cancel out.
fn plane(points: &[(Vec3, Vec3, f64)]) -> Option<(Vec3, Vec3)> {
    if points.len() < 3 {
        return None;
    }
    let (mut c, mut n, mut w) = (DVec3::ZERO, DVec3::ZERO, 0.0);
    for &(p, m, weight) in points {
        c += p.as_dvec3() * weight;
        n += m.as_dvec3() * weight;
        w += weight;
    }
    let n = n.normalize_or_zero();
    (w > 0.0 && n != DVec3::ZERO).then(|| ((c / w).as_vec3(), n.as_vec3()))
}

/// The weighted least-squares quadratic height field h(x, y) over the plane through `centroid`
/// with normal `normal`, evaluated at `q`'s plane coordinates: the height, and the gradient as
/// a vector in the plane (for the fit's normal, `normal - gradient`). `None` when the samples
/// do not determine one.
fn quadratic_height(points: &[(Vec3, Vec3, f64)], q: Vec3, centroid: Vec3, normal: Vec3) -> Option<(f32, DVec3)> {
    let n = normal.as_dvec3();
    let u = n.any_orthonormal_vector();
    let v = n.cross(u);
    let o = centroid.as_dvec3();
    // Coordinates in units of the neighbourhood's spread keep the system well conditioned.
    let scale = points.iter().map(|(p, _, _)| (p.as_dvec3() - o).length()).fold(0.0, f64::max);
    if scale <= 0.0 {
        return None;
    }
    let mut a = [[0.0f64; 6]; 6];
    let mut b = [0.0f64; 6];
    for &(p, _, w) in points {
        let d = (p.as_dvec3() - o) / scale;
        let phi = basis(d.dot(u), d.dot(v));
        let h = d.dot(n);
        for i in 0..6 {
            b[i] += w * phi[i] * h;
            for j in 0..6 {
                a[i][j] += w * phi[i] * phi[j];
            }
        }
    }
    let c = solve(a, b)?;
    let d = (q.as_dvec3() - o) / scale;
    let (x, y) = (d.dot(u), d.dot(v));
    let height = basis(x, y).iter().zip(&c).map(|(f, k)| f * k).sum::<f64>() * scale;
    let (dx, dy) = (c[1] + 2.0 * c[3] * x + c[4] * y, c[2] + c[4] * x + 2.0 * c[5] * y);
    Some((height as f32, u * dx + v * dy))
}

fn basis(x: f64, y: f64) -> [f64; 6] {
    [1.0, x, y, x * x, x * y, y * y]
}

/// Projects the vertices of `s` from `first` on onto the samples' surface, each at most `reach`
/// (a move farther than that would land on another part of the surface), and undoes the moves
/// that fold a triangle over.
pub(crate) fn project_vertices(s: &mut Surface, first: usize, onto: &SampleSurface, reach: f32, threads: &Threads) {
    let moves: Vec<(usize, Vec3, Vec3)> = threads.run(|| {
        (first..s.positions.len())
            .into_par_iter()
            .filter_map(|v| {
                let (p, n) = onto.project(s.positions[v], s.normals[v])?;
                (p.distance(s.positions[v]) <= reach).then_some((v, p, n))
            })
            .collect()
    });
    let mut before = Vec::with_capacity(moves.len());
    for &(v, p, n) in &moves {
        before.push((v, s.positions[v], s.normals[v]));
        s.positions[v] = p;
        s.normals[v] = n;
    }
    let folded = folded_vertices(s);
    for (v, p, n) in before {
        if folded.binary_search(&v).is_ok() {
            s.positions[v] = p;
            s.normals[v] = n;
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    pub(crate) fn sphere_samples(n: usize, radius: f32) -> Vec<TreeSample> {
        // A Fibonacci sphere: even spacing, exact outward normals.
        (0..n)
            .map(|i| {
                let z = 1.0 - (2.0 * i as f32 + 1.0) / n as f32;
                let r = (1.0 - z * z).sqrt();
                let phi = i as f32 * std::f32::consts::PI * (3.0 - 5f32.sqrt());
                let normal = Vec3::new(r * phi.cos(), r * phi.sin(), z);
                TreeSample { position: normal * radius, normal, index: i as u32 }
            })
            .collect()
    }

    #[test]
    fn a_point_off_a_sphere_lands_on_it_without_the_planes_sag() {
        let samples = sphere_samples(4000, 1.0);
        let surface = SampleSurface::new(&samples, &Threads::new(1).unwrap()).unwrap();
        for dir in [Vec3::new(0.3, -0.5, 0.8), Vec3::X, Vec3::new(-0.2, 0.1, -0.9)] {
            let dir = dir.normalize();
            for r in [0.97, 1.0, 1.03] {
                let (p, n) = surface.project(dir * r, dir).expect("a fit");
                // The plane through 24 samples' centroid sits inside by their sag (about 1e-3
                // here); the quadratic is within 1e-4.
                assert!((p.length() - 1.0).abs() < 1e-4, "{r}: {}", p.length());
                assert!(p.normalize().dot(dir) > 0.9999, "moved sideways: {p}");
                assert!(n.dot(p.normalize()) > 0.999, "normal {n}");
            }
        }
    }

    #[test]
    fn averaged_fits_land_on_a_noisy_sphere_as_the_samples_do() {
        // 100k samples scattered 0.005 off the unit sphere: a fit of 480 samples is made of
        // about 80 averages of groups of at most 10 (the k-d tree's nodes of that size hold
        // about 6), a sixth of the points to search and fit, and lands as
        // close to the true sphere as a fit of the 480 samples themselves would (within 10%).
        let mut rng = crate::rng::Rng::new(5);
        let mut samples = sphere_samples(100_000, 1.0);
        for s in samples.iter_mut() {
            s.position *= 1.0 + 0.005 * rng.normal();
        }
        let threads = Threads::new(1).unwrap();
        let averaged = SampleSurface::new(&samples, &threads).unwrap().with_neighbours(480, &threads).unwrap();
        assert!(averaged.fit_index.is_some() && averaged.points.len() < samples.len() / 5, "{}", averaged.points.len());
        assert!(averaged.neighbours < 100, "{} points per fit", averaged.neighbours);
        // The same fits over the samples: one group per sample.
        let mut plain = SampleSurface::new(&samples, &threads).unwrap();
        plain.neighbours = 480;
        let rms = |surface: &SampleSurface| {
            let dirs = sphere_samples(500, 1.0);
            let sum: f32 =
                dirs.iter().map(|d| (surface.project(d.normal, d.normal).unwrap().0.length() - 1.0).powi(2)).sum();
            (sum / dirs.len() as f32).sqrt()
        };
        let (a, p) = (rms(&averaged), rms(&plain));
        assert!(a < 1.1 * p && a < 0.001, "RMS off the sphere {a:.2e} averaged, {p:.2e} over the samples");
    }

    #[test]
    fn samples_of_the_other_side_of_a_thin_plate_are_left_out() {
        // Two sheets 0.01 apart (z = 0 facing down, z = 0.01 facing up), samples every 0.02:
        // the nearest samples mix both; a vertex on the upper one stays on it.
        let mut samples = Vec::new();
        for i in 0..41 {
            for j in 0..41 {
                let (x, y) = (i as f32 * 0.02 - 0.4, j as f32 * 0.02 - 0.4);
                let index = samples.len() as u32;
                samples.push(TreeSample { position: Vec3::new(x, y, 0.0), normal: -Vec3::Z, index });
                samples.push(TreeSample { position: Vec3::new(x, y, 0.01), normal: Vec3::Z, index: index + 1 });
            }
        }
        let surface = SampleSurface::new(&samples, &Threads::new(1).unwrap()).unwrap();
        let (p, _) = surface.project(Vec3::new(0.013, 0.0, 0.008), Vec3::Z).unwrap();
        assert!((p.z - 0.01).abs() < 1e-5, "{p}");
        let (p, _) = surface.project(Vec3::new(0.013, 0.0, 0.002), -Vec3::Z).unwrap();
        assert!(p.z.abs() < 1e-5, "{p}");
    }
}
