//! Construction (paper §3.2): recursive from the samples' bounding cube. A cell whose error is
//! within the threshold is a leaf; otherwise it becomes a T-node if the height-field indicator
//! holds (and is split 1-to-4 in its plane from then on), else it is split 1-to-8. (A leaf that
//! passes the indicator is a T-node too, with no children, so the T-layer covers the surface.)
//!
//! Parallel and deterministic: nodes with more than [`FRONTIER`] samples are split on the
//! calling thread (their partitions in fixed-size parallel chunks); the smaller subtrees below
//! them are then built independently in parallel and appended in a fixed order. Nothing
//! depends on the number of threads, so the tree is identical for 1 or N threads.

use super::indicator::{frame, is_height_field, reach};
use super::partition::partition;
use super::{Frame, Metric, Node, NodeKind, TreeKind, TreeParams, TreeSample, VsTree, NO_FRAME};
use crate::error::{Error, Result};
use crate::mesh::{check_positions, Aabb};
use crate::progress::{Progress, Threads};
use crate::quadric::CellStats;
use crate::samples::SampleSet;
use glam::{DVec3, Vec2, Vec3};
use rayon::prelude::*;

/// Nodes with more samples than this are split before the parallel phase.
const FRONTIER: u32 = 32 * 1024;
/// Chunk size of the parallel sums over the root (fixed, so float sums are reproducible).
const STATS_CHUNK: usize = 1 << 15;

/// A node index with the sums of its samples (computed while partitioning its parent).
pub(super) type Pending = (usize, CellStats);

/// The height-field test allows each sample this many noise levels off its plane: the largest
/// of a few hundred Gaussian deviations is about 3-4 of them, so a cell of noisy samples on a
/// smooth surface is as flat as its clean samples would be, once allowed this.
const NOISE_HEIGHTS: f32 = 4.0;

/// A V-node whose error only the noise allowance brings under the bound is split while its
/// half is above this many noise levels. The allowance is what noise adds to a height field's
/// error (a T-node's); a V-node is none, and its error is as much the shape of a thin part, a
/// tip or a crease as noise: left a leaf, it has no T-node, and the base mesh merges it into
/// its neighbours' (at 0.5% noise a fifth of the triceratops' samples, its tail and horns).
/// Below half of [`NOISE_HEIGHTS`] the whole cell lies within the height-field test's
/// allowance, and its shape cannot be told from noise. Measured on the corpus's 24 models at
/// 200k points with 0.25% and 0.5% noise: Chamfer to Poisson depth 8's at the median row 1.31x
/// and 1.42x before, 1.18x and 1.08x after, genus and components right on 18 rows of 24 at
/// either level (19 and 18 before); one noise level (1.18x and 1.01x) added handles on three
/// more rows. Pinned by `a_thin_rod_under_heavy_noise_is_kept` (tests/reconstruct.rs).
const VOLUME_NOISE_HALVES: f32 = 0.5 * NOISE_HEIGHTS;

/// Builds the tree `params` describes over `samples`.
pub fn build(samples: &SampleSet, params: &TreeParams, threads: &Threads, progress: &mut Progress) -> Result<VsTree> {
    build_allowing_noise(samples, params, 0.0, threads, progress)
}

