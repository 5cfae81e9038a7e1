//! A tree with a given number of leaves instead of an error bound: starting from the root, the
//! node with the largest error (the metric the tree was built with) is replaced by its children
//! until there are enough leaves. Nodes the tree already has are reused; leaves are split as
//! [`build`](super::build) would split them, so the result does not depend on the bound the
//! tree was built with, only on the number of leaves asked for, except where nodes have equal
//! errors (flat CAD faces have zero error): ties go to the lower node index, and indices
//! depend on how the tree was built. Nodes below the new leaves are dropped. This is how a simplification reaches a triangle count inside one tree, without
//! rebuilding it for trial bounds.

use super::build::{append_part, carve, sum, Builder, Part};
use super::{Frame, Node, TreeSample, VsTree};
use crate::progress::Threads;
use crate::quadric::CellStats;
use rayon::prelude::*;
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// A node waiting in the queue, ordered by error, then by index (lower first) so that ties
/// break the same way every time.
struct Queued {
    error: f64,
    node: u32,
}

impl PartialEq for Queued {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}
impl Eq for Queued {}
impl PartialOrd for Queued {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Queued {
    fn cmp(&self, other: &Self) -> Ordering {
        self.error.total_cmp(&other.error).then_with(|| other.node.cmp(&self.node))
    }
}

/// Most leaves one split adds: an octant split replaces one leaf by up to 8.
const MOST_NEW_LEAVES: usize = 7;

/// A batch takes one node from the queue per this many leaves still missing (a count of
/// leaves): 7 would never pass the count asked for by more than one split, 4 times that keeps
/// the batches small enough that a split node's child whose error is above the rest of its
/// batch is split in the next batch before them, as one node at a time would. On the torus of
/// the tests a batch of a 7th gave 97.4% of the one-at-a-time leaves, a 28th all of them.
const LEAVES_PER_BATCH_NODE: usize = 4 * MOST_NEW_LEAVES;

/// Batches with fewer leaves to split than this split them one by one (each large one with its
/// samples partitioned in parallel, as in the build's first phase); larger batches split their
/// leaves on all threads at once.
const PARALLEL_SPLITS: usize = 256;

/// Reshapes `tree` to `leaves` leaves (a little more when the last split adds several, fewer
/// when no leaf can be split any more: single samples, the depth or cell-size limits), by
/// splitting the nodes with the largest errors first. Returns the number of leaves. The tree's
/// `params.error` is left as it was: it no longer describes the leaves.
///
/// The nodes are taken from the queue in batches (see [`LEAVES_PER_BATCH_NODE`]), and a
/// batch's leaves are split in parallel: nearly the nodes one at a time would split (that
/// order would split a child whose error is above the rest of its batch before them).
pub fn fit(tree: &mut VsTree, leaves: usize, threads: &Threads) -> usize {
    fit_in_batches(tree, leaves, threads, LEAVES_PER_BATCH_NODE)
}

/// [`fit`], its batches as large as the leaves still missing over `per_node` (at least 1):
/// [`LEAVES_PER_BATCH_NODE`] in use, `usize::MAX` one node at a time (the tests compare the two).
fn fit_in_batches(tree: &mut VsTree, leaves: usize, threads: &Threads, per_node: usize) -> usize {
    let leaves = leaves.max(1);
    let builder = Builder::new(&tree.params, tree.root().center, tree.diagonal, tree.noise);
    let mut stats = node_stats(tree, builder.origin, threads);
    let mut expanded = vec![false; tree.nodes.len()];
    let mut nodes = std::mem::take(&mut tree.nodes);
    let mut frames = std::mem::take(&mut tree.frames);
    let samples: &mut [TreeSample] = &mut tree.samples;
    let mut queue = BinaryHeap::new();
    queue.push(Queued { error: builder.error_among(&frames, &nodes[0], &stats[0]), node: 0 });
    let mut count = 1usize;
    let mut kept = 0usize; // leaves that cannot be split: out of the queue, still leaves
    while count < leaves {
        let size = ((leaves - count) / per_node).max(1);
        let batch: Vec<usize> = std::iter::from_fn(|| queue.pop()).take(size).map(|q| q.node as usize).collect();
        if batch.is_empty() {
            break;
        }
        let to_split: Vec<usize> = batch.iter().copied().filter(|&i| nodes[i].is_leaf()).collect();
        if to_split.len() < PARALLEL_SPLITS {
            let mut part = Part { nodes, frames, shared_frames: &[], samples: &mut *samples, sample_base: 0 };
            for &i in &to_split {
                for (c, s) in builder.split(&mut part, i, Some(threads)) {
                    builder.classify(&mut part, c, &s);
                    stats.push(s);
                }
            }
            (nodes, frames) = (part.nodes, part.frames);
        } else {
            split_in_parallel(&builder, &mut nodes, &mut frames, samples, &to_split, &mut stats, threads);
        }
        expanded.resize(nodes.len(), false);
        debug_assert_eq!(stats.len(), nodes.len());
        for i in batch {
            let children = nodes[i].children();
            if children.is_empty() {
                kept += 1;
                continue;
            }
            expanded[i] = true;
            count += children.len() - 1;
            for c in children {
                queue.push(Queued { error: builder.error_among(&frames, &nodes[c], &stats[c]), node: c as u32 });
            }
        }
    }
    debug_assert_eq!(count, queue.len() + kept);
    tree.nodes = prune(nodes, &expanded);
    tree.frames = frames;
    count
}

/// Splits the leaves `to_split` (disjoint: none is under another) on all threads, each in its
/// own part over its own samples, and appends their children (classified, their sums to
/// `stats`) and new frames.
fn split_in_parallel(
    builder: &Builder,
    nodes: &mut Vec<Node>,
    frames: &mut Vec<Frame>,
    samples: &mut [TreeSample],
    to_split: &[usize],
    stats: &mut Vec<CellStats>,
    threads: &Threads,
) {
    let mut order = to_split.to_vec();
    order.sort_by_key(|&i| nodes[i].start);
    let jobs = carve(samples, order.iter().map(|&i| (i, nodes[i], stats[i])));
    let shared: &[Frame] = frames;
    let parts: Vec<_> = threads.run(|| {
        jobs.into_par_iter()
            .map(|job| {
                let index = job.index;
                let mut part = job.into_part(shared);
                let children = builder.split(&mut part, 0, None);
                let mut sums = Vec::with_capacity(children.len());
                for (c, s) in children {
                    builder.classify(&mut part, c, &s);
                    sums.push(s);
                }
                (index, part.nodes, part.frames, sums)
            })
            .collect()
    });
    let shared_len = frames.len() as u32;
    for (i, local_nodes, local_frames, sums) in parts {
        append_part(nodes, frames, i, local_nodes, local_frames, shared_len);
        stats.extend(sums);
    }
}

/// The sums of every node's samples: leaves summed, the others merged from their children
/// (which always come after their parent).
fn node_stats(tree: &VsTree, origin: glam::DVec3, threads: &Threads) -> Vec<CellStats> {
    let mut stats: Vec<CellStats> = threads.run(|| {
        tree.nodes
            .par_iter()
            .map(|n| if n.is_leaf() { sum(tree.samples_of(n), origin) } else { CellStats::default() })
            .collect()
    });
    for i in (1..tree.nodes.len()).rev() {
        let parent = tree.nodes[i].parent as usize;
        let s = stats[i];
        stats[parent].merge(&s);
    }
    stats
}

/// Drops the nodes below the unexpanded ones, keeping the order of the rest (so children stay
/// contiguous) and renumbering their links.
fn prune(nodes: Vec<Node>, expanded: &[bool]) -> Vec<Node> {
    let mut keep = vec![false; nodes.len()];
    keep[0] = true;
    for i in 1..nodes.len() {
        let p = nodes[i].parent as usize;
        keep[i] = keep[p] && expanded[p];
    }
    if keep.iter().all(|&k| k) && nodes.iter().enumerate().all(|(i, n)| n.is_leaf() || expanded[i]) {
        return nodes;
    }
    let mut index = vec![u32::MAX; nodes.len()];
    for (next, (i, _)) in keep.iter().enumerate().filter(|(_, &k)| k).enumerate() {
        index[i] = next as u32;
    }
    nodes
        .into_iter()
        .enumerate()
        .filter(|&(i, _)| keep[i])
        .map(|(i, mut n)| {
            n.parent = index[n.parent as usize];
            if expanded[i] {
                n.first_child = index[n.first_child as usize];
            } else {
                n.first_child = 0;
                n.child_count = 0;
            }
            n
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::shapes;
    use crate::samples::{MeshSampling, SampleSet};
    use crate::tree::{build, Metric, TreeKind, TreeParams};
    use crate::Progress;

    fn tree_of(error: f64, kind: TreeKind, metric: Metric) -> VsTree {
        tree_of_torus(error, kind, metric, 96, 48)
    }

    fn tree_of_torus(error: f64, kind: TreeKind, metric: Metric, around: u32, across: u32) -> VsTree {
        let mesh = shapes::torus(1.0, 0.3, around, across);
        let samples = SampleSet::from_mesh(&mesh, MeshSampling::Vertices).unwrap();
        let params = TreeParams { error, kind, metric, ..Default::default() };
        build(&samples, &params, &Threads::new(1).unwrap(), &mut Progress::none()).unwrap()
    }

    fn leaf_ranges(tree: &VsTree) -> Vec<(u32, u32)> {
        let mut r: Vec<(u32, u32)> = tree.leaves().map(|i| (tree.nodes[i].start, tree.nodes[i].count)).collect();
        r.sort_unstable();
        r
    }

    #[test]
    fn grows_and_cuts_to_the_asked_count_with_a_valid_tree() {
        let threads = Threads::new(1).unwrap();
        for (kind, metric) in
            [(TreeKind::VsTree, Metric::L2), (TreeKind::Octree, Metric::L2), (TreeKind::VsTree, Metric::L21)]
        {
            for target in [1, 10, 100, 1000, 3000] {
                let mut tree = tree_of(1e-3, kind, metric);
                let got = fit(&mut tree, target, &threads);
                tree.validate().unwrap();
                assert_eq!(got, tree.leaves().count());
                // A split adds at most 7 leaves (8 octants for 1).
                assert!(got >= target && got < target + 7, "{kind:?} {metric:?}: {got} leaves for {target}");
            }
        }
    }

    #[test]
    fn the_result_does_not_depend_on_the_bound_the_tree_was_built_with() {
        let threads = Threads::new(2).unwrap();
        for target in [200, 700] {
            let mut coarse = tree_of(1e-1, TreeKind::VsTree, Metric::L2);
            let mut fine = tree_of(1e-5, TreeKind::VsTree, Metric::L2);
            let (c, f) = (coarse.leaves().count(), fine.leaves().count());
            assert!(c < target && f > target, "{c} {f}");
            fit(&mut coarse, target, &threads);
            fit(&mut fine, target, &threads);
            assert_eq!(leaf_ranges(&coarse), leaf_ranges(&fine), "target {target}");
        }
    }

    #[test]
    fn batches_split_nearly_the_nodes_one_at_a_time_would_on_any_thread_count() {
        // 32k samples and 20k leaves: the first batches hold hundreds of leaves to split,
        // split in parallel.
        let target = 20_000;
        let one_by_one = {
            let mut tree = tree_of_torus(1e-2, TreeKind::VsTree, Metric::L2, 256, 128);
            fit_in_batches(&mut tree, target, &Threads::new(1).unwrap(), usize::MAX);
            leaf_ranges(&tree)
        };
        let mut batched = Vec::new();
        for threads in [1, 2] {
            let mut tree = tree_of_torus(1e-2, TreeKind::VsTree, Metric::L2, 256, 128);
            let got = fit(&mut tree, target, &Threads::new(threads).unwrap());
            tree.validate().unwrap();
            assert!(got >= target && got < target + MOST_NEW_LEAVES, "{got} leaves for {target}");
            batched.push(leaf_ranges(&tree));
        }
        assert_eq!(batched[0], batched[1], "the thread count changed the leaves");
        let same = batched[0].iter().filter(|r| one_by_one.binary_search(r).is_ok()).count();
        assert!(same as f64 >= 0.99 * one_by_one.len() as f64, "{same} of {} leaves in common", one_by_one.len());
    }

    #[test]
    fn stops_when_nothing_can_be_split() {
        let mut tree = tree_of(1e-3, TreeKind::VsTree, Metric::L2);
        let samples = tree.samples.len();
        let got = fit(&mut tree, 10 * samples, &Threads::new(1).unwrap());
        tree.validate().unwrap();
        assert!(got <= samples && got > samples / 2, "{got} leaves for {samples} samples");
    }
}
