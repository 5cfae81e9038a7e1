//! Inside or outside, far from the samples: the generalised winding number of the oriented
//! samples (Barill et al. 2018, "Fast winding numbers for soups and clouds"), summed over the
//! VS-Tree's leaves and sped up Barnes-Hut style by the tree's own hierarchy.
//!
//! The blended T-node planes only know the surface near the samples. Deep inside a thick part
//! no T-node's support reaches, and past a sharp tip the planes' blend can be slightly negative:
//! a "far = outside" rule there grows an inner shell around the medial axis, joined to the
//! real surface by tunnels that raise the genus. The winding number answers the question for
//! the whole cloud: about 1 inside a closed surface, about 0 outside, and behind an open scan it
//! falls from about 1 to 0 towards the scan's border, which closes the scan's back.
//!
//! Each leaf of the tree is one dipole: its area times its mean normal, at its samples'
//! centroid. A leaf's area is its cell's: the square of an S-node (or a T-node's bounding
//! square), the face of a V-node's cube. Cells, unlike sample counts, do not depend on how
//! densely a region was scanned, so overlapping scans do not weigh twice.

use crate::tree::{NodeKind, VsTree, MAX_DEPTH};
use glam::{Vec2, Vec3};

/// A node farther than this many times its radius is summed as one dipole.
const FAR_RATIO: f32 = 2.0;
/// The same for a height-field leaf.
const NEAR_LEAF_RATIO: f32 = 1.0;

/// The area-weighted normals of every node's leaves, for winding-number queries.
pub(crate) struct WindingNumber<'t> {
    tree: &'t VsTree,
    /// Per node: Σ area × normal over its leaves.
    flux: Vec<Vec3>,
    /// Per leaf: the area each of its samples stands for.
    sample_area: Vec<f32>,
    /// Per node: the area-weighted centroid of its leaves, and a radius around it that holds
    /// all its leaves' cells.
    centre: Vec<Vec3>,
    radius: Vec<f32>,
    /// Squared length over which each sample's dipole is softened (0: exact dipoles).
    softening_sq: f32,
}

impl<'t> WindingNumber<'t> {
    /// `min_sample_area`: the least area a sample stands for (0: the leaves' cells alone say).
    pub fn new(tree: &'t VsTree, min_sample_area: f32) -> WindingNumber<'t> {
        let n = tree.nodes.len();
        let mut flux = vec![Vec3::ZERO; n];
        let mut centre = vec![Vec3::ZERO; n];
        let mut radius = vec![0.0f32; n];
        let mut area = vec![0.0f32; n];
        // Children come after their parents: one backward pass accumulates every node.
        for i in (0..n).rev() {
            let node = &tree.nodes[i];
            if node.is_leaf() {
                let samples = tree.samples_of(node);
                if samples.is_empty() {
                    continue;
                }
                let normal = samples.iter().map(|s| s.normal).sum::<Vec3>().normalize_or_zero();
                centre[i] = samples.iter().map(|s| s.position).sum::<Vec3>() / samples.len() as f32;
                area[i] = leaf_area(tree, i, normal).max(samples.len() as f32 * min_sample_area);
                flux[i] = normal * area[i];
                radius[i] = samples.iter().map(|s| s.position.distance(centre[i])).fold(0.0, f32::max);
                continue;
            }
            let children = node.children();
            area[i] = children.clone().map(|c| area[c]).sum();
            if area[i] <= 0.0 {
                continue;
            }
            flux[i] = children.clone().map(|c| flux[c]).sum();
            centre[i] = children.clone().map(|c| centre[c] * area[c]).sum::<Vec3>() / area[i];
            radius[i] = children.map(|c| centre[c].distance(centre[i]) + radius[c]).fold(0.0, f32::max);
        }
        let sample_area = (0..n).map(|i| area[i] / tree.nodes[i].count.max(1) as f32).collect();
        WindingNumber { tree, flux, sample_area, centre, radius, softening_sq: 0.0 }
    }

    /// The same with each sample's dipole softened over `length` (its 1/r² replaced by
    /// 1/(r² + length²)): next to a sample, a single sample no longer dominates the sum, so the
    /// number stays near one half on the surface instead of swinging with the nearest sample.
    pub fn softened(mut self, length: f32) -> Self {
        self.softening_sq = length * length;
        self
    }

    /// The winding number at `p`: near 1 inside the sampled surface, near 0 outside.
    pub fn at(&self, p: Vec3) -> f32 {
        let mut sum = 0.0f32;
        // Depth-first, at most eight children pushed per level: a fixed stack, no allocation.
        let mut stack = [0u32; 8 * (MAX_DEPTH as usize + 1)];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let i = stack[top] as usize;
            let node = &self.tree.nodes[i];
            let d = self.centre[i] - p;
            let dist = d.length();
            // A height-field leaf (T- or S-node) has no opposite normals to cancel: as one
            // dipole it is accurate nearer than a node that may hold both sides of a part.
            let far_ratio = if node.is_leaf() && node.kind != NodeKind::Volume { NEAR_LEAF_RATIO } else { FAR_RATIO };
            if dist > far_ratio * self.radius[i] {
                sum += dipole(self.flux[i], d, 0.0);
            } else if node.is_leaf() {
                // Close to a leaf, its samples count one by one: a leaf that holds both sides
                // of a thin part has opposite normals that would cancel as one dipole.
                let a = self.sample_area[i];
                let e = self.softening_sq;
                sum += self.tree.samples_of(node).iter().map(|s| dipole(s.normal * a, s.position - p, e)).sum::<f32>();
            } else {
                for c in node.children() {
                    stack[top] = c as u32;
                    top += 1;
                }
            }
        }
        sum
    }
}