/// [`build`], for samples that scatter about their surface with the standard deviation `noise`
/// (absolute): the height-field test allows each sample `NOISE_HEIGHTS` times that off its
/// cell's plane, so that the T-layer sits where the surface is a height field, not where the
/// cells are too small to hold the noise; and the L2 error counts only what the noise does not
/// explain, so cells are not split to chase it.
pub fn build_allowing_noise(
    samples: &SampleSet,
    params: &TreeParams,
    noise: f32,
    threads: &Threads,
    progress: &mut Progress,
) -> Result<VsTree> {
    params.check()?;
    check_samples(samples)?;
    progress.report(0.0, "building tree")?;
    let bounds = Aabb::of(&samples.positions).ok_or_else(|| Error::input("no samples"))?;
    let diagonal = bounds.diagonal();
    let extent = (bounds.max - bounds.min).max_element();
    let center = bounds.center();
    // Enlarged a little so no sample sits exactly on the root's border (by more than the f32
    // rounding of the coordinates), in proportion to the input's own scale so that the tree
    // does not depend on units; never zero.
    let half = 0.5 * extent * (1.0 + 1e-4) + 1e-6 * (extent + center.abs().max_element()) + 1e-30;
    let builder = Builder::new(params, center, diagonal, noise);

    let mut work: Vec<TreeSample> = threads.run(|| {
        (samples.positions.par_iter(), samples.normals.par_iter())
            .into_par_iter()
            .enumerate()
            .map(|(i, (&position, &normal))| TreeSample { position, normal, index: i as u32 })
            .collect()
    });
    let root = Node {
        start: 0,
        count: work.len() as u32,
        first_child: 0,
        parent: 0,
        center,
        half,
        frame: NO_FRAME,
        kind: NodeKind::Volume,
        depth: 0,
        child_count: 0,
        slot: 0,
    };
    let root_stats = threads.run(|| {
        let sums: Vec<CellStats> = work.par_chunks(STATS_CHUNK).map(|c| sum(c, builder.origin)).collect();
        sums.iter().fold(CellStats::default(), |mut total, s| {
            total.merge(s);
            total
        })
    });

    // Phase 1: the large nodes, on this thread.
    let mut part =
        Part { nodes: vec![root], frames: Vec::new(), shared_frames: &[], samples: &mut work, sample_base: 0 };
    let mut pending = builder.grow(&mut part, (0, root_stats), Some(threads));
    let Part { mut nodes, mut frames, .. } = part;
    progress.report(0.2, "building tree")?;

    // Phase 2: the subtrees below them, in parallel, in batches so progress can be reported.
    pending.sort_by_key(|&(i, _)| nodes[i].start);
    let jobs = carve(&mut work, pending.iter().map(|&(i, stats)| (i, nodes[i], stats)));
    let total = samples.len().max(1) as f32;
    let mut done = 0usize;
    let mut results = Vec::with_capacity(jobs.len());
    let mut jobs = jobs.into_iter().peekable();
    while jobs.peek().is_some() {
        let mut batch = Vec::new();
        let mut batch_samples = 0usize;
        while let Some(job) = jobs.next_if(|_| batch_samples < samples.len() / 16 + 1) {
            batch_samples += job.node.count as usize;
            batch.push(job);
        }
        let shared: &[Frame] = &frames;
        results.extend(threads.run(|| {
            batch
                .into_par_iter()
                .map(|job| {
                    let (index, stats) = (job.index, job.stats);
                    let mut part = job.into_part(shared);
                    builder.grow(&mut part, (0, stats), None);
                    (index, part.nodes, part.frames)
                })
                .collect::<Vec<_>>()
        }));
        done += batch_samples;
        progress.report(0.2 + 0.8 * done as f32 / total, "building tree")?;
    }

    let shared_len = frames.len() as u32;
    for (i, local_nodes, local_frames) in results {
        append_part(&mut nodes, &mut frames, i, local_nodes, local_frames, shared_len);
    }
    Ok(VsTree { nodes, frames, samples: work, diagonal, params: *params, noise })
}

fn check_samples(samples: &SampleSet) -> Result<()> {
    if samples.is_empty() {
        return Err(Error::input("no samples"));
    }
    if samples.normals.len() != samples.len() {
        return Err(Error::input(format!("{} normals for {} samples", samples.normals.len(), samples.len())));
    }
    if samples.len() >= u32::MAX as usize {
        return Err(Error::TooLarge(format!("{} samples (at most {})", samples.len(), u32::MAX - 1)));
    }
    check_positions(&samples.positions, "sample")?;
    if let Some(i) = samples.normals.iter().position(|n| !n.is_finite()) {
        return Err(Error::input(format!("sample {i} has a NaN or infinite normal")));
    }
    Ok(())
}

/// A piece of the tree under construction: its nodes, the frames it created, and the samples
/// it owns. Frames numbered below `shared_frames.len()` were made earlier; a local frame `k`
/// is numbered `shared_frames.len() + k` until it is appended.
pub(super) struct Part<'a> {
    pub(super) nodes: Vec<Node>,
    pub(super) frames: Vec<Frame>,
    pub(super) shared_frames: &'a [Frame],
    pub(super) samples: &'a mut [TreeSample],
    /// Index in the whole sample array of `samples[0]`.
    pub(super) sample_base: u32,
}

