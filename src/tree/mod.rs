//! The Volume-Surface Tree (paper §3): an octree of V-nodes down to the T-layer, where each
//! T-node carries a local frame and roots a quadtree of S-nodes in its tangent plane.
//!
//! Storage is flat: `nodes[0]` is the root, a node's children are contiguous in `nodes`, and
//! the samples are reordered once so that every node owns the contiguous range
//! `samples[start .. start + count]`.

mod build;
mod fit;
mod indicator;
mod locate;
mod partition;
mod validate;

use crate::error::{shown, Error, Result};
use crate::params;
use crate::quadric::CellStats;
use glam::{DVec3, Vec2, Vec3};
use rayon::prelude::*;

pub use build::{build, build_allowing_noise};
pub use fit::fit;

/// Which hierarchy to build.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TreeKind {
    /// Octree above the T-layer, quadtrees below it (the paper's structure).
    #[default]
    VsTree,
    /// A plain octree with the same metric, thresholds and sample order: the baseline.
    Octree,
}

/// The error metric that decides whether a cell is split (paper §3.2, "Error metrics").
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Metric {
    /// Quadric error (Garland-Heckbert): the sum, over the cell's samples, of the squared
    /// distance from the cell's representative (its quadric minimiser, kept in the cell) to
    /// each sample's tangent plane, relative to the squared bounding-box diagonal.
    #[default]
    L2,
    /// Normal deviation (Cohen-Steiner et al. 2004): mean of ‖nⱼ − n̂‖² over the cell's samples
    /// (unitless, 0 = flat, at most 4).
    L21,
    /// Sample count: a cell with at most `error` samples is a leaf (a cheap proxy for huge inputs).
    Density,
}

/// Parameters of the tree. `error` is read according to `metric`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TreeParams {
    pub kind: TreeKind,
    pub metric: Metric,
    /// Split threshold: L2 relative to the squared bounding-box diagonal, L2,1 unitless, Density
    /// a sample count.
    pub error: f64,
    /// Height-field indicator, normal cone: every normal must satisfy nⱼ·n̄ > d_a. In [0, 1].
    pub d_a: f32,
    /// Height-field indicator, displacement: |(pⱼ − c)·n̄| / max‖pₖ − c‖ < d_d. In [0, 1].
    pub d_d: f32,
    /// Deepest level of the whole tree (octree and quadtree levels counted together), 1-30.
    pub max_depth: u32,
    /// Cells smaller than this (relative to the diagonal) are not split: guards against
    /// duplicate points. In [0, 1).
    pub min_cell_size: f64,
}

impl Default for TreeParams {
    fn default() -> Self {
        TreeParams {
            kind: TreeKind::VsTree,
            metric: Metric::L2,
            error: TreeParams::DEFAULT_ERROR,
            d_a: params::SIMPLIFY_D_A.default as f32,
            d_d: params::SIMPLIFY_D_D.default as f32,
            max_depth: params::SIMPLIFY_MAX_DEPTH.default_u32(),
            min_cell_size: params::SIMPLIFY_MIN_CELL_SIZE.default,
        }
    }
}

/// The deepest level supported: cube sizes stay representable in `f32` well past it.
pub const MAX_DEPTH: u32 = 30;

impl TreeParams {
    /// The default L2 bound for simplification (reconstruction has its own, see
    /// [`crate::reconstruct::ReconstructParams`]).
    /// cbindgen:ignore
    pub const DEFAULT_ERROR: f64 = params::SIMPLIFY_ERROR.default;

    /// The L2 bound under which every sample's tangent plane passes within `distance` of its
    /// cluster's point, for a model of bounding-box diagonal `diagonal`: the bound sums squared
    /// plane distances over the squared diagonal, so (distance / diagonal)^2. 0 unless both are
    /// finite and above 0.
    pub fn l2_error_for_distance(distance: f64, diagonal: f64) -> f64 {
        let usable = |x: f64| x.is_finite() && x > 0.0;
        if usable(distance) && usable(diagonal) {
            (distance / diagonal).powi(2)
        } else {
            0.0
        }
    }

