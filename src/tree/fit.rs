//! A tree with a given number of leaves instead of an error bound: starting from the root, the
//! node with the largest error (the metric the tree was built with) is replaced by its children
//! until there are enough leaves. Nodes the tree already has are reused; leaves are split as
//! [`build`](super::build) would split them, so the result does not depend on the bound the
//! tree was built with, only on the number of leaves asked for, except where nodes have equal
//! errors (flat CAD faces have zero error): ties go to the lower node index, and indices
//! depend on how the tree was built. Nodes below the new leaves are dropped. This is how a simplification reaches a triangle count inside one tree, without
//! rebuilding it for trial bounds.

use super::build::{sum, Builder, Part, Pending};
use super::{Node, VsTree};
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

/// Reshapes `tree` to `leaves` leaves (a little more when the last split adds several, fewer
/// when no leaf can be split any more: single samples, the depth or cell-size limits), by
/// splitting the node with the largest error first. Returns the number of leaves. The tree's
/// `params.error` is left as it was: it no longer describes the leaves.
pub fn fit(tree: &mut VsTree, leaves: usize, threads: &Threads) -> usize {
    let leaves = leaves.max(1);
    let builder = Builder::new(&tree.params, tree.root().center, tree.diagonal, tree.noise);
    let mut stats = node_stats(tree, builder.origin, threads);
    let mut expanded = vec![false; tree.nodes.len()];
    let mut part = Part {
        nodes: std::mem::take(&mut tree.nodes),
        frames: std::mem::take(&mut tree.frames),
        shared_frames: &[],
        samples: &mut tree.samples,
        sample_base: 0,
    };
    let mut queue = BinaryHeap::new();
    queue.push(Queued { error: builder.error(&part, &part.nodes[0], &stats[0]), node: 0 });
    let mut count = 1usize;
    let mut kept = 0usize; // leaves that cannot be split: out of the queue, still leaves
    while count < leaves {
        let Some(Queued { node: i, .. }) = queue.pop() else { break };
        let i = i as usize;
        let node = part.nodes[i];
        let children: Vec<usize> = if node.is_leaf() {
            // Large nodes are partitioned in parallel chunks, as in the build.
            let new: Vec<Pending> = builder.split(&mut part, i, Some(threads));
            for &(c, s) in &new {
                stats.push(s);
                expanded.push(false);
                debug_assert_eq!(stats.len(), c + 1);
                builder.classify(&mut part, c, &stats[c]);
            }
            new.into_iter().map(|(c, _)| c).collect()
        } else {
            node.children().collect()
        };
        if children.is_empty() {
            kept += 1;
            continue;
        }
        expanded[i] = true;
        count += children.len() - 1;
        for c in children {
            queue.push(Queued { error: builder.error(&part, &part.nodes[c], &stats[c]), node: c as u32 });
        }
    }
    debug_assert_eq!(count, queue.len() + kept);
    let Part { nodes, frames, .. } = part;
    tree.nodes = prune(nodes, &expanded);
    tree.frames = frames;
    count
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
        let mesh = shapes::torus(1.0, 0.3, 96, 48);
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
    fn stops_when_nothing_can_be_split() {
        let mut tree = tree_of(1e-3, TreeKind::VsTree, Metric::L2);
        let samples = tree.samples.len();
        let got = fit(&mut tree, 10 * samples, &Threads::new(1).unwrap());
        tree.validate().unwrap();
        assert!(got <= samples && got > samples / 2, "{got} leaves for {samples} samples");
    }
}
