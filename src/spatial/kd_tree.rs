//! The point index: a balanced k-d tree in flat arrays for exact nearest-neighbour queries, the
//! k nearest ([`KdTree::knn`], [`KdTree::knn_all`]) or the nearest one, optionally among the
//! points a filter keeps and within a radius ([`KdTree::nearest`], [`KdTree::any_within`],
//! [`KdTree::distance_within`]).
//!
//! The tree is implicit: node `i` has children `2i + 1` and `2i + 2`, a node's points are a
//! contiguous range of one array, and each split halves its range (`mid = begin + len / 2`), so
//! no ranges or child links are stored, only one split (axis, value) per inner node. The split
//! axis is the widest side of the node's bounding box and the split value its median point.
//! Construction goes level by level, every node of a level in parallel, and every step is a
//! pure function of the input: the tree (and so every answer) is the same for any thread count.
//!
//! Queries are exact in `f32`: neighbours are ordered by squared distance (computed as
//! `dx*dx + dy*dy + dz*dz`, left to right), ties broken by the smaller input index, which is
//! what a brute-force scan with the same ordering returns. Distances a query returns are the
//! square roots of those.

use crate::error::{Error, Result};
use crate::mesh::check_positions;
use glam::Vec3;
use rayon::prelude::*;

/// Most points in a leaf: 16 measured slightly faster than 4..=12 for k = 10 on 1M points.
const LEAF: usize = 16;

/// Most neighbours a query may ask for (the candidate list is kept sorted by insertion).
pub const MAX_K: usize = 1024;

/// Points answered per parallel task in batch queries.
const BATCH: usize = 1024;

/// A point in the tree's order with its index in the input. 16 bytes: one load per candidate.
#[derive(Clone, Copy, Debug, Default)]
#[repr(C, align(16))]
struct Entry {
    p: [f32; 3],
    id: u32,
}

/// An inner node's splitting plane: `p[axis] <= value` on the left, `>= value` on the right.
#[derive(Clone, Copy, Debug)]
struct Split {
    value: f32,
    axis: u32,
}

/// One answer of a query: a point's index in the input and its squared distance to the query.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Neighbour {
    /// Index of the point in the slice the tree was built from.
    pub index: u32,
    /// Squared Euclidean distance to the query point.
    pub distance_squared: f32,
}

/// A k-d tree over a slice of points for exact k-nearest-neighbour queries.
#[derive(Clone, Debug, Default)]
pub struct KdTree {
    /// The points, permuted so that every node's points are contiguous.
    entries: Vec<Entry>,
    /// Splits of the inner nodes, in heap order; nodes from `splits.len()` on are leaves.
    splits: Vec<Split>,
}

/// The squared distance every comparison in this module uses (fixed evaluation order, so a
/// lower bound built from smaller per-axis offsets is never rounded above it).
#[inline(always)]
fn dist2(a: [f32; 3], b: [f32; 3]) -> f32 {
    let (x, y, z) = (a[0] - b[0], a[1] - b[1], a[2] - b[2]);
    x * x + y * y + z * z
}

/// Levels of inner nodes so that no leaf holds more than [`LEAF`] points.
fn inner_levels(n: usize) -> u32 {
    let mut levels = 0;
    while n.div_ceil(1 << levels) > LEAF {
        levels += 1;
    }
    levels
}

/// Splits `entries` at its median along the widest axis of its bounding box; ties in the
/// coordinate are ordered by input index so the partition is unique.
fn split_node(entries: &mut [Entry]) -> Split {
    let first = entries[0].p;
    let (lo, hi) = entries.iter().fold((first, first), |(mut lo, mut hi), e| {
        for a in 0..3 {
            lo[a] = lo[a].min(e.p[a]);
            hi[a] = hi[a].max(e.p[a]);
        }
        (lo, hi)
    });
    let mut axis = 0;
    for a in 1..3 {
        if hi[a] - lo[a] > hi[axis] - lo[axis] {
            axis = a;
        }
    }
    let mid = entries.len() / 2;
    entries.select_nth_unstable_by(mid, |a, b| a.p[axis].total_cmp(&b.p[axis]).then(a.id.cmp(&b.id)));
    Split { value: entries[mid].p[axis], axis: axis as u32 }
}

/// A node of the tree during a search: its points `begin..end`, and per axis a lower bound of
/// the distance from the query to its cell.
#[derive(Clone, Copy)]
struct Cell {
    node: usize,
    begin: usize,
    end: usize,
    offset: [f32; 3],
}

impl Cell {
    fn root(len: usize) -> Cell {
        Cell { node: 0, begin: 0, end: len, offset: [0.0; 3] }
    }

