//! Point-to-mesh, point-to-point-cloud and mesh-to-mesh distances.
//!
//! Two bounding volume hierarchies do the searching: [`TriangleBvh`] (closest point on a set of
//! triangles, with the exact point-triangle distance) and [`PointBvh`] (nearest point of a
//! cloud). Both are built top-down, splitting each node's items at the median of their centroids
//! along the longest axis of the centroids' box, and stored in flat arrays linked by `u32`
//! indices with the items of each leaf contiguous. A query descends nearer child first and
//! prunes any box farther than the best distance found so far, so its result is exact.
//!
//! Conventions: distances are Euclidean, in the input's units, computed in `f32`. Anything
//! measured against an empty target (no usable triangles, no points) is `f32::INFINITY`; a query
//! point with a NaN coordinate gives NaN. Batch functions run in parallel and their output does
//! not depend on the thread count (each result depends on its own query only).

use crate::mesh::Mesh;
use crate::rng::stream_seed;
use crate::shapes::sample_surface;
use glam::Vec3;
use rayon::prelude::*;

/// The point of triangle (a, b, c) closest to `p`.
///
/// Ericson's region method (Real-Time Collision Detection, 5.1.5): the signs of a few dot
/// products tell which Voronoi region of the triangle (a vertex, an edge, or the face) contains
/// `p`, and only that feature's projection is computed. Degenerate triangles (zero area, or so
/// thin that the face formula is unstable) are handled as their three edges.
pub fn closest_point_on_triangle(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> Vec3 {
    let ab = b - a;
    let ac = c - a;
    let normal = ab.cross(ac);
    if normal.length_squared() <= f32::EPSILON * f32::EPSILON * ab.length_squared() * ac.length_squared() {
        return closest_point_on_edges(p, a, b, c);
    }
    let ap = p - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return a; // vertex region a
    }
    let bp = p - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= 0.0 && d4 <= d3 {
        return b; // vertex region b
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3)); // edge region ab
    }
    let cp = p - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return c; // vertex region c
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6)); // edge region ac
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return b + (c - b) * w; // edge region bc
    }
    // Face region: barycentric coordinates from the three sub-areas.
    let inverse = 1.0 / (va + vb + vc);
    let q = a + ab * (vb * inverse) + ac * (vc * inverse);
    if q.is_finite() {
        q
    } else {
        closest_point_on_edges(p, a, b, c)
    }
}

/// The point of segment [a, b] closest to `p` (a when the segment is a point).
fn closest_point_on_segment(p: Vec3, a: Vec3, b: Vec3) -> Vec3 {
    let ab = b - a;
    let length_squared = ab.length_squared();
    if length_squared <= 0.0 || length_squared.is_nan() {
        return a;
    }
    a + ab * ((p - a).dot(ab) / length_squared).clamp(0.0, 1.0)
}