    /// Rejects values outside their documented ranges, naming the parameter.
    pub fn check(&self) -> Result<()> {
        let positive = self.error.is_finite() && self.error > 0.0;
        match self.metric {
            Metric::Density if !(positive && self.error >= 1.0) => {
                return Err(Error::param("error", format!("{} samples per cell: must be at least 1", self.error)))
            }
            _ if !positive => {
                return Err(Error::param("error", format!("{}: must be a finite number > 0", shown(self.error))))
            }
            // |n - m|² of unit vectors n and m is at most 4: a larger bound never splits.
            Metric::L21 if self.error > 4.0 => {
                return Err(Error::param("error", format!("{}: the L2,1 bound must be in (0, 4]", shown(self.error))))
            }
            _ => {}
        }
        params::SIMPLIFY_D_A.check(self.d_a.into(), self.d_a)?;
        params::SIMPLIFY_D_D.check(self.d_d.into(), self.d_d)?;
        params::SIMPLIFY_MAX_DEPTH.check(self.max_depth.into(), self.max_depth)?;
        params::SIMPLIFY_MIN_CELL_SIZE.check(self.min_cell_size, self.min_cell_size)
    }
}

/// The three kinds of node (paper §3.1).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum NodeKind {
    /// An octree cell: 0 or 8 (non-empty) children, V- or T-nodes.
    Volume = 0,
    /// A leaf of the 3D hierarchy and root of a 2D one: 0 or 4 S-node children.
    Transition = 1,
    /// A quadtree cell in its T-node's plane: 0 or 4 S-node children.
    Surface = 2,
}

/// A node. For V- and T-nodes the cell is the cube `center ± half`; for S-nodes it is the
/// square `(center.x, center.y) ± half` in the (u, v) coordinates of frame `frame`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Node {
    /// First sample of the node's range in [`VsTree::samples`].
    pub start: u32,
    pub count: u32,
    /// Index of the first child; children are `first_child .. first_child + child_count`.
    pub first_child: u32,
    /// Parent index (the root is its own parent).
    pub parent: u32,
    pub center: Vec3,
    pub half: f32,
    /// Index into [`VsTree::frames`] for T- and S-nodes, [`NO_FRAME`] for V-nodes.
    pub frame: u32,
    pub kind: NodeKind,
    pub depth: u8,
    pub child_count: u8,
    /// Which octant (bits x, y, z) or quadrant (bits u, v) of the parent this node is.
    pub slot: u8,
}

/// The representative point of a node's samples (their sums `stats`, positions relative to
/// `origin`): the quadric minimiser, clamped into the node's cell, i.e. its cube for V- and
/// T-nodes, and for S-nodes (`frame` given) the prism over its square. The tree's L2 test and
/// the simplification's output vertex both use this point, so the bound holds for the vertex.
/// Returned in absolute coordinates.
pub fn representative(node: &Node, frame: Option<&Frame>, stats: &CellStats, origin: DVec3) -> DVec3 {
    let x = stats.quadric_minimizer() + origin;
    match (node.kind, frame) {
        (NodeKind::Surface, Some(f)) => {
            let (o, u, v, n) = (f.origin.as_dvec3(), f.u.as_dvec3(), f.v.as_dvec3(), f.normal.as_dvec3());
            let d = x - o;
            let (lo, hi) = ((node.center_uv() - node.half).as_dvec2(), (node.center_uv() + node.half).as_dvec2());
            o + u * d.dot(u).clamp(lo.x, hi.x) + v * d.dot(v).clamp(lo.y, hi.y) + n * d.dot(n)
        }
        _ => {
            let (c, h) = (node.center.as_dvec3(), f64::from(node.half));
            x.clamp(c - h, c + h)
        }
    }
}

impl Metric {
    /// The bound a tree is built with when none is given, in this metric's units: for L2 (a
    /// relative error) [`TreeParams::DEFAULT_ERROR`], the simplification's (reconstruction has
    /// its own); for L2,1 (unitless) the same number; for density, 16 samples per cell.
    pub fn default_error(self) -> f64 {
        match self {
            Metric::L2 | Metric::L21 => TreeParams::DEFAULT_ERROR,
            // Samples per cell: a cell of more is split in 4 to 8, so a cluster holds about 8
            // samples (8.0 to 8.8 on a sampled torus and its cloud, where the L2 default gives
            // 9.4): about the L2 default's reduction, whatever the model's size.
            Metric::Density => 16.0,
        }
    }