impl Part<'_> {
    fn frame(&self, index: u32) -> &Frame {
        let shared = self.shared_frames.len();
        match (index as usize).checked_sub(shared) {
            Some(local) => &self.frames[local],
            None => &self.shared_frames[index as usize],
        }
    }

    pub(super) fn slice(&mut self, node: &Node) -> &mut [TreeSample] {
        let lo = (node.start - self.sample_base) as usize;
        &mut self.samples[lo..lo + node.count as usize]
    }
}

/// One subtree of phase 2: the node that roots it, its sums, and the samples it owns.
pub(super) struct Job<'a> {
    pub(super) index: usize,
    pub(super) node: Node,
    pub(super) stats: CellStats,
    pub(super) samples: &'a mut [TreeSample],
}

#[derive(Clone, Copy)]
pub(super) struct Builder {
    params: TreeParams,
    /// Sums are taken relative to this point (the root's centre).
    pub(super) origin: DVec3,
    /// The L2 bound in absolute (squared) units.
    abs_error: f64,
    min_half: f32,
    /// The samples' noise level (absolute).
    noise: f32,
}

impl Builder {
    /// The builder of a tree whose root is centred on `center`, over samples whose bounding
    /// box has diagonal `diagonal` and scatter about their surface by `noise`.
    pub(super) fn new(params: &TreeParams, center: Vec3, diagonal: f32, noise: f32) -> Builder {
        Builder {
            params: *params,
            origin: center.as_dvec3(),
            abs_error: params.error * f64::from(diagonal).powi(2),
            min_half: (0.5 * params.min_cell_size * f64::from(diagonal)) as f32,
            noise,
        }
    }

    /// Processes node `first` and all its descendants, depth first. With `big` set (phase 1),
    /// nodes with at most [`FRONTIER`] samples are left unprocessed and returned.
    fn grow(&self, part: &mut Part, first: Pending, big: Option<&Threads>) -> Vec<Pending> {
        let mut pending = Vec::new();
        let mut stack = vec![first];
        while let Some((i, stats)) = stack.pop() {
            if big.is_some() && part.nodes[i].count <= FRONTIER {
                pending.push((i, stats));
                continue;
            }
            let children = self.process(part, i, &stats, big);
            stack.extend(children.into_iter().rev());
        }
        pending
    }

    /// Decides what node `i` (whose samples sum to `stats`) is: a leaf, a T-node, or split; and
    /// creates its children, returned with their sums.
    fn process(&self, part: &mut Part, i: usize, stats: &CellStats, threads: Option<&Threads>) -> Vec<Pending> {
        self.classify(part, i, stats);
        let node = &part.nodes[i];
        if self.error(part, node, stats) <= self.threshold() && !self.volume_above_noise(node, stats) {
            return Vec::new();
        }
        self.split(part, i, threads)
    }

    /// Makes a V-node a T-node (with its frame) when the height-field indicator holds; called
    /// once per node, when it is first processed.
    pub(super) fn classify(&self, part: &mut Part, i: usize, stats: &CellStats) {
        let node = part.nodes[i];
        if node.kind != NodeKind::Volume || self.params.kind != TreeKind::VsTree {
            return;
        }
        let slice = part.slice(&node);
        let centroid = (stats.centroid() + self.origin).as_vec3();
        let reach = reach(centroid, node.center, node.half);
        let (d_a, d_d) = (self.params.d_a, self.params.d_d);
        if is_height_field(slice, centroid, stats.mean_normal(), reach, d_a, d_d, NOISE_HEIGHTS * self.noise) {
            let f = frame(slice, stats, self.origin);
            let index = (part.shared_frames.len() + part.frames.len()) as u32;
            part.frames.push(f);
            let n = &mut part.nodes[i];
            n.kind = NodeKind::Transition;
            n.frame = index;
        }
    }