/// The closest point on the three edges of a (degenerate) triangle.
fn closest_point_on_edges(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> Vec3 {
    [closest_point_on_segment(p, a, b), closest_point_on_segment(p, b, c), closest_point_on_segment(p, c, a)]
        .into_iter()
        .min_by(|x, y| x.distance_squared(p).total_cmp(&y.distance_squared(p)))
        .unwrap_or(a)
}

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

/// Deeper than any of our trees gets: a median split halves its items (32 levels for 2^32), a
/// Morton split takes at least one of the code's 63 bits, then halves equal codes. The
/// traversal stack needs at most one entry per level plus one.
const MAX_STACK: usize = 128;

/// The shape of a bounding volume hierarchy over items given by their boxes; `order[i]` is the
/// item stored at position `i`, so each leaf covers `order[first..first + count]`.
#[derive(Clone, Debug, Default)]
struct Bvh {
    nodes: Vec<Node>,
    order: Vec<u32>,
}

/// Subtrees over more items than this build their two halves in parallel. The tree does not
/// depend on it (nor on the thread count): only who builds which part.
const PARALLEL_BUILD: usize = 1 << 15;

/// A point being sorted into the hierarchy, and its index. The build moves these small records
/// rather than indices into another array, so its comparisons and bounds read memory in order.
#[derive(Clone, Copy)]
struct Item {
    centroid: Vec3,
    index: u32,
}

/// What a build step of the median-split hierarchy (over points) needs to know.
struct BuildInput {
    leaf_size: usize,
}

impl BuildInput {
    /// The box of `items`, and its longest axis.
    fn bounds(&self, items: &[Item]) -> (Vec3, Vec3, usize) {
        let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
        for item in items {
            lo = lo.min(item.centroid);
            hi = hi.max(item.centroid);
        }
        let extent = hi - lo;
        let axis = if extent.x >= extent.y && extent.x >= extent.z {
            0
        } else if extent.y >= extent.z {
            1
        } else {
            2
        };
        (lo, hi, axis)
    }

    /// Puts the lower half of `items` (by centroid along `axis`) first; returns the split.
    fn split(&self, items: &mut [Item], axis: usize) -> usize {
        let middle = items.len() / 2;
        items.select_nth_unstable_by(middle, |a, b| a.centroid[axis].total_cmp(&b.centroid[axis]));
        middle
    }

    /// The nodes of the subtree over `items`, which sit at position `offset` of the full order.
    /// The root comes first and the two children of a node are adjacent. Leaves' `first` is a
    /// position in the full order; internal nodes' `first` indexes the returned vector.
    fn subtree(&self, items: &mut [Item], offset: usize) -> Vec<Node> {
        if items.len() <= PARALLEL_BUILD {
            return self.sequential_subtree(items, offset);
        }
        let (min, max, axis) = self.bounds(items);
        let middle = self.split(items, axis);
        let (low, high) = items.split_at_mut(middle);
        let (left, right) = rayon::join(|| self.subtree(low, offset), || self.subtree(high, offset + middle));
        join_subtrees(Node { min, max, first: 1, count: 0 }, left, right)
    }

    /// [`BuildInput::subtree`] on one thread, with an explicit stack.
    fn sequential_subtree(&self, items: &mut [Item], offset: usize) -> Vec<Node> {
        let blank = Node { min: Vec3::ZERO, max: Vec3::ZERO, first: 0, count: 0 };
        // A median split halves the count, so there are fewer than 4 n / leaf_size nodes.
        let mut nodes = Vec::with_capacity(4 * items.len() / self.leaf_size + 1);
        nodes.push(blank);
        let mut pending = vec![(0usize, 0usize, items.len())];
        while let Some((node, start, end)) = pending.pop() {
            let range = &mut items[start..end];
            let (min, max, axis) = self.bounds(range);
            nodes[node].min = min;
            nodes[node].max = max;
            if range.len() <= self.leaf_size {
                nodes[node].first = (offset + start) as u32;
                nodes[node].count = range.len() as u32;
                continue;
            }
            let middle = self.split(range, axis);
            let left = nodes.len();
            nodes.extend([blank, blank]);
            nodes[node].first = left as u32;
            pending.push((left + 1, start + middle, end));
            pending.push((left, start, start + middle));
        }
        nodes
    }
}

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

/// A hierarchy over Morton-sorted items (see [`Bvh::build_morton`]), laid out like
/// [`BuildInput::subtree`]'s, with every node's box the union of its children's.
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
    /// its codes' common prefix ends (a linear BVH, Lauterbach et al. 2009). Fast to build, a
    /// little slower to search than [`Bvh::build_over_points`]'s median splits: for
    /// hierarchies searched a few times per item.
    fn build_morton(boxes: &[(Vec3, Vec3)], leaf_size: usize) -> Bvh {
        if boxes.is_empty() {
            return Bvh::default();
        }
        let items = morton_order(boxes);
        let nodes = morton_subtree(&items, boxes, 0, leaf_size.max(1));
        Bvh { nodes, order: items.iter().map(|&(_, i)| i).collect() }
    }

    /// Builds the hierarchy over points (each its own box), at most `leaf_size` per leaf:
    /// top-down, each node split at the median along the longest axis of its box. Slower to
    /// build than [`Bvh::build_morton`], faster to search: for the many queries of a cloud.
    fn build_over_points(points: &[Vec3], leaf_size: usize) -> Bvh {
        if points.is_empty() {
            return Bvh::default();
        }
        let mut items: Vec<Item> =
            points.par_iter().enumerate().map(|(i, &p)| Item { centroid: p, index: i as u32 }).collect();
        let nodes = BuildInput { leaf_size: leaf_size.max(1) }.subtree(&mut items, 0);
        Bvh { nodes, order: items.iter().map(|item| item.index).collect() }
    }

    /// The item minimising `item_distance_squared(position, p)` over positions (indices into
    /// `order`), with its squared distance; `None` when empty or nothing compares below
    /// infinity. Ties keep the first found.
    fn nearest(&self, p: Vec3, item_distance_squared: impl Fn(usize) -> f32) -> Option<(usize, f32)> {
        self.search(p, item_distance_squared, f32::INFINITY, f32::NEG_INFINITY)
    }

    /// [`Bvh::nearest`] among the items closer than `below_d2` (squared), stopping at the first
    /// item found within `enough_d2`: `None` when no item is closer than `below_d2`.
    fn search(
        &self,
        p: Vec3,
        item_distance_squared: impl Fn(usize) -> f32,
        below_d2: f32,
        enough_d2: f32,
    ) -> Option<(usize, f32)> {
        let root = self.nodes.first()?;
        let mut best: Option<(usize, f32)> = None;
        let mut best_d2 = below_d2;
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
                        if d2 <= enough_d2 {
                            return best;
                        }
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
}

/// The closest point of a triangle set to a query, as found by [`TriangleBvh::closest_point`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Closest {
    /// Euclidean distance from the query to `point`.
    pub distance: f32,
    /// Index of the triangle in the mesh's `triangles`.
    pub triangle: u32,
    /// The closest point on that triangle.
    pub point: Vec3,
}

