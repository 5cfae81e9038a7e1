//! The bounding volume hierarchy behind [`super::TriangleBvh`]: items given by their boxes,
//! sorted along a Morton curve and split where their codes' common prefix ends (a linear BVH,
//! Lauterbach et al. 2009), stored in flat arrays linked by `u32` indices with each leaf's items
//! contiguous. A search descends the nearer child first and prunes every box farther than the
//! best distance so far, so its answer is exact.

use glam::Vec3;
use rayon::prelude::*;

/// A node of a [`Bvh`]: its box, and either a range of items (leaf, `count > 0`) or the index
/// of the first of its two adjacent children (`count == 0`).
#[derive(Clone, Copy, Debug)]
struct Node {
    min: Vec3,
    max: Vec3,
    first: u32,
    count: u32,
}

impl Node {
    /// Squared distance from `p` to the node's box (0 inside).
    fn distance_squared(&self, p: Vec3) -> f32 {
        (self.min - p).max(p - self.max).max(Vec3::ZERO).length_squared()
    }
}

/// Deeper than any of our trees gets: a Morton split takes at least one of the code's 63 bits,
/// then halves equal codes (32 levels for 2^32). The traversal stack needs at most one entry
/// per level plus one.
const MAX_STACK: usize = 128;

/// The shape of a bounding volume hierarchy over items given by their boxes; `order[i]` is the
/// item stored at position `i`, so each leaf covers `order[first..first + count]`.
#[derive(Clone, Debug, Default)]
pub(super) struct Bvh {
    nodes: Vec<Node>,
    pub(super) order: Vec<u32>,
}

/// Subtrees over more items than this build their two halves in parallel. The tree does not
/// depend on it (nor on the thread count): only who builds which part.
const PARALLEL_BUILD: usize = 1 << 15;

/// Spreads the low 21 bits of `x` to every third bit (for a 63-bit Morton code).
fn spread_bits(x: u64) -> u64 {
    let mut x = x & 0x1f_ffff;
    x = (x | x << 32) & 0x1f_0000_0000_ffff;
    x = (x | x << 16) & 0x1f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}

/// Items sorted along a Morton curve: (code of the box's centre, index), ties by index.
fn morton_order(boxes: &[(Vec3, Vec3)]) -> Vec<(u64, u32)> {
    let centre = |(lo, hi): &(Vec3, Vec3)| (*lo + *hi) * 0.5;
    let (lo, hi) = boxes
        .par_iter()
        .map(|b| (centre(b), centre(b)))
        .reduce(|| (Vec3::INFINITY, Vec3::NEG_INFINITY), |a, b| (a.0.min(b.0), a.1.max(b.1)));
    let scale = ((1u32 << 21) - 1) as f32 / (hi - lo).max_element().max(f32::MIN_POSITIVE);
    let mut codes: Vec<(u64, u32)> = boxes
        .par_iter()
        .enumerate()
        .map(|(i, b)| {
            let q = ((centre(b) - lo) * scale).clamp(Vec3::ZERO, Vec3::splat(((1u32 << 21) - 1) as f32));
            let code = spread_bits(q.x as u64) | spread_bits(q.y as u64) << 1 | spread_bits(q.z as u64) << 2;
            (code, i as u32)
        })
        .collect();
    codes.par_sort_unstable();
    codes
}

/// Where to split a run of Morton-sorted items: at the highest bit in which its first and last
/// codes differ (the items below share a prefix), or in the middle of equal codes.
fn morton_split(items: &[(u64, u32)]) -> usize {
    let (first, last) = (items[0].0, items[items.len() - 1].0);
    if first == last {
        return items.len() / 2;
    }
    let bit = 63 - (first ^ last).leading_zeros();
    items.partition_point(|&(code, _)| code >> bit & 1 == 0)
}