/// The solid angle, over 4π, of a small patch with area × normal `flux` seen from `d` away,
/// with the squared distance softened by `softening_sq`.
fn dipole(flux: Vec3, d: Vec3, softening_sq: f32) -> f32 {
    let dist_sq = d.length_squared() + softening_sq;
    if dist_sq > 0.0 {
        flux.dot(d) / (4.0 * std::f32::consts::PI * dist_sq * dist_sq.sqrt())
    } else {
        0.0
    }
}

/// The area of the surface in leaf `i`: the bounding rectangle of its samples in the plane
/// across `normal` (its frame's plane for T- and S-nodes), widened by the gap that uniform
/// samples leave at its sides, and no more than the cell's square. Without a usable normal (both
/// sides of a thin part) the cube's face stands in.
fn leaf_area(tree: &VsTree, i: usize, normal: Vec3) -> f32 {
    let node = &tree.nodes[i];
    let samples = tree.samples_of(node);
    let (u, v) = match node.kind {
        NodeKind::Volume if normal == Vec3::ZERO => return 4.0 * node.half * node.half,
        NodeKind::Volume => normal.any_orthonormal_pair(),
        _ => {
            let f = &tree.frames[node.frame as usize];
            (f.u, f.v)
        }
    };
    let (mut lo, mut hi) = (Vec2::splat(f32::MAX), Vec2::splat(f32::MIN));
    for s in samples {
        let q = Vec2::new(s.position.dot(u), s.position.dot(v));
        (lo, hi) = (lo.min(q), hi.max(q));
    }
    // n uniform samples span (n − 1)/(n + 1) of an interval on average.
    let n = samples.len() as f32;
    let rectangle = if n >= 3.0 { (hi - lo) * ((n + 1.0) / (n - 1.0)) } else { Vec2::ZERO };
    let cell_side = match node.kind {
        NodeKind::Transition => 2.0 * tree.frames[node.frame as usize].square_half,
        _ => 2.0 * node.half,
    };
    let cell = cell_side * cell_side;
    if n >= 3.0 {
        (rectangle.x * rectangle.y).min(cell)
    } else {
        cell
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tree::{self, TreeParams};
    use crate::{Progress, SampleSet, Threads};

    fn tree_of(cloud: &crate::Mesh) -> VsTree {
        let samples = SampleSet::from_cloud(cloud).unwrap();
        tree::build(
            &samples,
            &TreeParams { error: 1e-5, ..Default::default() },
            &Threads::new(0).unwrap(),
            &mut Progress::none(),
        )
        .unwrap()
    }

    #[test]
    fn one_inside_a_torus_and_zero_outside_it() {
        let torus = crate::eval::shapes::torus(1.0, 0.35, 96, 48);
        let cloud = crate::eval::shapes::sample_surface(&torus, 30_000, 3);
        let t = tree_of(&cloud);
        let w = WindingNumber::new(&t, 0.0);
        for p in [Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, -1.0, 0.0), Vec3::new(-0.8, 0.6, 0.0).normalize()] {
            assert!((w.at(p) - 1.0).abs() < 0.15, "w({p}) = {}", w.at(p));
        }
        // The hole, above the ring, and far away.
        for p in [Vec3::ZERO, Vec3::new(1.0, 0.0, 0.6), Vec3::splat(4.0)] {
            assert!(w.at(p).abs() < 0.15, "w({p}) = {}", w.at(p));
        }
    }

    #[test]
    fn softening_keeps_the_number_bounded_next_to_a_sample() {
        // On the samples the exact sum swings with the nearest one; softened over a spacing
        // it stays near one half, and deep inside and far outside it is unchanged.
        let sphere = crate::eval::shapes::icosphere(1.0, 5);
        let cloud = crate::eval::shapes::sample_surface(&sphere, 20_000, 5);
        let t = tree_of(&cloud);
        let spacing = (4.0 * std::f32::consts::PI / 20_000.0).sqrt();
        let exact = WindingNumber::new(&t, 0.0);
        let soft = WindingNumber::new(&t, 0.0).softened(spacing);
        let (mut exact_worst, mut soft_worst) = (0.0f32, 0.0f32);
        for (p, n) in cloud.positions.iter().zip(cloud.normals.as_ref().unwrap()).step_by(997) {
            let q = *p + 0.01 * spacing * *n;
            exact_worst = exact_worst.max((exact.at(q) - 0.5).abs());
            soft_worst = soft_worst.max((soft.at(q) - 0.5).abs());
        }
        assert!(exact_worst > 5.0, "exact: {exact_worst}");
        assert!(soft_worst < 0.3, "softened: {soft_worst}");
        // Away from the samples softening changes nothing (the leaves' areas, not the
        // softening, set how far from exactly 1 the inside is: 1.15 here).
        for p in [Vec3::ZERO, Vec3::new(0.5, 0.0, 0.0), Vec3::splat(3.0)] {
            assert!((soft.at(p) - exact.at(p)).abs() < 0.01, "{p}: {} against {}", soft.at(p), exact.at(p));
        }
        assert!((soft.at(Vec3::ZERO) - 1.0).abs() < 0.2, "{}", soft.at(Vec3::ZERO));
        assert!(soft.at(Vec3::splat(3.0)).abs() < 0.05, "{}", soft.at(Vec3::splat(3.0)));
    }
}
