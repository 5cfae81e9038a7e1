//! One refinement level (paper §5.2, "Mesh refinement"): the triangles asked for (all of them,
//! or those the samples are still far from) are split 1-to-4, their neighbours as a crack-free
//! mesh needs ([`red_green`]); each new mid-edge vertex starts on the curved PN triangle of its edge (Vlachos et al. 2001), is
//! then displaced by the quadtree of its T-node, and, where no quadtree leaf is left for it,
//! smoothed tangentially towards its already final neighbours.
//!
//! Displacement: the new vertices of a T-node are dropped down its quadtree together; where a
//! vertex is alone in an S-node, it moves to the average sample of the unlocked leaf of that
//! S-node with the highest local variation, and the leaf is locked for good. PN triangles
//! interpolate their corners, so a displaced vertex stays put in later levels; the locking
//! keeps two vertices from being pulled onto the same samples (which would alias).
//!
//! "Onto a leaf" means onto the quadratic height field fitted to the leaf's samples
//! ([`leaf_fit`](super::leaf_fit)) where they determine one, else onto the leaf's tangent plane.

use super::adjacency::Rows;
use super::cluster::t_node_at;
use super::folds::{folded_vertices, is_folded};
use super::leaf_fit::QuadraticPatch;
use super::red_green::{self, Green};
use crate::progress::Threads;
use crate::quadric::CellStats;
use crate::tree::{Node, NodeKind, VsTree};
use glam::{Vec2, Vec3};
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};

/// A mesh being refined: positions, unit normals, and the T-node each vertex belongs to.
#[derive(Clone, Debug, Default)]
pub(crate) struct Surface {
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    pub labels: Vec<u32>,
    pub triangles: Vec<[u32; 3]>,
}

impl Surface {
    /// Removes the vertices no triangle uses, with their normals and labels; the others are
    /// renumbered in the order the triangles first use them.
    pub fn drop_unused_vertices(&mut self) {
        let kept = super::renumber_used_vertices(&mut self.triangles, self.positions.len());
        self.positions = kept.iter().map(|&v| self.positions[v]).collect();
        self.normals = kept.iter().map(|&v| self.normals[v]).collect();
        self.labels = kept.iter().map(|&v| self.labels[v]).collect();
    }
}

/// What one level did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LevelStats {
    /// Triangles split 1-to-4 (those marked, and those the crack-free closure added).
    pub split: usize,
    pub new_vertices: usize,
    pub displaced: usize,
}

/// One refinement level's result.
pub(crate) struct Level {
    pub surface: Surface,
    /// Its green pairs, merged back before the next level splits.
    pub greens: Vec<Green>,
    /// Per triangle: the triangle of the level before that it is part of.
    pub from: Vec<u32>,
    pub stats: LevelStats,
}

/// The quadtrees' leaves, summarised once, and which of them are used up.
pub(crate) struct Refiner<'t> {
    tree: &'t VsTree,
    /// Per leaf below the T-layer: the average sample, the mean normal, the local variation.
    /// (Unused entries for other nodes.)
    average: Vec<Vec3>,
    normal: Vec<Vec3>,
    variation: Vec<f32>,
    /// Per leaf below the T-layer: the quadratic height field fitted to its samples, where
    /// they determine one.
    patch: Vec<Option<QuadraticPatch>>,
    locked: Vec<AtomicBool>,
}