/// The nodes of a hierarchy over Morton-sorted items (see [`Bvh::build_morton`]) that sit at
/// position `offset` of the full order. The root comes first, the two children of a node are
/// adjacent, and every node's box is the union of its children's. Leaves' `first` is a position
/// in the full order; inner nodes' `first` indexes the returned vector.
fn morton_subtree(items: &[(u64, u32)], boxes: &[(Vec3, Vec3)], offset: usize, leaf_size: usize) -> Vec<Node> {
    if items.len() > PARALLEL_BUILD {
        let middle = morton_split(items);
        let (low, high) = items.split_at(middle);
        let (left, right) = rayon::join(
            || morton_subtree(low, boxes, offset, leaf_size),
            || morton_subtree(high, boxes, offset + middle, leaf_size),
        );
        let (min, max) = (left[0].min.min(right[0].min), left[0].max.max(right[0].max));
        return join_subtrees(Node { min, max, first: 1, count: 0 }, left, right);
    }
    let blank = Node { min: Vec3::ZERO, max: Vec3::ZERO, first: 0, count: 0 };
    let mut nodes = Vec::with_capacity(4 * items.len() / leaf_size + 1);
    let mut ranges = vec![(0usize, 0usize)];
    nodes.push(blank);
    let mut pending = vec![(0usize, 0usize, items.len())];
    // Top-down: the splits. Children always come after their parent.
    while let Some((node, start, end)) = pending.pop() {
        if end - start <= leaf_size {
            nodes[node].first = (offset + start) as u32;
            nodes[node].count = (end - start) as u32;
            ranges[node] = (start, end);
            continue;
        }
        let middle = start + morton_split(&items[start..end]);
        let left = nodes.len();
        nodes.extend([blank, blank]);
        ranges.extend([(0, 0), (0, 0)]);
        nodes[node].first = left as u32;
        pending.push((left + 1, middle, end));
        pending.push((left, start, middle));
    }
    // Bottom-up: the boxes.
    for k in (0..nodes.len()).rev() {
        let (min, max) = if nodes[k].count > 0 {
            let (start, end) = ranges[k];
            items[start..end].iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &(_, i)| {
                let (bmin, bmax) = boxes[i as usize];
                (lo.min(bmin), hi.max(bmax))
            })
        } else {
            let (l, r) = (&nodes[nodes[k].first as usize], &nodes[nodes[k].first as usize + 1]);
            (l.min.min(r.min), l.max.max(r.max))
        };
        nodes[k].min = min;
        nodes[k].max = max;
    }
    nodes
}

/// `root` over two subtrees, laid out [root, left root, right root, rest of left, rest of
/// right]. Children indices inside a subtree are never 0, so they shift by where that
/// subtree's rest now starts.
fn join_subtrees(root: Node, left: Vec<Node>, right: Vec<Node>) -> Vec<Node> {
    let shift = |node: &Node, by: usize| Node {
        first: if node.count == 0 { node.first + by as u32 } else { node.first },
        ..*node
    };
    let mut nodes = Vec::with_capacity(1 + left.len() + right.len());
    nodes.push(root);
    nodes.push(shift(&left[0], 2));
    nodes.push(shift(&right[0], left.len() + 1));
    nodes.extend(left[1..].iter().map(|n| shift(n, 2)));
    nodes.extend(right[1..].iter().map(|n| shift(n, left.len() + 1)));
    nodes
}

impl Bvh {
    /// Builds the hierarchy over items with boxes `boxes[i] = (min, max)`, at most `leaf_size`
    /// items per leaf: the items are sorted along a Morton curve and each node is split where
    /// its codes' common prefix ends.
    pub(super) fn build_morton(boxes: &[(Vec3, Vec3)], leaf_size: usize) -> Bvh {
        if boxes.is_empty() {
            return Bvh::default();
        }
        let items = morton_order(boxes);
        let nodes = morton_subtree(&items, boxes, 0, leaf_size.max(1));
        Bvh { nodes, order: items.iter().map(|&(_, i)| i).collect() }
    }

    /// The item minimising `item_distance_squared(position)` over positions (indices into
    /// `order`), with its squared distance; `None` when empty or nothing compares below
    /// infinity (a NaN query). Ties keep the first found.
    pub(super) fn nearest(&self, p: Vec3, item_distance_squared: impl Fn(usize) -> f32) -> Option<(usize, f32)> {
        let root = self.nodes.first()?;
        let mut best: Option<(usize, f32)> = None;
        let mut best_d2 = f32::INFINITY;
        let mut stack = [0u32; MAX_STACK];
        let mut depth = 0;
        if root.distance_squared(p) < best_d2 {
            stack[0] = 0;
            depth = 1;
        }
        while depth > 0 {
            depth -= 1;
            let node = &self.nodes[stack[depth] as usize];
            // The box may have become too far since it was pushed.
            if node.distance_squared(p) >= best_d2 {
                continue;
            }
            if node.count > 0 {
                for position in node.first as usize..(node.first + node.count) as usize {
                    let d2 = item_distance_squared(position);
                    if d2 < best_d2 {
                        best_d2 = d2;
                        best = Some((position, d2));
                    }
                }
                continue;
            }
            let (left, right) = (node.first, node.first + 1);
            let dl = self.nodes[left as usize].distance_squared(p);
            let dr = self.nodes[right as usize].distance_squared(p);
            // Push the farther child first so the nearer one is searched first.
            let (near, d_near, far, d_far) = if dl <= dr { (left, dl, right, dr) } else { (right, dr, left, dl) };
            if d_far < best_d2 && depth < MAX_STACK {
                stack[depth] = far;
                depth += 1;
            }
            if d_near < best_d2 && depth < MAX_STACK {
                stack[depth] = near;
                depth += 1;
            }
        }
        best
    }