    /// The squared lower bound of the distance from the query to the cell.
    #[inline(always)]
    fn bound(&self) -> f32 {
        let [x, y, z] = self.offset;
        x * x + y * y + z * z
    }
}

/// Above this many neighbours the candidates are kept in a binary heap rather than a sorted
/// list: an insertion into the sorted list shifts up to k entries, which dominated queries of a
/// few hundred neighbours (the noisy clouds' local fits), while at k of a few tens the sorted
/// list is as fast. Both give the same set, sorted the same way once the search is done.
const HEAP_ABOVE: usize = 32;

/// A candidate's place in the (squared distance, input index) order as one integer: squared
/// distances are never negative (nor NaN), and the bits of non-negative floats order as they do.
#[inline(always)]
fn order_key(d2: f32, id: u32) -> u64 {
    (u64::from(d2.to_bits()) << 32) | u64::from(id)
}

/// The squared distance and input index of an [`order_key`].
#[inline(always)]
fn from_key(key: u64) -> (f32, u32) {
    (f32::from_bits((key >> 32) as u32), key as u32)
}

/// The k best candidates so far: sorted by (distance, index), or for k above [`HEAP_ABOVE`] a
/// max-heap on (distance, index) until [`Best::finish`] sorts it.
struct Best {
    k: usize,
    /// ([`order_key`], position in the tree).
    items: Vec<(u64, u32)>,
    /// The squared distance a candidate must not exceed to be considered: the k-th best's,
    /// infinite until there are k.
    bound: f32,
    heap: bool,
}

impl Best {
    fn new(k: usize) -> Best {
        Best { k, items: Vec::with_capacity(k + 1), bound: f32::INFINITY, heap: k > HEAP_ABOVE }
    }

    fn clear(&mut self) {
        self.items.clear();
        self.bound = f32::INFINITY;
    }

    #[inline(always)]
    fn bound(&self) -> f32 {
        self.bound
    }

    /// Sorts the candidates by (distance, index) (a no-op for the sorted list).
    fn finish(&mut self) {
        if self.heap {
            self.items.sort_unstable_by_key(|item| item.0);
        }
    }

    #[inline(always)]
    fn offer(&mut self, d2: f32, id: u32, position: u32) {
        let key = order_key(d2, id);
        if self.heap {
            self.offer_heap((key, position));
            return;
        }
        if self.items.len() == self.k {
            if key > self.items[self.k - 1].0 {
                return;
            }
            self.items.pop();
        }
        let mut at = self.items.len();
        while at > 0 && self.items[at - 1].0 > key {
            at -= 1;
        }
        self.items.insert(at, (key, position));
        if self.items.len() == self.k {
            self.bound = from_key(self.items[self.k - 1].0).0;
        }
    }

    /// [`Best::offer`] on the max-heap: the worst candidate at the root.
    #[inline]
    fn offer_heap(&mut self, item: (u64, u32)) {
        let items = &mut self.items;
        if items.len() < self.k {
            // Sift up.
            let mut at = items.len();
            items.push(item);
            while at > 0 {
                let parent = (at - 1) / 2;
                if item.0 < items[parent].0 {
                    break;
                }
                items[at] = items[parent];
                at = parent;
            }
            items[at] = item;
            if items.len() == self.k {
                self.bound = from_key(items[0].0).0;
            }
            return;
        }
        if item.0 > items[0].0 {
            return;
        }
        // Replace the root and sift down.
        let n = items.len();
        let mut at = 0;
        loop {
            let left = 2 * at + 1;
            if left >= n {
                break;
            }
            let right = left + 1;
            let child = if right < n && items[right].0 > items[left].0 { right } else { left };
            if items[child].0 < item.0 {
                break;
            }
            items[at] = items[child];
            at = child;
        }
        items[at] = item;
        self.bound = from_key(items[0].0).0;
    }
}

/// Bounded searches look a little beyond their radius, so that rounding in the squared
/// distances cannot change an answer against the unsquared one.
const PRUNE_MARGIN: f32 = 1.0 + 1e-4;

/// The nearest point found so far by a single-nearest search, among those it keeps.
struct Nearest {
    /// Squared distance of `id`, or the exclusive bound while nothing is found.
    d2: f32,
    id: Option<u32>,
    /// A point this close (squared) ends the search.
    enough: f32,
}

impl Nearest {
    /// Whether a point at `d2` with index `id` beats the best so far (ties: smaller index).
    #[inline(always)]
    fn beaten_by(&self, d2: f32, id: u32) -> bool {
        d2 < self.d2 || (d2 == self.d2 && self.id.is_some_and(|best| id < best))
    }
}