/// A bounding volume hierarchy over a mesh's triangles for closest-point queries.
///
/// Triangles with an out-of-range vertex index are left out; zero-area triangles are kept and
/// measured as segments or points.
#[derive(Clone, Debug, Default)]
pub struct TriangleBvh {
    bvh: Bvh,
    /// Corner positions per stored position (leaf order).
    corners: Vec<[Vec3; 3]>,
    /// Original triangle index per stored position.
    ids: Vec<u32>,
}

/// Triangles per leaf: small leaves prune well, and a leaf's corners share cache lines.
const TRIANGLE_LEAF: usize = 4;
/// Points per leaf.
const POINT_LEAF: usize = 8;

impl TriangleBvh {
    /// Builds the hierarchy over the triangles of `mesh` (none for a point cloud).
    pub fn new(mesh: &Mesh) -> TriangleBvh {
        let p = &mesh.positions;
        let (corners, ids): (Vec<[Vec3; 3]>, Vec<u32>) = mesh
            .triangles
            .par_iter()
            .enumerate()
            .filter(|(_, tri)| tri.iter().all(|&v| (v as usize) < p.len()))
            .map(|(i, tri)| (tri.map(|v| p[v as usize]), i as u32))
            .unzip();
        let boxes: Vec<(Vec3, Vec3)> =
            corners.par_iter().map(|[a, b, c]| (a.min(*b).min(*c), a.max(*b).max(*c))).collect();
        let bvh = Bvh::build_morton(&boxes, TRIANGLE_LEAF);
        let corners_sorted = bvh.order.par_iter().map(|&i| corners[i as usize]).collect();
        let ids_sorted = bvh.order.par_iter().map(|&i| ids[i as usize]).collect();
        TriangleBvh { bvh, corners: corners_sorted, ids: ids_sorted }
    }

    /// Number of triangles in the hierarchy.
    pub fn len(&self) -> usize {
        self.ids.len()
    }

    /// True when there are no triangles to measure against.
    pub fn is_empty(&self) -> bool {
        self.ids.is_empty()
    }

    /// The closest point to `p` on any triangle, or `None` when there are no triangles or `p`
    /// has a NaN coordinate.
    pub fn closest_point(&self, p: Vec3) -> Option<Closest> {
        let point_of = |position: usize| {
            let [a, b, c] = self.corners[position];
            closest_point_on_triangle(p, a, b, c)
        };
        let (position, d2) = self.bvh.nearest(p, |position| point_of(position).distance_squared(p))?;
        Some(Closest { distance: d2.sqrt(), triangle: self.ids[position], point: point_of(position) })
    }