    /// Checks what a search relies on: `order` is a permutation, every item sits in exactly one
    /// leaf of at most `leaf_size` items, no path is deeper than the search's stack, each
    /// child's box lies inside its parent's and each item's box (`item_box(position)`) inside
    /// its leaf's. The first broken rule, named, as the error.
    pub(super) fn validate(&self, leaf_size: usize, item_box: impl Fn(usize) -> (Vec3, Vec3)) -> Result<(), String> {
        let n = self.order.len();
        let mut is_item = vec![false; n];
        for &item in &self.order {
            if item as usize >= n || std::mem::replace(&mut is_item[item as usize], true) {
                return Err(format!("order is not a permutation of 0..{n} (item {item})"));
            }
        }
        if self.nodes.is_empty() {
            return if n == 0 { Ok(()) } else { Err(format!("{n} items and no node")) };
        }
        let mut in_leaf = vec![false; n];
        let mut stack = vec![(0usize, 1usize)];
        while let Some((i, depth)) = stack.pop() {
            if depth >= MAX_STACK {
                return Err(format!("node {i} is deeper than the search's stack"));
            }
            let node = self.nodes[i];
            let inside = |(lo, hi): (Vec3, Vec3)| lo.cmpge(node.min).all() && hi.cmple(node.max).all();
            if node.count > 0 {
                if node.count as usize > leaf_size {
                    return Err(format!("leaf {i} holds {} items (at most {leaf_size})", node.count));
                }
                let (first, end) = (node.first as usize, (node.first + node.count) as usize);
                if end > n {
                    return Err(format!("leaf {i} reaches position {end} of {n}"));
                }
                for (position, seen) in in_leaf[first..end].iter_mut().enumerate().map(|(k, s)| (first + k, s)) {
                    if std::mem::replace(seen, true) {
                        return Err(format!("position {position} is in two leaves"));
                    }
                    if !inside(item_box(position)) {
                        return Err(format!("item at position {position} sticks out of leaf {i}"));
                    }
                }
                continue;
            }
            for child in [node.first as usize, node.first as usize + 1] {
                if child <= i || child >= self.nodes.len() {
                    return Err(format!("node {i} links to child {child}"));
                }
                if !inside((self.nodes[child].min, self.nodes[child].max)) {
                    return Err(format!("child {child} sticks out of node {i}"));
                }
                stack.push((child, depth + 1));
            }
        }
        match in_leaf.iter().position(|&seen| !seen) {
            Some(position) => Err(format!("position {position} is in no leaf")),
            None => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    fn random_boxes(n: usize, seed: u64) -> Vec<(Vec3, Vec3)> {
        let mut rng = Rng::new(seed);
        (0..n)
            .map(|_| {
                let p = Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 2.0 - Vec3::ONE;
                (p, p + Vec3::splat(rng.f32() * 0.01))
            })
            .collect()
    }

    fn validate(bvh: &Bvh, boxes: &[(Vec3, Vec3)]) -> Result<(), String> {
        bvh.validate(4, |position| boxes[bvh.order[position] as usize])
    }

    #[test]
    fn parallel_build_is_valid_and_thread_independent() {
        let boxes = random_boxes(5 * PARALLEL_BUILD + 123, 3);
        let build = |threads| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| Bvh::build_morton(&boxes, 4))
        };
        let (one, two) = (build(1), build(2));
        validate(&two, &boxes).unwrap();
        assert_eq!(one.order, two.order);
        assert_eq!(format!("{:?}", one.nodes), format!("{:?}", two.nodes));
        // Many equal centres (duplicated triangles): split in the middle, still valid.
        let repeated: Vec<(Vec3, Vec3)> = boxes.iter().take(100).cycle().take(3 * PARALLEL_BUILD).copied().collect();
        validate(&Bvh::build_morton(&repeated, 4), &repeated).unwrap();
        validate(&Bvh::build_morton(&[], 4), &[]).unwrap();
    }

    #[test]
    fn validate_names_each_broken_rule() {
        let boxes = random_boxes(200, 4);
        let good = Bvh::build_morton(&boxes, 4);
        let broken = |change: &dyn Fn(&mut Bvh)| {
            let mut bvh = good.clone();
            change(&mut bvh);
            validate(&bvh, &boxes).unwrap_err()
        };
        assert!(broken(&|b| b.order[1] = b.order[0]).contains("permutation"));
        assert!(broken(&|b| b.nodes[0].max = b.nodes[0].min).contains("sticks out"));
        let leaf = good.nodes.iter().position(|n| n.count > 1).unwrap();
        assert!(broken(&|b| b.nodes[leaf].count -= 1).contains("in no leaf"));
        assert!(broken(&|b| b.nodes[leaf].count = 9).contains("at most 4"));
        let inner = good.nodes.iter().rposition(|n| n.count == 0).unwrap();
        assert!(broken(&|b| b.nodes[inner].first = 0).contains("links to child"));
    }
}