    /// The error of a cell under this metric, as the split test measures it before comparing:
    /// L2, the quadric at the cell's [`representative`] beyond what samples scattered by
    /// `noise` (absolute; see [`beyond_noise`]) explain (absolute, squared units); L2,1, the
    /// normal deviation; density, the sample count. `stats` sums the cell's samples relative to
    /// `origin`; `frame` is the frame of an S-node's T-node.
    pub fn cell_error(self, node: &Node, frame: Option<&Frame>, stats: &CellStats, origin: DVec3, noise: f32) -> f64 {
        match self {
            Metric::L2 => {
                let x = representative(node, frame, stats, origin);
                beyond_noise(stats.quadric_at(x - origin), stats.count, noise)
            }
            Metric::L21 => stats.normal_deviation(),
            Metric::Density => stats.count as f64,
        }
    }
}

/// How many standard deviations of a noisy cell's L2 error [`beyond_noise`] allows above its
/// mean: 3 leaves a flat cell of Gaussian noise a leaf in all but about one in a thousand cases.
const NOISE_SPREADS: f64 = 3.0;

/// The L2 error `quadric` of a cell of `count` samples beyond what their noise explains. Each
/// sample scattered off a flat surface with standard deviation `noise` adds its squared height,
/// so the sum is `noise`² times a chi-square with `count` degrees of freedom: mean `count`, spread
/// √(2·`count`). What is beyond that mean plus [`NOISE_SPREADS`] spreads is the surface's own
/// shape, which the L2 bound is about; the rest is noise, which the bound should not chase.
fn beyond_noise(quadric: f64, count: u64, noise: f32) -> f64 {
    let n = count as f64;
    let explained = f64::from(noise).powi(2) * (n + NOISE_SPREADS * (2.0 * n).sqrt());
    (quadric - explained).max(0.0)
}

/// `Node::frame` of a V-node.
pub const NO_FRAME: u32 = u32::MAX;

impl Node {
    pub fn is_leaf(&self) -> bool {
        self.child_count == 0
    }

    pub fn range(&self) -> std::ops::Range<usize> {
        self.start as usize..(self.start + self.count) as usize
    }

    pub fn children(&self) -> std::ops::Range<usize> {
        self.first_child as usize..(self.first_child + u32::from(self.child_count)) as usize
    }

    /// The centre of the square for an S-node, in its frame's (u, v) coordinates.
    pub fn center_uv(&self) -> Vec2 {
        self.center.truncate()
    }
}

/// A T-node's local frame {n, u, v} at the centroid of its samples, and the bounding square of
/// their projections (the root of its quadtree) in (u, v) coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    pub origin: Vec3,
    pub normal: Vec3,
    pub u: Vec3,
    pub v: Vec3,
    pub square_center: Vec2,
    pub square_half: f32,
}

impl Frame {
    /// (u, v) coordinates of the projection of `p` onto the frame's plane.
    #[inline]
    pub fn project(&self, p: Vec3) -> Vec2 {
        let d = p - self.origin;
        Vec2::new(d.dot(self.u), d.dot(self.v))
    }

    /// Signed height of `p` above the plane.
    #[inline]
    pub fn height(&self, p: Vec3) -> f32 {
        (p - self.origin).dot(self.normal)
    }

    /// The 3D point at plane coordinates `uv` and height `h`.
    pub fn point(&self, uv: Vec2, h: f32) -> Vec3 {
        self.origin + self.u * uv.x + self.v * uv.y + self.normal * h
    }
}

/// A sample in tree order; `index` is its position in the [`crate::SampleSet`] it came from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TreeSample {
    pub position: Vec3,
    pub normal: Vec3,
    pub index: u32,
}

/// A built tree.
#[derive(Clone, Debug)]
pub struct VsTree {
    pub nodes: Vec<Node>,
    pub frames: Vec<Frame>,
    pub samples: Vec<TreeSample>,
    /// Diagonal of the samples' bounding box: the unit of relative thresholds.
    pub diagonal: f32,
    pub params: TreeParams,
    /// The samples' noise level (absolute) that the height-field test and the L2 error allowed
    /// for; 0 unless the tree was built by [`build_allowing_noise`].
    pub noise: f32,
}