    /// Distance from `p` to the triangles: `f32::INFINITY` when there are none, NaN when `p` has
    /// a NaN coordinate.
    pub fn distance(&self, p: Vec3) -> f32 {
        match self.closest_point(p) {
            Some(c) => c.distance,
            None if p.is_nan() => f32::NAN,
            None => f32::INFINITY,
        }
    }
}

/// Bounded searches look a little beyond their radius, so that rounding in the squared
/// distances cannot change an answer against the unsquared one.
const PRUNE_MARGIN: f32 = 1.0 + 1e-4;

/// A bounding volume hierarchy over a point cloud for nearest-neighbour queries.
#[derive(Clone, Debug, Default)]
pub struct PointBvh {
    bvh: Bvh,
    /// Points per stored position (leaf order).
    points: Vec<Vec3>,
}

impl PointBvh {
    /// Builds the hierarchy over `points`.
    pub fn new(points: &[Vec3]) -> PointBvh {
        let bvh = Bvh::build_over_points(points, POINT_LEAF);
        let sorted = bvh.order.iter().map(|&i| points[i as usize]).collect();
        PointBvh { bvh, points: sorted }
    }

    /// Number of points in the hierarchy.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// True when there are no points.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// The nearest point to `p` as (distance, index in the input slice), or `None` when the
    /// cloud is empty or `p` has a NaN coordinate.
    pub fn nearest(&self, p: Vec3) -> Option<(f32, u32)> {
        let (position, d2) = self.bvh.nearest(p, |position| self.points[position].distance_squared(p))?;
        Some((d2.sqrt(), self.bvh.order[position]))
    }

    /// The nearest point to `p` among those whose input index passes `keep`, as
    /// [`PointBvh::nearest`] gives it.
    pub fn nearest_among(&self, p: Vec3, keep: impl Fn(u32) -> bool) -> Option<(f32, u32)> {
        let (position, d2) = self.bvh.nearest(p, |position| {
            if keep(self.bvh.order[position]) {
                self.points[position].distance_squared(p)
            } else {
                f32::INFINITY
            }
        })?;
        Some((d2.sqrt(), self.bvh.order[position]))
    }

    /// Whether the nearest point is within `radius` of `p` (`distance(p) <= radius`, to the
    /// bit); the search stops at the first point found well inside, and skips everything
    /// farther than `radius`, so it costs less than [`PointBvh::distance`].
    pub fn any_within(&self, p: Vec3, radius: f32) -> bool {
        let (below, enough) = ((radius * PRUNE_MARGIN).powi(2), (radius / PRUNE_MARGIN).powi(2));
        let found = self.bvh.search(p, |position| self.points[position].distance_squared(p), below, enough);
        found.is_some_and(|(_, d2)| d2.sqrt() <= radius)
    }

    /// Whether a point whose input index passes `keep` lies within `radius` of `p`; like
    /// [`PointBvh::any_within`], it skips everything farther than `radius`.
    pub fn any_within_among(&self, p: Vec3, radius: f32, keep: impl Fn(u32) -> bool) -> bool {
        let (below, enough) = ((radius * PRUNE_MARGIN).powi(2), (radius / PRUNE_MARGIN).powi(2));
        let distance2 = |position: usize| {
            if keep(self.bvh.order[position]) {
                self.points[position].distance_squared(p)
            } else {
                f32::INFINITY
            }
        };
        let found = self.bvh.search(p, distance2, below, enough);
        found.is_some_and(|(_, d2)| d2.sqrt() <= radius)
    }

    /// `distance(p)` when that is at most `cap`, else `f32::INFINITY`: the search skips
    /// everything farther than `cap`. NaN when `p` has a NaN coordinate.
    pub fn distance_within(&self, p: Vec3, cap: f32) -> f32 {
        if p.is_nan() {
            return f32::NAN;
        }
        let below = (cap * PRUNE_MARGIN).powi(2);
        match self.bvh.search(p, |position| self.points[position].distance_squared(p), below, f32::NEG_INFINITY) {
            Some((_, d2)) if d2.sqrt() <= cap => d2.sqrt(),
            _ => f32::INFINITY,
        }
    }

