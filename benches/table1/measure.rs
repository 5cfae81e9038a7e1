//! Timings and figures: tree builds, simplifications, and distances to the input.

use crate::common::distance::{self, Distances};
use crate::common::stats::median;
use glam::Vec3;
use std::time::Instant;
use vstree::eval::distance::Target;
use vstree::tree::{self, NodeKind, TreeKind, TreeParams, TreeStats, VsTree};
use vstree::{simplify, Mesh, MeshSampling, Progress, SampleSet, SimplifyParams, Threads};

/// The two hierarchies, in the order the table shows them.
pub const KINDS: [TreeKind; 2] = [TreeKind::Octree, TreeKind::VsTree];

/// Tree parameters: the paper's defaults with the L2 metric at `bound`.
pub fn params(kind: TreeKind, bound: f64) -> TreeParams {
    TreeParams { kind, error: bound, ..TreeParams::default() }
}

/// One tree kind's build on one input at one bound.
#[derive(Clone, Copy, Debug)]
pub struct Build {
    /// Median wall time of the builds, in seconds.
    pub seconds: f64,
    pub stats: TreeStats,
    /// Leaves that are S-nodes: clusters cut by a quadtree in a T-node's plane.
    pub surface_leaves: usize,
    /// Leaves plus the empty cells a pointer-based tree allocates (8 children per octree split,
    /// 4 per quadtree split, empty or not): what the paper's Table 1 calls "partitions".
    pub partitions: usize,
}

impl Build {
    /// Variance of the samples per cluster over the squared mean (scale-free spread).
    pub fn spread(&self) -> f64 {
        self.stats.leaf_size_variance / self.stats.leaf_size_mean.powi(2)
    }

    /// Share of the clusters that are S-nodes.
    pub fn surface_share(&self) -> f64 {
        self.surface_leaves as f64 / self.stats.leaves.max(1) as f64
    }
}

/// A tree's figures beyond [`TreeStats`].
#[derive(Clone, Copy, Debug, Default)]
pub struct Figures {
    pub stats: TreeStats,
    pub surface_leaves: usize,
    pub partitions: usize,
}

/// The tree's figures: its stats, how many leaves are S-nodes, and its partitions.
pub fn figures(tree: &VsTree) -> Figures {
    let surface_leaves = tree.nodes.iter().filter(|n| n.is_leaf() && n.kind == NodeKind::Surface).count();
    let empty: usize = tree
        .nodes
        .iter()
        .filter(|n| !n.is_leaf())
        .map(|n| if n.kind == NodeKind::Volume { 8 } else { 4 } - usize::from(n.child_count))
        .sum();
    let stats = tree.stats();
    Figures { stats, surface_leaves, partitions: stats.leaves + empty }
}

/// A timed sample should last at least this long: faster builds are repeated within one sample
/// (and the time divided), so timer resolution and scheduler ticks do not dominate.
const MIN_SAMPLE_SECONDS: f64 = 0.02;

/// Builds the octree and the VS-Tree `runs` times each, interleaved (and alternating which goes
/// first) so load changes on the machine hit both alike. With `warm_up`, one untimed build of
/// each comes first, and builds faster than [`MIN_SAMPLE_SECONDS`] are repeated within each
/// timed sample. Returns `[octree, vstree]`.
pub fn builds(
    samples: &SampleSet,
    bound: f64,
    threads: &Threads,
    runs: usize,
    warm_up: bool,
) -> vstree::Result<[Build; 2]> {
    let mut times = [Vec::new(), Vec::new()];
    let mut stats = [Figures::default(); 2];
    // Mean seconds of `repeat` builds of kind `k`, and the tree's figures.
    let build = |k: usize, repeat: usize| -> vstree::Result<(f64, Figures)> {
        let mut total = 0.0;
        let mut last = Figures::default();
        for _ in 0..repeat {
            let start = Instant::now();
            let tree = tree::build(samples, &params(KINDS[k], bound), threads, &mut Progress::none())?;
            total += start.elapsed().as_secs_f64();
            last = figures(&tree); // the tree is dropped outside the timed span
        }
        Ok((total / repeat as f64, last))
    };
    let mut repeat = [1, 1];
    if warm_up {
        for (k, r) in repeat.iter_mut().enumerate() {
            let (seconds, _) = build(k, 1)?;
            *r = (MIN_SAMPLE_SECONDS / seconds.max(1e-6)).ceil().clamp(1.0, 1000.0) as usize;
        }
    }
    for run in 0..runs.max(1) {
        for step in 0..2 {
            let k = if run % 2 == 0 { step } else { 1 - step };
            let (seconds, s) = build(k, repeat[k])?;
            times[k].push(seconds);
            stats[k] = s;
        }
    }
    Ok([0, 1].map(|k| Build {
        seconds: median(&times[k]),
        stats: stats[k].stats,
        surface_leaves: stats[k].surface_leaves,
        partitions: stats[k].partitions,
    }))
}