impl<'t> Refiner<'t> {
    pub fn new(tree: &'t VsTree, threads: &Threads) -> Refiner<'t> {
        let origin = tree.root().center.as_dvec3();
        let summaries: Vec<(Vec3, Vec3, f32, Option<QuadraticPatch>)> = threads.run(|| {
            tree.nodes
                .par_iter()
                .map(|node| {
                    if !node.is_leaf() || node.kind == NodeKind::Volume {
                        return (Vec3::ZERO, Vec3::ZERO, 0.0, None);
                    }
                    let mut stats = CellStats::default();
                    for s in tree.samples_of(node) {
                        stats.add(s.position.as_dvec3() - origin, s.normal.as_dvec3());
                    }
                    // Local variation: the leaf's quadric error, i.e. how far its samples are
                    // from agreeing on one point's tangent planes.
                    let variation = stats.l2_error() as f32;
                    let frame = &tree.frames[node.frame as usize];
                    let (center, half) = leaf_square(tree, node);
                    (
                        (stats.centroid() + origin).as_vec3(),
                        stats.mean_normal().normalize_or_zero().as_vec3(),
                        variation,
                        QuadraticPatch::fit(tree.samples_of(node), frame, center, half),
                    )
                })
                .collect()
        });
        let (mut average, mut normal, mut variation, mut patch) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for (a, n, v, q) in summaries {
            average.push(a);
            normal.push(n);
            variation.push(v);
            patch.push(q);
        }
        let locked = (0..tree.nodes.len()).map(|_| AtomicBool::new(false)).collect();
        Refiner { tree, average, normal, variation, patch, locked }
    }

    /// Splits the triangles of `s` that `marked` says 1-to-4 (and their neighbours as
    /// [`red_green`] needs for a crack-free mesh, after merging `greens`, the previous
    /// level's green pairs) and places the new vertices.
    pub fn refine(&self, s: &Surface, marked: &[bool], greens: &[Green], threads: &Threads) -> Level {
        threads.run(|| self.refine_level(s, marked, greens))
    }

    fn refine_level(&self, s: &Surface, marked: &[bool], greens: &[Green]) -> Level {
        let old = s.positions.len() as u32;
        let halves_well = |t: [u32; 3], k: usize| halves_well(t.map(|v| s.positions[v as usize]), k);
        let split = red_green::split(&s.triangles, s.positions.len(), marked, greens, halves_well);
        // A border edge (one face) gives a border vertex, which stays on its edge's curve:
        // sliding or smoothing it towards its neighbours would pull the border inward.
        let on_border = &split.on_border;

        // New vertices on the PN triangles' edge curves, with PN's quadratic normals.
        let placed: Vec<(Vec3, Vec3, u32)> = split
            .new_edges
            .par_iter()
            .map(|&(a, b)| {
                let (pa, pb, na, nb) =
                    (s.positions[a as usize], s.positions[b as usize], s.normals[a as usize], s.normals[b as usize]);
                let (p, n) = pn_midpoint(pa, na, pb, nb);
                let label = t_node_at(self.tree, p).unwrap_or(s.labels[a as usize]);
                (p, n, label)
            })
            .collect();
        let mut out = Surface {
            positions: s.positions.clone(),
            normals: s.normals.clone(),
            labels: s.labels.clone(),
            triangles: split.triangles,
        };
        for (p, n, l) in &placed {
            out.positions.push(*p);
            out.normals.push(*n);
            out.labels.push(*l);
        }

        // Displacement, one T-node's quadtree per task.
        let mut by_t_node: Vec<(u32, u32)> =
            placed.iter().enumerate().map(|(k, &(_, _, l))| (l, old + k as u32)).collect();
        by_t_node.par_sort_unstable();
        let groups: Vec<&[(u32, u32)]> = by_t_node.chunk_by(|a, b| a.0 == b.0).collect();
        let moves: Vec<(u32, u32)> = groups
            .par_iter()
            .flat_map_iter(|group| {
                let t = group[0].0 as usize;
                let vertices: Vec<(u32, Vec2)> =
                    group.iter().map(|&(_, v)| (v, self.uv(t, out.positions[v as usize]))).collect();
                let mut moves = Vec::new();
                self.displace(t, vertices, &mut moves);
                moves
            })
            .collect();
        let mut displaced = vec![false; out.positions.len()];
        let mut border = vec![false; out.positions.len()];
        for (k, &b) in on_border.iter().enumerate() {
            border[old as usize + k] = b;
        }
        for &(v, leaf) in &moves {
            let v = v as usize;
            out.positions[v] = if border[v] {
                self.onto_leaf(leaf as usize, out.positions[v])
            } else {
                self.place_on_leaf(leaf as usize, out.positions[v])
            };
            if self.normal[leaf as usize] != Vec3::ZERO {
                out.normals[v] = self.normal[leaf as usize];
            }
            displaced[v] = true;
        }

        smooth_tangentially(&mut out, old, &displaced, &border);
        self.project_undisplaced(&mut out, old as usize, &displaced);
        self.unfold(&mut out, old as usize, &border);
        let stats = LevelStats { split: split.red, new_vertices: placed.len(), displaced: moves.len() };
        Level { surface: out, greens: split.greens, from: split.from, stats }
    }

    /// Moves each vertex of the base mesh along the normal onto the tangent plane of the
    /// quadtree leaf under it (its samples' centroid and mean normal). M0 lies on the blended
    /// T-node planes, which pass through their patches' centroids, so on a curved surface it
    /// sits inside by a T-node patch's sag; a leaf is smaller, and so is its sag. Moves longer
    /// than the T-node's half size are not made (the leaf would belong to another sheet).
    pub fn snap_base(&self, s: &mut Surface) {
        for v in 0..s.positions.len() {
            let t = s.labels[v] as usize;
            let Some(leaf) = self.leaf_under(t, self.uv(t, s.positions[v])) else { continue };
            let snapped = self.onto_leaf(leaf, s.positions[v]);
            if self.normal[leaf] != Vec3::ZERO && snapped.distance(s.positions[v]) <= self.tree.nodes[t].half {
                s.positions[v] = snapped;
                s.normals[v] = self.normal[leaf];
            }
        }
    }

    /// Moves each new vertex that no leaf was left for along the normal onto the tangent plane
    /// of the leaf under it, without locking the leaf. The PN patches and the tangential
    /// smoothing put it near the surface, off by the curvature that the coarse vertices and
    /// normals around it did not capture; sliding along the normal keeps its place in the
    /// mesh, so several vertices can share a leaf without piling up (the aliasing that the
    /// paper's locking avoids comes from moving to the leaf's average sample). Moves longer than
    /// [`PROJECTION_REACH`] leaf half sizes are not made (the leaf would belong to another
    /// sheet), nor moves that fold a triangle.
    fn project_undisplaced(&self, s: &mut Surface, first: usize, displaced: &[bool]) {
        let moved: Vec<(usize, Vec3)> = (first..s.positions.len())
            .into_par_iter()
            .filter(|&v| !displaced[v])
            .filter_map(|v| {
                let t = s.labels[v] as usize;
                let leaf = self.leaf_under(t, self.uv(t, s.positions[v]))?;
                if self.normal[leaf] == Vec3::ZERO {
                    return None;
                }
                let p = self.onto_leaf(leaf, s.positions[v]);
                (p.distance(s.positions[v]) <= PROJECTION_REACH * self.leaf_half(leaf)).then_some((v, p))
            })
            .collect();
        let mut before = Vec::with_capacity(moved.len());
        for &(v, p) in &moved {
            before.push((v, s.positions[v]));
            s.positions[v] = p;
        }
        // Where a leaf's plane is tilted against the mesh around it the move can fold a
        // triangle over: those moves are undone.
        let folded = folded_vertices(s);
        for (v, p) in before {
            if folded.binary_search(&v).is_ok() {
                s.positions[v] = p;
            }
        }
    }

    /// Half the side of leaf `leaf`'s square.
    fn leaf_half(&self, leaf: usize) -> f32 {
        leaf_square(self.tree, &self.tree.nodes[leaf]).1
    }

    /// Unfolds the base mesh where clustering left triangles facing against their corners'
    /// normals (where a T-node is large for the curvature under it): each corner of such a
    /// triangle moves to the mean of its neighbours, then onto the quadtree leaf under that
    /// point. A few rounds; corners that cannot be unfolded stay where they are, and so do
    /// border vertices: the mean of a border vertex's neighbours is inside the mesh, so moving
    /// it there would pull the border inward (a whole region of a large flat T-node when its
    /// corner folds).
    pub fn unfold_base(&self, s: &mut Surface) {
        self.unfold(s, 0, &crate::topology::border_vertices(&s.triangles, s.positions.len()));
    }

    /// [`Refiner::unfold_base`] for the vertices from `first` on that `border` does not mark
    /// (the others stay put). After one pass over all triangles, each round looks only at the
    /// triangles around the vertices it moved: no other triangle can fold or unfold.
    fn unfold(&self, s: &mut Surface, first: usize, border: &[bool]) {
        let movable = |v: &usize| *v >= first && !border[*v];
        let mut folded: Vec<usize> = folded_vertices(s).into_iter().filter(movable).collect();
        if folded.is_empty() {
            return;
        }
        let faces = Rows::faces(&s.triangles, s.positions.len());
        let mut ring = Vec::new();
        for round in 0..2 * UNFOLD_ROUNDS {
            for &v in &folded {
                ring.clear();
                for &t in faces.of(v as u32) {
                    ring.extend(s.triangles[t as usize].iter().copied().filter(|&w| w as usize != v));
                }
                ring.sort_unstable();
                ring.dedup();
                if ring.is_empty() {
                    continue;
                }
                let mean = ring.iter().map(|&w| s.positions[w as usize]).sum::<Vec3>() / ring.len() as f32;
                // Back onto the surface: the leaf under the mean, in whichever T-node holds it.
                let t = t_node_at(self.tree, mean).map_or(s.labels[v] as usize, |t| t as usize);
                let leaf = self.leaf_under(t, self.uv(t, mean)).filter(|&l| self.normal[l] != Vec3::ZERO);
                if round < UNFOLD_ROUNDS {
                    if let Some(leaf) = leaf {
                        s.positions[v] = self.place_on_leaf(leaf, mean);
                    }
                } else {
                    // Where that keeps folding (noisy leaves whose planes disagree by more than
                    // the vertices' spacing), the mean is only moved along the leaf's normal
                    // onto its plane: no sideways slide onto the leaf's square.
                    s.positions[v] = leaf.map_or(mean, |leaf| self.onto_leaf(leaf, mean));
                }
            }
            let mut still: Vec<usize> = folded
                .iter()
                .flat_map(|&v| faces.of(v as u32))
                .filter(|&&t| is_folded(s, &s.triangles[t as usize]))
                .flat_map(|&t| s.triangles[t as usize].map(|w| w as usize))
                .filter(movable)
                .collect();
            still.sort_unstable();
            still.dedup();
            if still.is_empty() {
                return;
            }
            folded = still;
        }
    }

    /// `p` moved onto leaf `leaf`: sideways just enough to be over the leaf's square, then
    /// along the leaf's normal onto its tangent plane. The leaf chosen for a vertex can be
    /// anywhere in the vertex's S-node; jumping to its average sample slides the vertex over
    /// its neighbours (folds), and extending the leaf's plane far beyond the leaf misses the
    /// surface by the curvature.
    fn place_on_leaf(&self, leaf: usize, p: Vec3) -> Vec3 {
        let node = &self.tree.nodes[leaf];
        let frame = &self.tree.frames[node.frame as usize];
        let (center, half) = leaf_square(self.tree, node);
        let uv = frame.project(p);
        let shift = (uv - center).clamp(Vec2::splat(-half), Vec2::splat(half)) + center - uv;
        self.onto_leaf(leaf, p + frame.u * shift.x + frame.v * shift.y)
    }

    /// `p` moved along leaf `leaf`'s mean normal onto its tangent plane (through the average
    /// sample). Moving straight to the average sample would also slide the vertex sideways
    /// by up to the leaf's size, over its neighbours, and fold triangles; along the normal it
    /// keeps the place the 1-to-4 split gave it on the surface.
    /// Where the leaf's samples determine a quadratic height field ([`QuadraticPatch`]), `p`
    /// goes along the T-node's normal onto that instead, which follows the curvature the
    /// plane misses; unless that lands far from the plane (the fit bends towards something
    /// the leaf's plane does not describe, such as a few samples of another sheet).
    fn onto_leaf(&self, leaf: usize, p: Vec3) -> Vec3 {
        let n = self.normal[leaf];
        let on_plane = p + n * (self.average[leaf] - p).dot(n);
        let Some(patch) = &self.patch[leaf] else { return on_plane };
        let on_patch = patch.project(&self.tree.frames[self.tree.nodes[leaf].frame as usize], p);
        if on_patch.distance(on_plane) <= PATCH_TRUST * self.leaf_half(leaf) {
            on_patch
        } else {
            on_plane
        }
    }

    /// The leaf of T-node `t`'s quadtree whose square holds plane coordinates `uv`, if any.
    fn leaf_under(&self, t: usize, uv: Vec2) -> Option<usize> {
        let mut i = t;
        while !self.tree.nodes[i].is_leaf() {
            let center = if i == t {
                self.tree.frames[self.tree.nodes[t].frame as usize].square_center
            } else {
                self.tree.nodes[i].center_uv()
            };
            let slot = (uv.x >= center.x) as u8 | ((uv.y >= center.y) as u8) << 1;
            i = self.tree.nodes[i].children().find(|&c| self.tree.nodes[c].slot == slot)?;
        }
        (self.tree.nodes[i].count > 0).then_some(i)
    }

    /// Coordinates of `p` in the plane of T-node `t`.
    fn uv(&self, t: usize, p: Vec3) -> Vec2 {
        self.tree.frames[self.tree.nodes[t].frame as usize].project(p)
    }

    /// Sends `vertices` (with their plane coordinates) down the quadtree from node `i`, and
    /// records (vertex, leaf) for each vertex that ends up alone in a node with a free leaf.
    fn displace(&self, i: usize, vertices: Vec<(u32, Vec2)>, moves: &mut Vec<(u32, u32)>) {
        let node = &self.tree.nodes[i];
        let (center, half) = if node.kind == NodeKind::Transition {
            let f = &self.tree.frames[node.frame as usize];
            (f.square_center, f.square_half)
        } else {
            (node.center_uv(), node.half)
        };
        let inside: Vec<(u32, Vec2)> =
            vertices.into_iter().filter(|(_, uv)| (*uv - center).abs().max_element() <= half).collect();
        match inside.len() {
            0 => {}
            1 => {
                if let Some(leaf) = self.take_leaf(i, inside[0].1) {
                    moves.push((inside[0].0, leaf));
                }
            }
            _ if node.is_leaf() => {} // several vertices share one leaf: none is displaced
            _ => {
                for child in node.children() {
                    let slot = self.tree.nodes[child].slot;
                    let mine: Vec<(u32, Vec2)> = inside
                        .iter()
                        .copied()
                        .filter(|(_, uv)| ((uv.x >= center.x) as u8 | ((uv.y >= center.y) as u8) << 1) == slot)
                        .collect();
                    if !mine.is_empty() {
                        self.displace(child, mine, moves);
                    }
                }
            }
        }
    }

    /// The unlocked leaf below node `i` with the highest variation (ties: the one nearest to
    /// `uv`), locked before it is returned.
    fn take_leaf(&self, i: usize, uv: Vec2) -> Option<u32> {
        let mut best: Option<(f32, f32, usize)> = None;
        let mut stack = vec![i];
        while let Some(n) = stack.pop() {
            let node = &self.tree.nodes[n];
            if !node.is_leaf() {
                stack.extend(node.children());
                continue;
            }
            if self.locked[n].load(Ordering::Relaxed) {
                continue;
            }
            let distance = (self.uv_of_leaf(n) - uv).length_squared();
            let candidate = (self.variation[n], -distance, n);
            if best.is_none_or(|b| (candidate.0, candidate.1) > (b.0, b.1)) {
                best = Some(candidate);
            }
        }
        let (_, _, leaf) = best?;
        self.locked[leaf].store(true, Ordering::Relaxed);
        Some(leaf as u32)
    }

    fn uv_of_leaf(&self, n: usize) -> Vec2 {
        leaf_square(self.tree, &self.tree.nodes[n]).0
    }
}

/// The square of a node below the T-layer in its frame's plane coordinates: an S-node's own,
/// a T-node's bounding square. (Centre, half side.)
fn leaf_square(tree: &VsTree, node: &Node) -> (Vec2, f32) {
    if node.kind == NodeKind::Surface {
        (node.center_uv(), node.half)
    } else {
        let frame = &tree.frames[node.frame as usize];
        (frame.square_center, frame.square_half)
    }
}

/// How far a vertex left without a leaf of its own may be projected onto the leaf under it,
/// in leaf half sides. Where coarser levels bridged a crease, the vertices over it must travel
/// deeper than a leaf is wide. Measured on the 24 closed models at 200k clean points and the
/// corpus bench's open inputs, 3 against 1 and 0 (no projection): the same genus everywhere and
/// the same median Chamfer; creases kept (fandisk closed 0.0218% of the diagonal against 0.0260%
/// with 0; its single view 0.094% against 0.123% with 1), at the cost of 6-13% more folds.
const PROJECTION_REACH: f32 = 3.0;

/// How far from a leaf's plane its quadratic patch may put a vertex, in leaf half sides.
const PATCH_TRUST: f32 = 0.5;

/// Rounds of [`Refiner::unfold_base`].
const UNFOLD_ROUNDS: usize = 5;

/// The midpoint of a PN triangle's edge curve from (`pa`, `na`) to (`pb`, `nb`), and the PN
/// quadratic normal there. The edge's cubic Bézier control points are the ends moved a third of
/// the way along the edge and projected onto the end's tangent plane; the curve (and so the
/// point) is the same for both triangles sharing the edge.
pub(crate) fn pn_midpoint(pa: Vec3, na: Vec3, pb: Vec3, nb: Vec3) -> (Vec3, Vec3) {
    let e = pb - pa;
    let b1 = (2.0 * pa + pb - e.dot(na) * na) / 3.0;
    let b2 = (2.0 * pb + pa + e.dot(nb) * nb) / 3.0;
    let p = (pa + 3.0 * b1 + 3.0 * b2 + pb) / 8.0;
    // Quadratic normal: the average, reflected across the plane normal to the edge.
    let len2 = e.length_squared();
    let v = if len2 > 0.0 { 2.0 * e.dot(na + nb) / len2 } else { 0.0 };
    let n110 = (na + nb - v * e).normalize_or_zero();
    let n = (0.25 * (na + nb) + 0.5 * n110).normalize_or_zero();
    (p, if n == Vec3::ZERO { na } else { n })
}

/// A green split (see [`red_green`]) halves a triangle from the midpoint of one edge; where that
/// makes an angle under this many degrees, and smaller than the triangle's own smallest, the
/// triangle is split 1-to-4 instead, which keeps its shape: halving a skewed triangle (near a
/// crease, where M0's triangles bend round) makes slivers.
const GREEN_MIN_DEGREES: f32 = 20.0;

/// Whether halving triangle `corners` at the midpoint of its edge `k` (corner k to k + 1)
/// keeps its angles above [`GREEN_MIN_DEGREES`] or its own smallest.
fn halves_well(corners: [Vec3; 3], k: usize) -> bool {
    let smallest = |[a, b, c]: [Vec3; 3]| {
        let at = |p: Vec3, q: Vec3, r: Vec3| (q - p).angle_between(r - p);
        at(a, b, c).min(at(b, c, a)).min(at(c, a, b)).to_degrees()
    };
    let (b, c, a) = (corners[k], corners[(k + 1) % 3], corners[(k + 2) % 3]);
    let m = (b + c) / 2.0;
    let halves = smallest([a, b, m]).min(smallest([a, m, c]));
    halves >= GREEN_MIN_DEGREES.min(smallest(corners)) - 1e-3
}

/// Moves each new vertex that was not displaced towards the mean of its neighbours that are
/// final (old vertices and displaced ones), within its tangent plane only. Each new vertex has
/// at least its edge's two ends as final neighbours. Border vertices stay on their edge's curve.
fn smooth_tangentially(s: &mut Surface, first_new: u32, displaced: &[bool], border: &[bool]) {
    let is_final = |v: u32| v < first_new || displaced[v as usize];
    let mut sum = vec![Vec3::ZERO; s.positions.len()];
    let mut count = vec![0u32; s.positions.len()];
    for t in &s.triangles {
        for k in 0..3 {
            for (x, y) in [(t[k], t[(k + 1) % 3]), (t[(k + 1) % 3], t[k])] {
                if !is_final(x) && is_final(y) {
                    sum[x as usize] += s.positions[y as usize];
                    count[x as usize] += 1;
                }
            }
        }
    }
    for v in first_new as usize..s.positions.len() {
        if !displaced[v] && !border[v] && count[v] > 0 {
            let n = s.normals[v];
            let delta = sum[v] / count[v] as f32 - s.positions[v];
            s.positions[v] += delta - n * n.dot(delta);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_triangle_is_halved_only_where_that_makes_no_sliver() {
        let h = 3f32.sqrt() / 2.0;
        let equilateral = [Vec3::ZERO, Vec3::X, Vec3::new(0.5, h, 0.0)];
        assert!((0..3).all(|k| halves_well(equilateral, k)), "halves of 30, 60 and 90 degrees");
        // Right angle at the origin, 14 degrees at (4, 0). Halved across the hypotenuse, the
        // smallest angle stays the triangle's own; across the long leg it would be 12.5.
        let skewed = [Vec3::ZERO, Vec3::new(4.0, 0.0, 0.0), Vec3::Y];
        assert!(halves_well(skewed, 1));
        assert!(!halves_well(skewed, 0));
    }

    #[test]
    fn pn_midpoint_of_an_arc_bulges_towards_the_circle() {
        // A 90-degree arc of the unit circle with radial normals: the PN control points are
        // (1, 1/3) and (1/3, 1), so the curve's midpoint is exactly (5/8, 5/8), outside the
        // chord (PN triangles do not reproduce circles exactly).
        let (a, b) = (Vec3::X, Vec3::Y);
        let (p, n) = pn_midpoint(a, a, b, b);
        assert!((p - Vec3::new(0.625, 0.625, 0.0)).length() < 1e-6, "{p}");
        assert!((n - Vec3::new(1.0, 1.0, 0.0).normalize()).length() < 1e-5);
        // A 20-degree arc: the midpoint is within 0.1% of the circle.
        let c = Vec3::new(20f32.to_radians().cos(), 20f32.to_radians().sin(), 0.0);
        let (p, _) = pn_midpoint(a, a, c, c);
        assert!((p.length() - 1.0).abs() < 1e-3, "{}", p.length());
        // Flat: the midpoint of the chord.
        let (p, _) = pn_midpoint(Vec3::ZERO, Vec3::Z, Vec3::X, Vec3::Z);
        assert!((p - Vec3::new(0.5, 0.0, 0.0)).length() < 1e-6);
    }
}