    /// Distance from `p` to the nearest point: `f32::INFINITY` for an empty cloud, NaN when `p`
    /// has a NaN coordinate.
    pub fn distance(&self, p: Vec3) -> f32 {
        match self.nearest(p) {
            Some((d, _)) => d,
            None if p.is_nan() => f32::NAN,
            None => f32::INFINITY,
        }
    }
}

/// Distance from each of `points` to the surface of `mesh` (its triangles), in parallel.
/// `f32::INFINITY` everywhere when the mesh has no usable triangles.
pub fn point_to_mesh_distances(points: &[Vec3], mesh: &Mesh) -> Vec<f32> {
    let bvh = TriangleBvh::new(mesh);
    points.par_iter().map(|&p| bvh.distance(p)).collect()
}

/// Distance from each of `points` to the nearest point of `cloud`, in parallel.
/// `f32::INFINITY` everywhere when `cloud` is empty.
pub fn point_to_points_distances(points: &[Vec3], cloud: &[Vec3]) -> Vec<f32> {
    let bvh = PointBvh::new(cloud);
    points.par_iter().map(|&p| bvh.distance(p)).collect()
}

/// Summary of a set of distances.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DistanceStats {
    /// How many distances were summarised; all other fields are 0 when this is 0.
    pub count: usize,
    /// Arithmetic mean.
    pub mean: f32,
    /// Root mean square.
    pub rms: f32,
    /// Largest value.
    pub max: f32,
    /// 99th percentile by the nearest-rank method: the smallest value that at least 99% of the
    /// values do not exceed.
    pub p99: f32,
}

impl DistanceStats {
    /// Summarises `distances` (sums in double precision, in order, so the result is
    /// deterministic). Empty input gives all zeros with `count == 0`.
    pub fn from_distances(distances: &[f32]) -> DistanceStats {
        let count = distances.len();
        if count == 0 {
            return DistanceStats::default();
        }
        let (mut sum, mut sum_squares, mut max) = (0.0f64, 0.0f64, f32::NEG_INFINITY);
        for &d in distances {
            let d64 = f64::from(d);
            sum += d64;
            sum_squares += d64 * d64;
            max = max.max(d);
        }
        let rank = (count * 99).div_ceil(100).max(1) - 1;
        let mut scratch = distances.to_vec();
        let (_, p99, _) = scratch.select_nth_unstable_by(rank, f32::total_cmp);
        DistanceStats {
            count,
            mean: (sum / count as f64) as f32,
            rms: (sum_squares / count as f64).sqrt() as f32,
            max,
            p99: *p99,
        }
    }
}