    /// The node's error ([`Metric::cell_error`], allowing for the noise) in the units of
    /// [`Builder::threshold`].
    pub(super) fn error(&self, part: &Part, node: &Node, stats: &CellStats) -> f64 {
        self.error_with(node, |f| part.frame(f), stats)
    }

    /// [`Builder::error`] of a node of a whole tree, whose frames are all in `frames`.
    pub(super) fn error_among(&self, frames: &[Frame], node: &Node, stats: &CellStats) -> f64 {
        self.error_with(node, |f| &frames[f as usize], stats)
    }

    fn error_with<'f>(&self, node: &Node, frame_of: impl Fn(u32) -> &'f Frame, stats: &CellStats) -> f64 {
        let frame = (node.kind == NodeKind::Surface).then(|| frame_of(node.frame));
        self.params.metric.cell_error(node, frame, stats, self.origin, self.noise)
    }

    /// Whether `node` is a V-node larger than the noise whose error only the noise allowance
    /// brings under the bound (see [`VOLUME_NOISE_HALVES`]).
    fn volume_above_noise(&self, node: &Node, stats: &CellStats) -> bool {
        node.kind == NodeKind::Volume
            && self.noise > 0.0
            && node.half > VOLUME_NOISE_HALVES * self.noise
            && self.params.metric.cell_error(node, None, stats, self.origin, 0.0) > self.threshold()
    }

    /// The bound on [`Builder::error`] below which a node is a leaf.
    fn threshold(&self) -> f64 {
        match self.params.metric {
            Metric::L2 => self.abs_error,
            Metric::L21 | Metric::Density => self.params.error,
        }
    }

    /// Splits node `i` (already classified) into its octants or quadrants, unless it is too
    /// small, too deep or a single sample; returns the children with their sums.
    pub(super) fn split(&self, part: &mut Part, i: usize, threads: Option<&Threads>) -> Vec<Pending> {
        let node = part.nodes[i];
        if node.count <= 1 || self.limit(&node).is_some() {
            return Vec::new();
        }
        match node.kind {
            NodeKind::Volume => self.split_octants(part, i, threads),
            NodeKind::Transition => {
                let f = *part.frame(node.frame);
                let center = Vec3::new(f.square_center.x, f.square_center.y, 0.0);
                self.split_quadrants(part, i, center, f.square_half, threads)
            }
            NodeKind::Surface => self.split_quadrants(part, i, node.center, node.half, threads),
        }
    }

    /// The limit that keeps `node` from being split, by its parameter's name: `max_depth` at the
    /// deepest level allowed, `min_cell_size` for a cell that small; None when its bound (or a
    /// single sample) decides.
    pub(super) fn limit(&self, node: &Node) -> Option<&'static str> {
        if u32::from(node.depth) >= self.params.max_depth {
            Some("max_depth")
        } else if node.half <= self.min_half {
            Some("min_cell_size")
        } else {
            None
        }
    }

    fn split_octants(&self, part: &mut Part, i: usize, threads: Option<&Threads>) -> Vec<Pending> {
        let node = part.nodes[i];
        let c = node.center;
        let octant = |s: &TreeSample| {
            let p = s.position;
            (p.x >= c.x) as usize | ((p.y >= c.y) as usize) << 1 | ((p.z >= c.z) as usize) << 2
        };
        let stats = partition::<8>(part.slice(&node), octant, self.origin, threads);
        let q = 0.5 * node.half;
        add_children(part, i, &stats, NodeKind::Volume, NO_FRAME, |slot| {
            let sign = |bit: usize| if slot >> bit & 1 == 1 { q } else { -q };
            (c + Vec3::new(sign(0), sign(1), sign(2)), q)
        })
    }

    /// Splits node `i` (a T-node or S-node) into the quadrants of the square `center ± half`
    /// (in its frame's plane coordinates).
    fn split_quadrants(
        &self,
        part: &mut Part,
        i: usize,
        center: Vec3,
        half: f32,
        threads: Option<&Threads>,
    ) -> Vec<Pending> {
        let node = part.nodes[i];
        let f = *part.frame(node.frame);
        let c = center.truncate();
        let quadrant = |s: &TreeSample| {
            let q: Vec2 = f.project(s.position);
            (q.x >= c.x) as usize | ((q.y >= c.y) as usize) << 1
        };
        let stats = partition::<4>(part.slice(&node), quadrant, self.origin, threads);
        let q = 0.5 * half;
        add_children(part, i, &stats, NodeKind::Surface, node.frame, |slot| {
            let sign = |bit: usize| if slot >> bit & 1 == 1 { q } else { -q };
            (Vec3::new(c.x + sign(0), c.y + sign(1), 0.0), q)
        })
    }
}

