//! Orientation: Hoppe's propagation of signs along the minimum spanning forest of the
//! neighbour graph (edges ordered by a bucket sort), then each component's sign by the rule
//! [`Orientation`] names.

use super::estimate::Graph;
use super::{OrientReport, Orientation};
use crate::error::Result;
use crate::progress::{Progress, Threads};
use crate::union_find::UnionFind;
use glam::{DVec3, Vec3};
use rayon::prelude::*;

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

impl Graph {
    /// Orients `normals` (tree order) in place as `rule` says; `None` for `Unoriented`.
    pub(super) fn orient(
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