/// What distances are measured to: a mesh's triangles, or a set of points.
#[derive(Clone, Copy, Debug)]
pub enum Target<'a> {
    /// The surface of the mesh's triangles.
    Triangles(&'a Mesh),
    /// The nearest of these points.
    Points(&'a [Vec3]),
}

impl<'a> Target<'a> {
    /// The triangles of `mesh` when it has any, else its points.
    pub fn of(mesh: &'a Mesh) -> Target<'a> {
        if mesh.triangles.is_empty() {
            Target::Points(&mesh.positions)
        } else {
            Target::Triangles(mesh)
        }
    }

    /// Distance from each of `points` to this target, in parallel.
    pub fn distances(&self, points: &[Vec3]) -> Vec<f32> {
        match *self {
            Target::Triangles(mesh) => point_to_mesh_distances(points, mesh),
            Target::Points(cloud) => point_to_points_distances(points, cloud),
        }
    }
}

/// Statistics of the distances from each of `from` to `to` (one-sided).
pub fn one_sided(from: &[Vec3], to: Target) -> DistanceStats {
    DistanceStats::from_distances(&to.distances(from))
}

/// The points that stand for `mesh` in a two-sided comparison: `samples` points sampled
/// uniformly by area on its triangles, or all its points when it is a point cloud.
fn representative_points(mesh: &Mesh, samples: usize, seed: u64) -> Vec<Vec3> {
    if mesh.triangles.is_empty() {
        mesh.positions.clone()
    } else {
        sample_surface(mesh, samples, seed).positions
    }
}

/// One-sided statistics in both directions: (a to b, b to a).
///
/// Each side is represented by `samples_per_mesh` points sampled uniformly by area on its
/// surface (seeded from `seed`; the two sides use different streams) or, for a point cloud, by
/// all its points. Those points are measured to the other side's triangles, or to its points
/// when it is a cloud. A side with no representative points (empty, or zero area) gives
/// `count == 0` statistics in its direction, and measuring to it gives infinite distances.
pub fn two_sided(a: &Mesh, b: &Mesh, samples_per_mesh: usize, seed: u64) -> (DistanceStats, DistanceStats) {
    let from_a = representative_points(a, samples_per_mesh, stream_seed(seed, 0));
    let from_b = representative_points(b, samples_per_mesh, stream_seed(seed, 1));
    (one_sided(&from_a, Target::of(b)), one_sided(&from_b, Target::of(a)))
}

/// The symmetric Chamfer and Hausdorff distances between `a` and `b`, from [`two_sided`]:
/// chamfer = (mean(a to b) + mean(b to a)) / 2, the mean of the two one-sided mean distances
/// (not squared); hausdorff = max(max(a to b), max(b to a)), estimated on the samples. Both are 0
/// when neither side has points, and infinite when exactly one side is empty.
pub fn chamfer_and_hausdorff(a: &Mesh, b: &Mesh, samples_per_mesh: usize, seed: u64) -> (f32, f32) {
    let (ab, ba) = two_sided(a, b, samples_per_mesh, seed);
    (0.5 * (ab.mean + ba.mean), ab.max.max(ba.max))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;
    use glam::DVec3;

    #[test]
    fn bounded_point_queries_agree_with_the_nearest_distance() {
        let cloud = crate::shapes::sample_surface(&crate::shapes::icosphere(1.0, 3), 5_000, 2);
        let bvh = PointBvh::new(&cloud.positions);
        let mut rng = Rng::new(9);
        for _ in 0..2_000 {
            let p = glam::Vec3::new(rng.f32() * 3.0 - 1.5, rng.f32() * 3.0 - 1.5, rng.f32() * 3.0 - 1.5);
            let d = bvh.distance(p);
            for r in [0.01, 0.05, 0.2, d, 1.0] {
                assert_eq!(bvh.any_within(p, r), d <= r, "{p} {r} {d}");
                let within = bvh.distance_within(p, r);
                assert_eq!(within, if d <= r { d } else { f32::INFINITY }, "{p} {r}");
            }
        }
    }

    /// Independent oracle: project onto the plane in double precision; if the projection is
    /// inside (barycentric test) that is the answer, else the nearest of the three edges.
    fn oracle_distance(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> f64 {
        let (p, a, b, c) = (p.as_dvec3(), a.as_dvec3(), b.as_dvec3(), c.as_dvec3());
        let segment = |a: DVec3, b: DVec3| {
            let ab = b - a;
            let t =
                if ab.length_squared() > 0.0 { ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0) } else { 0.0 };
            (a + ab * t).distance(p)
        };
        let edges = segment(a, b).min(segment(b, c)).min(segment(c, a));
        let n = (b - a).cross(c - a);
        if n.length_squared() == 0.0 {
            return edges;
        }
        let q = p - n * ((p - a).dot(n) / n.length_squared());
        let inside = [(a, b), (b, c), (c, a)].iter().all(|&(u, v)| (v - u).cross(q - u).dot(n) >= 0.0);
        if inside {
            q.distance(p)
        } else {
            edges
        }
    }

    fn random_vec(rng: &mut Rng) -> Vec3 {
        Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 2.0 - Vec3::ONE
    }

    #[test]
    fn point_triangle_matches_oracle() {
        let mut rng = Rng::new(11);
        for _ in 0..20_000 {
            let (a, b, c) = (random_vec(&mut rng), random_vec(&mut rng), random_vec(&mut rng));
            let p = random_vec(&mut rng) * 2.0;
            let got = f64::from(closest_point_on_triangle(p, a, b, c).distance(p));
            let want = oracle_distance(p, a, b, c);
            assert!((got - want).abs() < 1e-5, "{p} {a} {b} {c}: {got} vs {want}");
        }
        // Degenerate triangles: a point, a segment, collinear corners.
        let p = Vec3::new(0.3, 1.0, 0.0);
        let z = Vec3::ZERO;
        assert_eq!(closest_point_on_triangle(p, z, z, z), z);
        let q = closest_point_on_triangle(p, z, Vec3::X, Vec3::X);
        assert!((q - Vec3::new(0.3, 0.0, 0.0)).length() < 1e-6);
        let q = closest_point_on_triangle(p, z, Vec3::X * 0.5, Vec3::X);
        assert!((q - Vec3::new(0.3, 0.0, 0.0)).length() < 1e-6);
    }

    /// A small random triangle soup.
    fn soup(rng: &mut Rng, n: usize) -> Mesh {
        let mut mesh = Mesh::default();
        for t in 0..n as u32 {
            let centre = random_vec(rng);
            for _ in 0..3 {
                mesh.positions.push(centre + random_vec(rng) * 0.2);
            }
            mesh.triangles.push([3 * t, 3 * t + 1, 3 * t + 2]);
        }
        mesh
    }

    #[test]
    fn triangle_bvh_matches_brute_force() {
        let mut rng = Rng::new(5);
        let mesh = soup(&mut rng, 300);
        let bvh = TriangleBvh::new(&mesh);
        assert_eq!(bvh.len(), 300);
        for _ in 0..3_000 {
            let p = random_vec(&mut rng) * 1.5;
            let brute = mesh
                .triangles
                .iter()
                .map(|t| {
                    let [a, b, c] = t.map(|v| mesh.positions[v as usize]);
                    closest_point_on_triangle(p, a, b, c).distance_squared(p).sqrt()
                })
                .fold(f32::INFINITY, f32::min);
            let found = bvh.closest_point(p).unwrap();
            assert!((found.distance - brute).abs() <= 1e-6, "{} vs {brute}", found.distance);
            let [a, b, c] = mesh.triangles[found.triangle as usize].map(|v| mesh.positions[v as usize]);
            assert!((closest_point_on_triangle(p, a, b, c) - found.point).length() <= 1e-6);
        }
    }

    /// Checks the invariants a query relies on: every item in exactly one leaf, leaves no larger
    /// than `leaf_size`, children's boxes inside their parent's, items' boxes inside their leaf's.
    fn validate(bvh: &Bvh, boxes: &[(Vec3, Vec3)], leaf_size: usize) {
        let mut seen = vec![false; boxes.len()];
        let mut stack = vec![(0usize, 1usize)];
        while let Some((i, depth)) = stack.pop() {
            assert!(depth < MAX_STACK, "too deep for the search's stack");
            let node = bvh.nodes[i];
            let inside = |lo: Vec3, hi: Vec3| lo.cmpge(node.min).all() && hi.cmple(node.max).all();
            if node.count > 0 {
                assert!(node.count as usize <= leaf_size);
                for position in node.first..node.first + node.count {
                    let item = bvh.order[position as usize] as usize;
                    assert!(!seen[item]);
                    seen[item] = true;
                    assert!(inside(boxes[item].0, boxes[item].1));
                }
            } else {
                for child in [node.first as usize, node.first as usize + 1] {
                    assert!(child > i && child < bvh.nodes.len());
                    assert!(inside(bvh.nodes[child].min, bvh.nodes[child].max));
                    stack.push((child, depth + 1));
                }
            }
        }
        assert!(seen.iter().all(|&s| s));
    }

    #[test]
    fn parallel_build_is_valid_and_thread_independent() {
        let mut rng = Rng::new(3);
        let n = 5 * PARALLEL_BUILD + 123;
        let boxes: Vec<(Vec3, Vec3)> = (0..n)
            .map(|_| {
                let p = random_vec(&mut rng);
                (p, p + Vec3::splat(rng.f32() * 0.01))
            })
            .collect();
        let points: Vec<Vec3> = boxes.iter().map(|b| b.0).collect();
        let point_boxes: Vec<(Vec3, Vec3)> = points.iter().map(|&p| (p, p)).collect();
        for morton in [false, true] {
            let build = |threads| {
                let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
                pool.install(|| if morton { Bvh::build_morton(&boxes, 4) } else { Bvh::build_over_points(&points, 4) })
            };
            let (one, two) = (build(1), build(2));
            validate(&two, if morton { &boxes } else { &point_boxes }, 4);
            assert_eq!(one.order, two.order);
            assert_eq!(format!("{:?}", one.nodes), format!("{:?}", two.nodes));
        }
        // Many equal centres (duplicated triangles): split in the middle, still valid.
        let repeated: Vec<(Vec3, Vec3)> = boxes.iter().take(100).cycle().take(3 * PARALLEL_BUILD).copied().collect();
        validate(&Bvh::build_morton(&repeated, 4), &repeated, 4);
        let cloud = PointBvh::new(&points);
        for q in points.iter().step_by(997) {
            assert_eq!(cloud.distance(*q), 0.0);
        }
    }

    #[test]
    fn point_bvh_matches_brute_force() {
        let mut rng = Rng::new(9);
        let cloud: Vec<Vec3> = (0..2_000).map(|_| random_vec(&mut rng)).collect();
        let queries: Vec<Vec3> = (0..2_000).map(|_| random_vec(&mut rng) * 1.2).collect();
        let bvh = PointBvh::new(&cloud);
        let fast = point_to_points_distances(&queries, &cloud);
        for (q, d) in queries.iter().zip(&fast) {
            let (brute_index, brute) =
                cloud.iter().enumerate().map(|(i, c)| (i, c.distance(*q))).min_by(|x, y| x.1.total_cmp(&y.1)).unwrap();
            assert!((d - brute).abs() <= 1e-6);
            let (d2, index) = bvh.nearest(*q).unwrap();
            assert_eq!(d2, *d);
            assert!((cloud[index as usize].distance(*q) - brute).abs() <= 1e-6, "{brute_index}");
        }
    }

    #[test]
    fn empty_targets_and_stats() {
        let p = [Vec3::ONE];
        assert_eq!(point_to_mesh_distances(&p, &Mesh::default()), vec![f32::INFINITY]);
        assert_eq!(point_to_points_distances(&p, &[]), vec![f32::INFINITY]);
        assert!(TriangleBvh::new(&Mesh::default()).closest_point(Vec3::ZERO).is_none());
        let mut bad = Mesh::from_points(vec![Vec3::ZERO], None);
        bad.triangles.push([0, 1, 2]);
        assert!(TriangleBvh::new(&bad).is_empty());
        assert!(PointBvh::new(&[Vec3::ZERO]).distance(Vec3::NAN).is_nan());

        assert_eq!(DistanceStats::from_distances(&[]), DistanceStats::default());
        let values: Vec<f32> = (1..=200).map(|i| i as f32).collect();
        let s = DistanceStats::from_distances(&values);
        assert_eq!((s.count, s.max, s.p99), (200, 200.0, 198.0));
        assert!((s.mean - 100.5).abs() < 1e-4);
        let s = DistanceStats::from_distances(&[3.0]);
        assert_eq!((s.mean, s.rms, s.max, s.p99), (3.0, 3.0, 3.0, 3.0));

        let cloud = Mesh::from_points(vec![Vec3::ZERO, Vec3::X * 10.0], None);
        assert_eq!(chamfer_and_hausdorff(&Mesh::default(), &Mesh::default(), 10, 1), (0.0, 0.0));
        let (c, h) = chamfer_and_hausdorff(&cloud, &Mesh::default(), 10, 1);
        assert!(c.is_infinite() && h.is_infinite());
        let shifted = Mesh::from_points(vec![Vec3::Y, Vec3::X * 10.0 + Vec3::Y * 3.0], None);
        let (c, h) = chamfer_and_hausdorff(&cloud, &shifted, 10, 1);
        assert!((c - 2.0).abs() < 1e-6 && (h - 3.0).abs() < 1e-6, "{c} {h}");
    }
}