pub(super) fn sum(samples: &[TreeSample], origin: DVec3) -> CellStats {
    let mut stats = CellStats::default();
    for s in samples {
        stats.add(s.position.as_dvec3() - origin, s.normal.as_dvec3());
    }
    stats
}

/// Appends one child per non-empty bucket (in bucket order) to node `i`.
fn add_children(
    part: &mut Part,
    i: usize,
    buckets: &[CellStats],
    kind: NodeKind,
    frame: u32,
    cell: impl Fn(usize) -> (Vec3, f32),
) -> Vec<Pending> {
    let parent = part.nodes[i];
    let first = part.nodes.len();
    let mut start = parent.start;
    let mut children = Vec::with_capacity(buckets.len());
    for (slot, stats) in buckets.iter().enumerate() {
        let count = stats.count as u32;
        if count > 0 {
            let (center, half) = cell(slot);
            children.push((part.nodes.len(), *stats));
            part.nodes.push(Node {
                start,
                count,
                first_child: 0,
                parent: i as u32,
                center,
                half,
                frame,
                kind,
                depth: parent.depth + 1,
                child_count: 0,
                slot: slot as u8,
            });
        }
        start += count;
    }
    let n = &mut part.nodes[i];
    n.first_child = first as u32;
    n.child_count = children.len() as u8;
    children
}

impl<'a> Job<'a> {
    /// The part of the tree this job grows: its root node alone over its own samples, frames
    /// numbered after `shared`.
    pub(super) fn into_part(self, shared: &'a [Frame]) -> Part<'a> {
        Part {
            nodes: vec![self.node],
            frames: Vec::new(),
            shared_frames: shared,
            samples: self.samples,
            sample_base: self.node.start,
        }
    }
}

/// Splits `samples` into the disjoint ranges of the given nodes (sorted by start).
pub(super) fn carve(samples: &mut [TreeSample], nodes: impl Iterator<Item = (usize, Node, CellStats)>) -> Vec<Job<'_>> {
    let mut rest = samples;
    let mut consumed = 0usize;
    let mut jobs = Vec::new();
    for (index, node, stats) in nodes {
        let skip = node.start as usize - consumed;
        let (_, tail) = std::mem::take(&mut rest).split_at_mut(skip);
        let (mine, tail) = tail.split_at_mut(node.count as usize);
        rest = tail;
        consumed = node.start as usize + node.count as usize;
        jobs.push(Job { index, node, stats, samples: mine });
    }
    jobs
}

/// Appends a part built in phase 2 under node `i`: its local node 0 replaces node `i`, the
/// others are appended with their indices shifted; local frames likewise.
pub(super) fn append_part(
    nodes: &mut Vec<Node>,
    frames: &mut Vec<Frame>,
    i: usize,
    local: Vec<Node>,
    local_frames: Vec<Frame>,
    shared: u32,
) {
    let node_base = nodes.len() as u32;
    let frame_base = frames.len() as u32;
    let node_index = |j: u32| if j == 0 { i as u32 } else { node_base + j - 1 };
    let frame_index = |f: u32| {
        if f == NO_FRAME || f < shared {
            f
        } else {
            frame_base + (f - shared)
        }
    };
    for (j, mut n) in local.into_iter().enumerate() {
        if n.child_count > 0 {
            n.first_child = node_index(n.first_child);
        }
        n.frame = frame_index(n.frame);
        if j == 0 {
            nodes[i] = n; // keeps its parent, which is already global
        } else {
            n.parent = node_index(n.parent);
            nodes.push(n);
        }
    }
    frames.extend(local_frames);
}