/// Figures that describe a tree.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TreeStats {
    pub samples: usize,
    pub nodes: usize,
    pub v_nodes: usize,
    pub t_nodes: usize,
    pub s_nodes: usize,
    /// Leaves = clusters.
    pub leaves: usize,
    pub max_depth: u32,
    /// Shallowest and deepest T-node (0, 0 when there is none).
    pub t_depth_min: u32,
    pub t_depth_max: u32,
    /// Mean and variance of the number of samples per leaf.
    pub leaf_size_mean: f64,
    pub leaf_size_variance: f64,
}

impl VsTree {
    pub fn root(&self) -> &Node {
        &self.nodes[0]
    }

    /// Indices of the leaves, in node order: leaf `k` of this iterator is cluster `k`.
    pub fn leaves(&self) -> impl Iterator<Item = usize> + '_ {
        self.nodes.iter().enumerate().filter(|(_, n)| n.is_leaf()).map(|(i, _)| i)
    }

    pub fn samples_of(&self, node: &Node) -> &[TreeSample] {
        &self.samples[node.range()]
    }

    /// The error of `node` that the split test compares with `params.error`, in its units (L2
    /// relative to the squared diagonal, L2,1 unitless, density in samples). Every leaf of a
    /// tree built with a bound is within it, unless a single sample, the deepest level or the
    /// smallest cell size stopped its split; every inner node is beyond it.
    pub fn node_error(&self, node: &Node) -> f64 {
        let origin = self.root().center.as_dvec3();
        let stats = build::sum(self.samples_of(node), origin);
        let frame = (node.kind == NodeKind::Surface).then(|| &self.frames[node.frame as usize]);
        let error = self.params.metric.cell_error(node, frame, &stats, origin, self.noise);
        match self.params.metric {
            Metric::L2 => {
                let scale = f64::from(self.diagonal).powi(2);
                if scale > 0.0 {
                    error / scale
                } else {
                    0.0
                }
            }
            Metric::L21 | Metric::Density => error,
        }
    }

    /// The parameter that made the tree coarser than its bound asks: the limit (`max_depth` or
    /// `min_cell_size`) that kept a leaf beyond the bound from being split, by its name; None
    /// when every leaf is within the bound or a single sample. For a tree as [`build`] made it
    /// (not reshaped by [`fit`]).
    pub fn limited_by(&self) -> Option<&'static str> {
        let builder = build::Builder::new(&self.params, self.root().center, self.diagonal, self.noise);
        self.leaves()
            .map(|i| &self.nodes[i])
            .filter(|node| node.count > 1 && self.node_error(node) > self.params.error)
            .find_map(|node| builder.limit(node))
    }

    /// [`VsTree::node_error`] of each of the nodes numbered `nodes`, in parallel.
    pub fn node_errors(&self, nodes: &[u32]) -> Vec<f64> {
        nodes.par_iter().map(|&i| self.node_error(&self.nodes[i as usize])).collect()
    }

    pub fn stats(&self) -> TreeStats {
        let mut s = TreeStats { samples: self.samples.len(), nodes: self.nodes.len(), ..Default::default() };
        let (mut t_min, mut t_max) = (u32::MAX, 0);
        let (mut sum, mut sum_sq) = (0.0f64, 0.0f64);
        for node in &self.nodes {
            match node.kind {
                NodeKind::Volume => s.v_nodes += 1,
                NodeKind::Transition => {
                    s.t_nodes += 1;
                    t_min = t_min.min(node.depth.into());
                    t_max = t_max.max(node.depth.into());
                }
                NodeKind::Surface => s.s_nodes += 1,
            }
            s.max_depth = s.max_depth.max(node.depth.into());
            if node.is_leaf() {
                s.leaves += 1;
                sum += f64::from(node.count);
                sum_sq += f64::from(node.count).powi(2);
            }
        }
        if s.t_nodes > 0 {
            (s.t_depth_min, s.t_depth_max) = (t_min, t_max);
        }
        if s.leaves > 0 {
            s.leaf_size_mean = sum / s.leaves as f64;
            s.leaf_size_variance = (sum_sq / s.leaves as f64 - s.leaf_size_mean.powi(2)).max(0.0);
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::shapes;
    use crate::progress::{Progress, Threads};
    use crate::samples::{MeshSampling, SampleSet};

    fn tree_of(samples: &SampleSet, metric: Metric, error: f64) -> VsTree {
        let params = TreeParams { metric, error, ..Default::default() };
        build(samples, &params, &Threads::new(1).unwrap(), &mut Progress::none()).unwrap()
    }

    #[test]
    fn node_error_gives_each_metric_s_figure() {
        // A slab: 5 × 5 samples on z = 1 facing up and on z = -1 facing down. The quadric's
        // minimiser is on z = 0, one unit from all 50 tangent planes; the mean normal is zero.
        let mut samples = SampleSet::default();
        for (z, nz) in [(1.0, 1.0), (-1.0, -1.0)] {
            for i in 0..25 {
                samples.positions.push(Vec3::new((i % 5) as f32, (i / 5) as f32, z));
                samples.normals.push(Vec3::new(0.0, 0.0, nz));
                samples.origin.push(samples.origin.len() as u32);
            }
        }
        // Bounds the root is within, so it stays a leaf; the diagonal is 6 (4, 4, 2).
        for (metric, bound, figure) in
            [(Metric::L2, 2.0, 50.0 / 36.0), (Metric::L21, 4.0, 2.0), (Metric::Density, 50.0, 50.0)]
        {
            let tree = tree_of(&samples, metric, bound);
            assert_eq!(tree.nodes.len(), 1, "{metric:?}");
            let error = tree.node_error(tree.root());
            assert!((error - figure).abs() < 1e-12, "{metric:?}: {error}, not {figure}");
        }
    }

    #[test]
    fn node_error_is_what_the_build_split_on() {
        let samples = SampleSet::from_mesh(&shapes::torus(1.0, 0.3, 96, 48), MeshSampling::Vertices).unwrap();
        for (metric, bound) in [(Metric::L2, 1e-3), (Metric::L21, 0.05), (Metric::Density, 40.0)] {
            let tree = tree_of(&samples, metric, bound);
            let all: Vec<u32> = (0..tree.nodes.len() as u32).collect();
            let errors = tree.node_errors(&all);
            let (mut leaves, mut inner) = (0, 0);
            for (node, &error) in tree.nodes.iter().zip(&errors) {
                assert_eq!(error, tree.node_error(node));
                if !node.is_leaf() {
                    assert!(error > bound * (1.0 - 1e-9), "{metric:?}: inner node with error {error}");
                    inner += 1;
                } else if node.count > 1 && u32::from(node.depth) < tree.params.max_depth {
                    assert!(error <= bound * (1.0 + 1e-9), "{metric:?}: leaf with error {error}");
                    leaves += 1;
                }
            }
            assert!(leaves > 100 && inner > 10, "{metric:?}: {leaves} leaves, {inner} inner nodes checked");
        }
    }

    /// A flat unit square of 20k samples scattered off it by Gaussian noise of deviation 1% of
    /// its side: with that noise allowed for, neither the height-field test nor the L2 bound
    /// sees any shape, and the whole square is one T-node of a few leaves; without, the bound
    /// chases the noise down to cells of a few samples each.
    #[test]
    fn the_noise_allowed_for_is_not_split_on() {
        let sigma = 0.01;
        let mut cloud = shapes::sample_surface(&shapes::square_grid(8), 20_000, 1);
        shapes::add_noise(&mut cloud, sigma, 0.0, 2);
        let samples = SampleSet::from_cloud(&cloud).unwrap();
        let params = TreeParams { error: 1e-5, ..Default::default() };
        let tree_allowing = |noise| {
            build_allowing_noise(&samples, &params, noise, &Threads::new(1).unwrap(), &mut Progress::none()).unwrap()
        };
        let allowing = tree_allowing(sigma);
        let stats = allowing.stats();
        assert!(stats.t_nodes <= 4 && allowing.leaves().count() <= 4, "noise allowed for: {stats:?}");
        let chasing = tree_allowing(0.0);
        let leaves = chasing.leaves().count();
        assert!(leaves > 2_000, "noise not allowed for: only {leaves} leaves");
    }
}