impl KdTree {
    /// Builds the tree over `points` (in parallel on the current rayon pool).
    ///
    /// Errors: a point with a NaN, infinite or out-of-range coordinate (named, see
    /// [`check_positions`]), or more than `u32::MAX - 1` points.
    pub fn new(points: &[Vec3]) -> Result<KdTree> {
        if points.len() >= u32::MAX as usize {
            return Err(Error::TooLarge(format!("{} points (at most {})", points.len(), u32::MAX - 1)));
        }
        check_positions(points, "point")?;
        let mut entries: Vec<Entry> =
            points.par_iter().enumerate().map(|(i, p)| Entry { p: p.to_array(), id: i as u32 }).collect();
        let levels = inner_levels(entries.len());
        let mut splits = Vec::with_capacity((1usize << levels) - 1);
        // The nodes of one level own disjoint ranges: split them all in parallel, then cut
        // every range at its middle for the next level.
        let mut ranges: Vec<&mut [Entry]> = vec![&mut entries[..]];
        for _ in 0..levels {
            let level: Vec<Split> = ranges.par_iter_mut().map(|r| split_node(r)).collect();
            splits.extend(level);
            ranges = ranges
                .into_iter()
                .flat_map(|r| {
                    let mid = r.len() / 2;
                    let (left, right) = r.split_at_mut(mid);
                    [left, right]
                })
                .collect();
        }
        Ok(KdTree { entries, splits })
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// True when the tree holds no points.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// The nearest point to `p` as (distance, index in the input slice), ties broken by the
    /// smaller index; `None` when the tree is empty or `p` is not finite.
    pub fn nearest(&self, p: Vec3) -> Option<(f32, u32)> {
        self.nearest_among(p, |_| true)
    }

    /// The nearest point to `p` among those whose input index passes `keep`, as
    /// [`KdTree::nearest`] gives it.
    pub fn nearest_among(&self, p: Vec3, keep: impl Fn(u32) -> bool) -> Option<(f32, u32)> {
        self.search_nearest(p, f32::INFINITY, f32::NEG_INFINITY, &keep).map(|(d2, id)| (d2.sqrt(), id))
    }

    /// Whether the nearest point is within `radius` of `p` (`distance(p) <= radius`, to the
    /// bit); the search stops at the first point found well inside and skips everything
    /// farther than `radius`, so it costs less than [`KdTree::distance`].
    pub fn any_within(&self, p: Vec3, radius: f32) -> bool {
        self.any_within_among(p, radius, |_| true)
    }

    /// Whether a point whose input index passes `keep` lies within `radius` of `p`; like
    /// [`KdTree::any_within`], it skips everything farther than `radius`.
    pub fn any_within_among(&self, p: Vec3, radius: f32, keep: impl Fn(u32) -> bool) -> bool {
        let (below, enough) = ((radius * PRUNE_MARGIN).powi(2), (radius / PRUNE_MARGIN).powi(2));
        self.search_nearest(p, below, enough, &keep).is_some_and(|(d2, _)| d2.sqrt() <= radius)
    }

    /// `distance(p)` when that is at most `cap`, else `f32::INFINITY`: the search skips
    /// everything farther than `cap`. NaN when `p` has a NaN coordinate.
    pub fn distance_within(&self, p: Vec3, cap: f32) -> f32 {
        if p.is_nan() {
            return f32::NAN;
        }
        match self.search_nearest(p, (cap * PRUNE_MARGIN).powi(2), f32::NEG_INFINITY, &|_| true) {
            Some((d2, _)) if d2.sqrt() <= cap => d2.sqrt(),
            _ => f32::INFINITY,
        }
    }

    /// Distance from `p` to the nearest point: `f32::INFINITY` for an empty tree, NaN when `p`
    /// has a NaN coordinate.
    pub fn distance(&self, p: Vec3) -> f32 {
        match self.nearest(p) {
            Some((d, _)) => d,
            None if p.is_nan() => f32::NAN,
            None => f32::INFINITY,
        }
    }

    /// The `k` points nearest to `p` (fewer when the tree has fewer), nearest first, ties
    /// broken by the smaller index. Empty when `p` is not finite.
    pub fn knn(&self, p: Vec3, k: usize) -> Vec<Neighbour> {
        let k = k.min(MAX_K);
        if k == 0 || !p.is_finite() {
            return Vec::new();
        }
        let mut best = Best::new(k);
        self.search(p.to_array(), u32::MAX, &mut best);
        best.finish();
        best.items
            .iter()
            .map(|&(key, _)| {
                let (d2, id) = from_key(key);
                Neighbour { index: id, distance_squared: d2 }
            })
            .collect()
    }

    /// For every input point, the input indices of its `k` nearest *other* points (the point
    /// itself is left out; a duplicate of it is a neighbour at distance 0), nearest first, ties
    /// broken by index: `n * k` indices, row `i` for point `i`. Parallel on the current rayon
    /// pool, and the same for any thread count.
    ///
    /// Errors: `k` of 0, above [`MAX_K`] or not below the number of points.
    pub fn knn_all(&self, k: usize) -> Result<Vec<u32>> {
        self.check_k(k)?;
        let n = self.len();
        let mut by_position = vec![0u32; n * k];
        self.knn_positions(k, 0, &mut by_position);
        // Rows are in tree order with tree positions inside: map both back to input indices.
        let mut position_of = vec![0u32; n];
        for (position, e) in self.entries.iter().enumerate() {
            position_of[e.id as usize] = position as u32;
        }
        let mut out = vec![0u32; n * k];
        out.par_chunks_mut(k).zip(position_of.par_iter()).for_each(|(row, &position)| {
            let from = &by_position[position as usize * k..][..k];
            for (o, &q) in row.iter_mut().zip(from) {
                *o = self.entries[q as usize].id;
            }
        });
        Ok(out)
    }

    /// Checks `k` for [`KdTree::knn_all`]-style queries (each point's `k` other points).
    pub(crate) fn check_k(&self, k: usize) -> Result<()> {
        if k == 0 || k > MAX_K {
            return Err(Error::param("k", format!("{k}: must be from 1 to {MAX_K}")));
        }
        if k >= self.len() {
            return Err(Error::input(format!("{} points: each needs {k} other points as neighbours", self.len())));
        }
        Ok(())
    }

    /// Batch query in tree order: for the points at tree positions `first..first + out.len() / k`,
    /// `out` receives, row by row, the tree positions of each one's `k` nearest other points
    /// (order as in [`KdTree::knn_all`]).
    /// Working in tree order keeps neighbouring points close in memory. `k` must pass
    /// [`KdTree::check_k`].
    pub(crate) fn knn_positions(&self, k: usize, first: usize, out: &mut [u32]) {
        out.par_chunks_mut(k * BATCH).enumerate().for_each(|(chunk, rows)| {
            let mut best = Best::new(k);
            for (r, row) in rows.chunks_exact_mut(k).enumerate() {
                let position = first + chunk * BATCH + r;
                best.clear();
                self.search(self.entries[position].p, position as u32, &mut best);
                best.finish();
                for (o, item) in row.iter_mut().zip(&best.items) {
                    *o = item.1;
                }
            }
        });
    }

    /// Checks what the queries rely on: the entries are a permutation of the input indices, there
    /// are as many splits as [`inner_levels`] asks for, and every inner node's left half lies on
    /// or below its split value and its right half on or above. The first broken rule, named,
    /// as the error.
    pub fn validate(&self) -> Result<(), String> {
        let n = self.entries.len();
        let mut seen = vec![false; n];
        for e in &self.entries {
            if e.id as usize >= n || std::mem::replace(&mut seen[e.id as usize], true) {
                return Err(format!("the entries are not a permutation of 0..{n} (index {})", e.id));
            }
        }
        let inner = (1usize << inner_levels(n)) - 1;
        if self.splits.len() != inner {
            return Err(format!("{} splits for {n} points (want {inner})", self.splits.len()));
        }
        let mut pending = vec![(0usize, 0usize, n)];
        while let Some((node, begin, end)) = pending.pop() {
            if node >= self.splits.len() {
                continue;
            }
            let Split { value, axis } = self.splits[node];
            if axis > 2 {
                return Err(format!("node {node} splits along axis {axis}"));
            }
            let mid = begin + (end - begin) / 2;
            let side = |range: std::ops::Range<usize>, on_side: &dyn Fn(f32) -> bool| {
                self.entries[range].iter().all(|e| on_side(e.p[axis as usize]))
            };
            if !side(begin..mid, &|x| x <= value) || !side(mid..end, &|x| x >= value) {
                return Err(format!("node {node}: a point is on the wrong side of {value} along axis {axis}"));
            }
            pending.extend([(2 * node + 1, begin, mid), (2 * node + 2, mid, end)]);
        }
        Ok(())
    }

    /// The tree's nodes at the shallowest depth whose nodes hold at most `most` points each, as
    /// ranges of tree positions (see [`KdTree::index`]): compact groups of nearby points, half
    /// to all of `most` points each (fewer where the tree is smaller).
    pub(crate) fn groups(&self, most: usize) -> Vec<std::ops::Range<usize>> {
        let all: std::ops::Range<usize> = 0..self.entries.len();
        let mut ranges = vec![all];
        while ranges.iter().any(|r| r.len() > most.max(1)) {
            ranges = ranges
                .into_iter()
                .flat_map(|r| {
                    let mid = r.start + r.len() / 2;
                    [r.start..mid, mid..r.end]
                })
                .collect();
        }
        ranges
    }

    /// The point at tree position `position`.
    pub(crate) fn point(&self, position: usize) -> Vec3 {
        Vec3::from_array(self.entries[position].p)
    }

    /// The input index of the point at tree position `position`.
    pub(crate) fn index(&self, position: usize) -> u32 {
        self.entries[position].id
    }

    /// The nearest kept point closer than `below` (squared), as (squared distance, input
    /// index), stopping at the first kept point within `enough` (squared).
    fn search_nearest(&self, p: Vec3, below: f32, enough: f32, keep: &impl Fn(u32) -> bool) -> Option<(f32, u32)> {
        if !p.is_finite() {
            return None;
        }
        let mut best = Nearest { d2: below, id: None, enough };
        self.visit_nearest(Cell::root(self.entries.len()), p.to_array(), keep, &mut best);
        best.id.map(|id| (best.d2, id))
    }

    /// [`KdTree::visit`] for a single nearest point; true once a point within `best.enough`
    /// is found, which ends the search.
    fn visit_nearest(&self, cell: Cell, q: [f32; 3], keep: &impl Fn(u32) -> bool, best: &mut Nearest) -> bool {
        if cell.node >= self.splits.len() {
            for e in &self.entries[cell.begin..cell.end] {
                let d2 = dist2(q, e.p);
                if best.beaten_by(d2, e.id) && keep(e.id) {
                    (best.d2, best.id) = (d2, Some(e.id));
                    if d2 <= best.enough {
                        return true;
                    }
                }
            }
            return false;
        }
        let (near, far) = self.children(cell, q);
        self.visit_nearest(near, q, keep, best) || (far.bound() <= best.d2 && self.visit_nearest(far, q, keep, best))
    }

    /// Fills `best` with the nearest points to `q`, leaving out tree position `skip`.
    fn search(&self, q: [f32; 3], skip: u32, best: &mut Best) {
        self.visit(Cell::root(self.entries.len()), q, skip, best);
    }

    /// Searches `cell`'s points.
    fn visit(&self, cell: Cell, q: [f32; 3], skip: u32, best: &mut Best) {
        if cell.node >= self.splits.len() {
            for (position, e) in self.entries[cell.begin..cell.end].iter().enumerate() {
                let position = (cell.begin + position) as u32;
                if position != skip {
                    let d2 = dist2(q, e.p);
                    if d2 <= best.bound() {
                        best.offer(d2, e.id, position);
                    }
                }
            }
            return;
        }
        let (near, far) = self.children(cell, q);
        self.visit(near, q, skip, best);
        if far.bound() <= best.bound() {
            self.visit(far, q, skip, best);
        }
    }

    /// The two children of inner node `cell`, the one on `q`'s side of the split first. Every
    /// point across the plane is at least |q - split| away along its axis. Rounding is
    /// monotonic, so the far child's bound never exceeds a true candidate's computed distance,
    /// and ties (equal distance, smaller index) are still visited: the pruning is exact.
    #[inline(always)]
    fn children(&self, cell: Cell, q: [f32; 3]) -> (Cell, Cell) {
        let Split { value, axis } = self.splits[cell.node];
        let axis = axis as usize;
        let mid = cell.begin + (cell.end - cell.begin) / 2;
        let diff = q[axis] - value;
        let left = Cell { node: 2 * cell.node + 1, end: mid, ..cell };
        let right = Cell { node: 2 * cell.node + 2, begin: mid, ..cell };
        let (near, mut far) = if diff <= 0.0 { (left, right) } else { (right, left) };
        far.offset[axis] = far.offset[axis].max(diff.abs());
        (near, far)
    }
}

/// For every point, the indices of its `k` nearest other points, nearest first, ties broken by
/// index: `points.len() * k` indices (see [`KdTree::knn_all`]). Parallel on the current rayon
/// pool (wrap in [`crate::Threads::run`] to choose), deterministic for any thread count.
pub fn knn_all(points: &[Vec3], k: usize) -> Result<Vec<u32>> {
    KdTree::new(points)?.knn_all(k)
}

#[cfg(test)]
mod tests;