/// A simplified mesh and the median time it took.
pub struct Simplified {
    pub mesh: Mesh,
    pub seconds: f64,
}

/// Simplifies `mesh` with vertex samples `runs` times (the whole call: samples, tree,
/// clustering) on `threads` threads (0 = all); the median time and the last output.
pub fn simplified(mesh: &Mesh, kind: TreeKind, bound: f64, threads: usize, runs: usize) -> vstree::Result<Simplified> {
    // The paper's plain clustering, as Table 1 measures it.
    let params = SimplifyParams {
        tree: params(kind, bound),
        sampling: MeshSampling::Vertices,
        threads,
        keep_topology: vstree::KeepTopology::Off,
        target_faces: 0,
    };
    let mut times = Vec::new();
    let mut out = Mesh::default();
    for _ in 0..runs.max(1) {
        let start = Instant::now();
        let (mesh, _) = simplify(mesh, &params, &mut Progress::none())?;
        times.push(start.elapsed().as_secs_f64());
        out = mesh;
    }
    Ok(Simplified { mesh: out, seconds: median(&times) })
}

/// [`Distances`] of the simplified `output` to `input` (whose samples are `input_points`, box
/// diagonal `diagonal`): from points on the output to the input's triangles, and back.
pub fn distances(input: &Mesh, input_points: &[Vec3], diagonal: f32, output: &Mesh) -> Distances {
    distance::between(output, Target::Triangles(input), input_points, diagonal)
}

/// One input's clusters at one bound, for both kinds (untimed).
pub struct SweepRow {
    pub input: String,
    pub bound: f64,
    /// `[octree, vstree]`.
    pub figures: [Figures; 2],
}

impl SweepRow {
    /// 1 − VS-Tree clusters / octree clusters.
    pub fn gain(&self) -> f64 {
        reduction(self.figures[0].stats.leaves, self.figures[1].stats.leaves)
    }

    /// The same on partitions.
    pub fn partition_gain(&self) -> f64 {
        reduction(self.figures[0].partitions, self.figures[1].partitions)
    }
}

/// How much smaller the VS-Tree's count is than the octree's: 1 − vstree / octree.
pub fn reduction(octree: usize, vstree: usize) -> f64 {
    1.0 - vstree as f64 / octree.max(1) as f64
}

/// Both trees over `samples` at each of `bounds`, one build each: how the gain moves with the
/// bound, and how much of the VS-Tree lies below the T-layer.
pub fn sweep(name: &str, samples: &SampleSet, bounds: &[f64], threads: &Threads) -> vstree::Result<Vec<SweepRow>> {
    let mut rows = Vec::new();
    for &bound in bounds {
        let mut figures = [Figures::default(); 2];
        for (k, kind) in KINDS.into_iter().enumerate() {
            figures[k] = self::figures(&tree::build(samples, &params(kind, bound), threads, &mut Progress::none())?);
        }
        rows.push(SweepRow { input: name.to_string(), bound, figures });
    }
    Ok(rows)
}
