//! The base mesh's surface extracted over the tree's own octree ([`super::BaseMesh::Adaptive`]):
//! dual contouring (Ju et al. 2002) with the T-nodes as cells, so each region is polygonised at
//! its own T-node's size and the field is evaluated only at the corners of the T-layer's cubes.
//!
//! The octree is the tree's V-nodes made complete: a missing child is an empty leaf, T-nodes and
//! childless V-nodes are leaves, and the tree's root sits inside a cube four times its size so
//! the surface never reaches the outer boundary.
//!
//! Every minimal edge whose ends lie on different sides gives one polygon joining the vertices
//! of the (three or four) leaves around it. A leaf gets one vertex per loop that the surface
//! draws on its boundary, as in Manifold Dual Contouring (Schaefer, Ju, Warren 2007): the loops
//! come from marching squares over the minimal faces of the leaf's boundary, and a face crossed
//! more than twice is resolved by the field at its centre, the same way from both sides. A leaf
//! with two sheets through it thus gets two vertices, and the result is a closed 2-manifold.

use crate::polygonise::FastMap;
use crate::progress::Threads;
use crate::topology;
use crate::tree::{NodeKind, VsTree};
use crate::union_find::UnionFind;
use glam::{UVec3, Vec2, Vec3};
use rayon::prelude::*;

/// Leaves at non-manifold vertices are split this many times at most; each round splits only
/// those, so it costs little (the corpus's 200k clouds need at most five).
const REPAIR_ROUNDS: u32 = 8;
/// A leaf at non-manifold vertices may be split this many levels below the finest the samples
/// resolve: where two sheets of the field pass within a finest leaf, its loops cannot tell them
/// apart, and the field, defined at any scale, can. Each level takes a handful of leaves (2 to
/// 10 on the corpus's 200k clouds); without them man, cheese and rotor_small kept 8 to 38
/// non-manifold vertices and were polygonised on the grid, at twenty times the evaluations.
const REPAIR_LEVELS: u32 = 2;
/// Corner coordinates are packed 21 bits to an axis into one key.
const KEY_BITS: u32 = 21;
/// Octree levels taken from the tree: the outer cube takes two levels and the finest level is
/// left for splits; deeper V-nodes become leaves (cells 2^-17 of the cloud are finer than any
/// sampling).
const TREE_LEVELS: u32 = KEY_BITS - 4;
/// No child, or no tree node.
const NONE: u32 = u32::MAX;

/// One cell of the complete octree.
#[derive(Clone, Copy)]
struct Cell {
    /// Lowest corner, in units of the finest level's cell.
    min: UVec3,
    level: u32,
    /// First of eight children, or [`NONE`] for a leaf.
    children: u32,
    /// The tree node a leaf lies in: a T-node, a childless V-node, or [`NONE`] for an empty leaf.
    node: u32,
}

/// The complete octree over the tree's V-nodes, with the field at the corners it needs.
struct Octree<'t> {
    tree: &'t VsTree,
    cells: Vec<Cell>,
    /// World position of the integer corner (0, 0, 0), and one integer unit's length.
    origin: Vec3,
    unit: f32,
    /// The field at the corners evaluated so far.
    values: FastMap<u64, f32>,
}

/// The surface dual contouring gives: the mesh, and per vertex the T-node it stands for
/// ([`NONE`] where its leaf is no T-node's).
pub(crate) struct Contour {
    pub positions: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
    pub labels: Vec<u32>,
}

/// Polygonises the zero set of `f` (negative inside) over the octree of `tree`'s T-layer; `None`
/// when the result is not a 2-manifold. No leaf is split below `finest` (world units), the
/// samples resolve nothing smaller, except [`REPAIR_LEVELS`] more to make the result a
/// 2-manifold. `opposed(centre, radius, t)` says whether samples of
/// another sheet than T-node `t`'s lie within `radius` of `centre`, facing it across a gap.
pub(crate) fn contour(
    tree: &VsTree,
    f: &(dyn Fn(Vec3) -> f32 + Sync),
    opposed: &(dyn Fn(Vec3, f32, u32) -> bool + Sync),
    finest: f32,
    threads: &Threads,
) -> Option<Contour> {
    let mut octree = Octree::new(tree);
    let finest_level = (KEY_BITS - 1).saturating_sub((finest / octree.unit).max(1.0).log2().floor() as u32);
    octree.split_where_opposed(opposed, finest_level, threads);
    // Leaves whose vertices the polygons do not join into a 2-manifold (a leaf crossed by
    // sheets that its boundary's loops do not tell apart) are split, as far as levels allow.
    let mut rounds = 0;
    loop {
        let mut walk = Walk::default();
        octree.cell_proc(0, &mut walk);
        let ends: Vec<u64> = walk.edges.iter().flat_map(|e| octree.edge_ends(e)).collect();
        octree.evaluate(ends, f, threads);
        let (contour, leaves) = octree.contour_edges(&walk, f, threads);
        let flagged = topology::non_manifold_vertices(&contour.triangles, contour.positions.len());
        let mut to_split: Vec<u32> = leaves.iter().zip(&flagged).filter(|(_, &f)| f).map(|(&l, _)| l).collect();
        to_split.sort_unstable();
        to_split.dedup();
        to_split.retain(|&c| octree.cells[c as usize].level < finest_level + REPAIR_LEVELS);
        rounds += 1;
        if flagged.iter().all(|&f| !f) {
            return Some(contour);
        }
        if to_split.is_empty() || rounds > REPAIR_ROUNDS {
            return None;
        }
        for c in to_split {
            octree.split(c);
        }
    }
}

impl<'t> Octree<'t> {
    fn new(tree: &'t VsTree) -> Octree<'t> {
        let root = tree.root();
        let depth = KEY_BITS - 1;
        let unit = 8.0 * root.half / (1u32 << depth) as f32;
        let mut octree = Octree {
            tree,
            cells: vec![Cell { min: UVec3::ZERO, level: 0, children: NONE, node: NONE }],
            origin: root.center - 3.0 * root.half,
            unit,
            values: FastMap::default(),
        };
        // The tree's root is the last child of the outer cube's first child: a margin of its
        // own size on every side.
        let first = octree.add_children(0, NONE);
        let inner = octree.add_children(first, NONE);
        octree.adopt(inner + 7, 0);
        octree
    }

    /// The side of a cell of `level`, in integer units.
    fn size(&self, level: u32) -> u32 {
        1 << (KEY_BITS - 1 - level)
    }

    /// Makes `cell` the parent of eight leaves in tree node `node`; returns
    /// the first one's index.
    fn add_children(&mut self, cell: usize, node: u32) -> usize {
        let Cell { min, level, .. } = self.cells[cell];
        let half = self.size(level + 1);
        let first = self.cells.len();
        self.cells[cell].children = first as u32;
        self.cells.extend((0..8u32).map(|o| Cell {
            min: min + UVec3::new(o & 1, o >> 1 & 1, o >> 2 & 1) * half,
            level: level + 1,
            children: NONE,
            node,
        }));
        first
    }

    /// Gives `cell` the shape of tree node `node` and its descendants down to the T-layer.
    fn adopt(&mut self, cell: usize, node: usize) {
        let mut stack = vec![(cell, node)];
        while let Some((cell, node)) = stack.pop() {
            let n = &self.tree.nodes[node];
            let deep = self.cells[cell].level >= TREE_LEVELS + 2;
            if n.kind == NodeKind::Volume && !n.is_leaf() && !deep {
                let first = self.add_children(cell, NONE);
                stack.extend(n.children().map(|c| (first + usize::from(self.tree.nodes[c].slot), c)));
            } else {
                self.cells[cell].node = node as u32;
            }
        }
    }

    fn position(&self, key: u64) -> Vec3 {
        self.origin + self.unit * unkey(key).as_vec3()
    }

    /// Evaluates `f` at those of `keys` not evaluated yet.
    fn evaluate(&mut self, mut keys: Vec<u64>, f: &(dyn Fn(Vec3) -> f32 + Sync), threads: &Threads) {
        keys.sort_unstable();
        keys.dedup();
        keys.retain(|k| !self.values.contains_key(k));
        let values: Vec<f32> = threads.run(|| keys.par_iter().map(|&k| f(self.position(k))).collect());
        self.values.extend(keys.into_iter().zip(values));
    }

    fn inside(&self, key: u64) -> bool {
        self.values[&key] < 0.0
    }

    /// Splits the T-nodes' leaves, down to `finest_level`, while another sheet faces the
    /// T-node's within a leaf's side of its centre: a gap narrower than the leaf is seen by no
    /// corner of it, and the handle it makes closes, until the leaves are as small as it.
    fn split_where_opposed(
        &mut self,
        opposed: &(dyn Fn(Vec3, f32, u32) -> bool + Sync),
        finest_level: u32,
        threads: &Threads,
    ) {
        loop {
            let tree = self.tree;
            let leaves: Vec<u32> = (0..self.cells.len() as u32)
                .filter(|&c| {
                    let cell = &self.cells[c as usize];
                    cell.children == NONE
                        && cell.level < finest_level
                        && cell.node != NONE
                        && tree.nodes[cell.node as usize].kind == NodeKind::Transition
                })
                .collect();
            let split: Vec<u32> = threads.run(|| {
                leaves
                    .into_par_iter()
                    .filter(|&c| {
                        let cell = &self.cells[c as usize];
                        let side = self.unit * self.size(cell.level) as f32;
                        let centre = self.origin + self.unit * cell.min.as_vec3() + Vec3::splat(0.5 * side);
                        opposed(centre, side, cell.node)
                    })
                    .collect()
            });
            if split.is_empty() {
                return;
            }
            for c in split {
                self.split(c);
            }
        }
    }

    /// Splits a leaf into eight in the same tree node.
    fn split(&mut self, c: u32) {
        let node = self.cells[c as usize].node;
        self.add_children(c as usize, node);
    }

    /// A child of `c` (octant bits x = 1, y = 2, z = 4), or `c` itself if it is a leaf.
    fn child(&self, c: u32, octant: u32) -> u32 {
        match self.cells[c as usize].children {
            NONE => c,
            first => first + octant,
        }
    }

    fn is_leaf(&self, c: u32) -> bool {
        self.cells[c as usize].children == NONE
    }

    /// Visits every minimal face and edge inside cell `c` (Ju et al.'s `cellProc`).
    fn cell_proc(&self, c: u32, walk: &mut Walk) {
        if self.is_leaf(c) {
            return;
        }
        for o in 0..8 {
            self.cell_proc(self.child(c, o), walk);
        }
        for axis in 0..3 {
            for o in (0..8).filter(|o| o >> axis & 1 == 0) {
                self.face_proc(self.child(c, o), self.child(c, o | 1 << axis), axis, walk);
            }
        }
        for dir in 0..3 {
            let (p, q) = others(dir);
            for h in 0..2 {
                let around =
                    std::array::from_fn(|k| self.child(c, h << dir | (k as u32 & 1) << p | (k as u32 >> 1) << q));
                self.edge_proc(around, dir, walk);
            }
        }
    }

    /// Visits the minimal faces and edges on the face between `a` and `b`, `b` the next
    /// along `axis` (`faceProc`).
    fn face_proc(&self, a: u32, b: u32, axis: u32, walk: &mut Walk) {
        if self.is_leaf(a) && self.is_leaf(b) {
            return;
        }
        let (u, v) = others(axis);
        for quadrant in 0..4u32 {
            let side = (quadrant & 1) << u | (quadrant >> 1) << v;
            self.face_proc(self.child(a, side | 1 << axis), self.child(b, side), axis, walk);
        }
        // The four half edges where the face's quadrants meet.
        for (dir, w) in [(u, v), (v, u)] {
            let (p, _) = others(dir);
            for h in 0..2 {
                let around = std::array::from_fn(|k| {
                    let bits = [k as u32 & 1, k as u32 >> 1];
                    let (along_axis, along_w) = if p == axis { (bits[0], bits[1]) } else { (bits[1], bits[0]) };
                    let octant = h << dir | along_w << w;
                    if along_axis == 0 {
                        self.child(a, octant | 1 << axis)
                    } else {
                        self.child(b, octant)
                    }
                });
                self.edge_proc(around, dir, walk);
            }
        }
    }

    /// Visits the minimal edges along the edge shared by `around` (`edgeProc`): cell `k` lies on
    /// the upper side of the edge along the first other axis if bit 0 of `k` is set, along the
    /// second if bit 1 is.
    fn edge_proc(&self, around: [u32; 4], dir: u32, walk: &mut Walk) {
        if around.iter().all(|&c| self.is_leaf(c)) {
            walk.edges.push(MinimalEdge { around, dir });
            return;
        }
        let (p, q) = others(dir);
        for h in 0..2 {
            let sub = std::array::from_fn(|k| {
                self.child(around[k], h << dir | (1 - (k as u32 & 1)) << p | (1 - (k as u32 >> 1)) << q)
            });
            self.edge_proc(sub, dir, walk);
        }
    }

    /// The keys of a minimal edge's two ends: it is the edge of the smallest cell around it.
    fn edge_ends(&self, e: &MinimalEdge) -> [u64; 2] {
        let k = (0..4).max_by_key(|&k| self.cells[e.around[k] as usize].level).unwrap_or(0);
        let Cell { min, level, .. } = self.cells[e.around[k] as usize];
        let s = self.size(level);
        let (p, q) = others(e.dir);
        let mut start = min;
        start[p as usize] += if k & 1 == 0 { s } else { 0 };
        start[q as usize] += if k >> 1 == 0 { s } else { 0 };
        let mut end = start;
        end[e.dir as usize] += s;
        [key(start), key(end)]
    }

    /// The polygons of the crossed minimal edges, one vertex per loop on a leaf's boundary.
    /// Returns, per vertex, its leaf too.
    fn contour_edges(&self, walk: &Walk, f: &(dyn Fn(Vec3) -> f32 + Sync), threads: &Threads) -> (Contour, Vec<u32>) {
        // The crossed edges, with their crossing point.
        let crossed: Vec<(usize, [u64; 2], Vec3)> = walk
            .edges
            .iter()
            .enumerate()
            .filter_map(|(i, e)| {
                let ends = self.edge_ends(e);
                let [a, b] = ends.map(|k| self.values[&k]);
                ((a < 0.0) != (b < 0.0)).then(|| {
                    let t = (a / (a - b)).clamp(0.0, 1.0);
                    (i, ends, self.position(ends[0]).lerp(self.position(ends[1]), t))
                })
            })
            .collect();
        // One incidence per crossed edge and distinct leaf around it.
        let mut incidence: FastMap<u64, u32> = FastMap::default();
        let mut incidences = 0u32;
        for (c, (i, ..)) in crossed.iter().enumerate() {
            for &leaf in &walk.edges[*i].around {
                incidence.entry(pair(leaf, c as u32)).or_insert_with(|| {
                    incidences += 1;
                    incidences - 1
                });
            }
        }
        // The crossed edges on each minimal face: the faces between neighbours around an edge.
        let mut on_face: FastMap<u64, Vec<u32>> = FastMap::default();
        for (c, (i, ..)) in crossed.iter().enumerate() {
            let a = walk.edges[*i].around;
            for (x, y) in [(0, 1), (2, 3), (0, 2), (1, 3)] {
                if a[x] != a[y] {
                    on_face.entry(pair(a[x].min(a[y]), a[x].max(a[y]))).or_default().push(c as u32);
                }
            }
        }
        // Marching squares on every face joins its crossings in pairs, for both leaves.
        let mut loops = UnionFind::new(incidences as usize);
        let ambiguous: Vec<(u64, Vec3)> = on_face
            .iter()
            .filter(|(_, c)| c.len() > 2)
            .map(|(&faces, _)| (faces, self.face_centre(unpair(faces))))
            .collect();
        let centre_values: Vec<f32> = threads.run(|| ambiguous.par_iter().map(|&(_, p)| f(p)).collect());
        let centre_inside: FastMap<u64, bool> =
            ambiguous.iter().zip(&centre_values).map(|(&(faces, _), &v)| (faces, v < 0.0)).collect();
        for (&faces, crossings) in &on_face {
            let (a, b) = unpair(faces);
            for [x, y] in self.pair_crossings(a, b, crossings, &crossed, centre_inside.get(&faces).copied()) {
                for leaf in [a, b] {
                    loops.union(incidence[&pair(leaf, x)], incidence[&pair(leaf, y)]);
                }
            }
        }
        // A vertex per loop, at the mean of its crossings.
        let mut vertex_of = vec![NONE; incidences as usize];
        let mut sums: Vec<(Vec3, u32, u32)> = Vec::new();
        for (&k, &i) in &incidence {
            let (leaf, c) = unpair(k);
            let root = loops.find(i) as usize;
            if vertex_of[root] == NONE {
                vertex_of[root] = sums.len() as u32;
                sums.push((Vec3::ZERO, 0, leaf));
            }
            let s = &mut sums[vertex_of[root] as usize];
            s.0 += crossed[c as usize].2;
            s.1 += 1;
        }
        let mut triangles = Vec::with_capacity(2 * crossed.len());
        let positions: Vec<Vec3> = sums.iter().map(|&(sum, n, _)| sum / n as f32).collect();
        for (c, &(i, ends, _)) in crossed.iter().enumerate() {
            let e = &walk.edges[i];
            // Around the edge in turn; seen from the upper end this turns counterclockwise when
            // the other two axes and the edge's make a right-handed frame.
            let mut polygon: Vec<u32> = [0, 1, 3, 2]
                .iter()
                .map(|&k| vertex_of[loops.find(incidence[&pair(e.around[k], c as u32)]) as usize])
                .collect();
            polygon.dedup();
            if polygon.first() == polygon.last() {
                polygon.pop();
            }
            // Outward is towards the outside end; the polygon turns counterclockwise around +dir.
            let outward_up = self.inside(ends[0]);
            if outward_up != (e.dir != 1) {
                polygon.reverse();
            }
            triangulate(&polygon, &positions, &mut triangles);
        }
        let labels = sums
            .iter()
            .map(|&(_, _, leaf)| {
                let node = self.cells[leaf as usize].node;
                if node != NONE && self.tree.nodes[node as usize].kind == NodeKind::Transition {
                    node
                } else {
                    NONE
                }
            })
            .collect();
        (Contour { positions, triangles, labels }, sums.iter().map(|&(_, _, leaf)| leaf).collect())
    }

    /// The centre of the minimal face between leaves `a` and `b`: the smaller one's face.
    fn face_centre(&self, (a, b): (u32, u32)) -> Vec3 {
        let (small, large) = if self.cells[a as usize].level >= self.cells[b as usize].level { (a, b) } else { (b, a) };
        let (s, l) = (&self.cells[small as usize], &self.cells[large as usize]);
        let half = self.size(s.level) as f32 / 2.0;
        let centre = s.min.as_vec3() + half;
        let lc = l.min.as_vec3() + self.size(l.level) as f32 / 2.0;
        // Along the axis where the cells touch, the face lies on the small cell's side.
        let axis = (lc - centre).abs().max_position();
        let mut c = centre;
        c[axis] += half * (lc[axis] - centre[axis]).signum();
        self.origin + self.unit * c
    }

    /// Joins the crossings on the face between leaves `a` and `b` in pairs, each pair the ends
    /// of one stretch of the surface across the face. Where more than two cross, they are
    /// taken in turn around the face: an inside stretch of the boundary is cut off on its own
    /// unless the face's centre is inside, in which case the outside stretches are.
    fn pair_crossings(
        &self,
        a: u32,
        b: u32,
        crossings: &[u32],
        crossed: &[(usize, [u64; 2], Vec3)],
        centre_inside: Option<bool>,
    ) -> Vec<[u32; 2]> {
        if crossings.len() == 2 {
            return vec![[crossings[0], crossings[1]]];
        }
        let Some(centre_inside) = centre_inside else { return Vec::new() };
        let centre = (self.face_centre((a, b)) - self.origin) / self.unit;
        let axis = {
            let (ca, cb) = (self.cells[a as usize], self.cells[b as usize]);
            let mid = |c: Cell| c.min.as_vec3() + self.size(c.level) as f32 / 2.0;
            (mid(cb) - mid(ca)).abs().max_position()
        };
        let (u, v) = others(axis as u32);
        let flat = |p: Vec3| Vec2::new(p[u as usize] - centre[u as usize], p[v as usize] - centre[v as usize]);
        // Each crossing with its angle around the centre and whether the boundary, taken
        // counterclockwise, enters the inside there.
        let mut around: Vec<(f32, bool, u32)> = crossings
            .iter()
            .map(|&c| {
                let (_, ends, at) = crossed[c as usize];
                let [p0, p1] = ends.map(|k| flat(unkey(k).as_vec3()));
                let first_is_p0 = p0.perp_dot(p1) > 0.0;
                let later = if first_is_p0 { ends[1] } else { ends[0] };
                let at = flat((at - self.origin) / self.unit);
                (at.y.atan2(at.x), self.inside(later), c)
            })
            .collect();
        around.sort_by(|x, y| x.0.total_cmp(&y.0));
        // Start at a crossing that begins a stretch to cut off: into the inside, or out of it.
        let Some(start) = around.iter().position(|&(_, enters, _)| enters != centre_inside) else { return Vec::new() };
        around.rotate_left(start);
        around.chunks_exact(2).map(|pair| [pair[0].2, pair[1].2]).collect()
    }
}

/// Splits a polygon of three or four vertices into triangles, a quadrilateral along its
/// shorter diagonal.
fn triangulate(polygon: &[u32], positions: &[Vec3], triangles: &mut Vec<[u32; 3]>) {
    match *polygon {
        [a, b, c] => triangles.push([a, b, c]),
        [a, b, c, d] => {
            let p = |v: u32| positions[v as usize];
            if p(a).distance_squared(p(c)) <= p(b).distance_squared(p(d)) {
                triangles.extend([[a, b, c], [a, c, d]]);
            } else {
                triangles.extend([[a, b, d], [b, c, d]]);
            }
        }
        _ => {}
    }
}

/// The minimal faces and edges found by walking the octree.
#[derive(Default)]
struct Walk {
    edges: Vec<MinimalEdge>,
}

/// A minimal edge along axis `dir`, with the leaves around it (see [`Octree::edge_proc`]).
struct MinimalEdge {
    around: [u32; 4],
    dir: u32,
}

/// The two axes other than `axis`, in increasing order.
fn others(axis: u32) -> (u32, u32) {
    match axis {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    }
}

/// Two indices in one key.
fn pair(a: u32, b: u32) -> u64 {
    u64::from(a) << 32 | u64::from(b)
}

fn unpair(k: u64) -> (u32, u32) {
    ((k >> 32) as u32, k as u32)
}

fn key(p: UVec3) -> u64 {
    u64::from(p.x) | u64::from(p.y) << KEY_BITS | u64::from(p.z) << (2 * KEY_BITS)
}

fn unkey(k: u64) -> UVec3 {
    let mask = (1u64 << KEY_BITS) - 1;
    UVec3::new((k & mask) as u32, (k >> KEY_BITS & mask) as u32, (k >> (2 * KEY_BITS)) as u32)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::shapes;
    use crate::tree::{self, TreeParams};
    use crate::{Mesh, Progress, SampleSet};

    /// The field of an axis-aligned cube of side 1 (negative inside).
    fn cube(p: Vec3) -> f32 {
        p.abs().max_element() - 0.5
    }

    /// The tree of 50k samples on that cube.
    fn cube_tree(threads: &Threads) -> VsTree {
        let cloud =
            shapes::sample_surface(&shapes::implicit_mesh(cube, Vec3::splat(-1.0), Vec3::splat(1.0), 128), 50_000, 1);
        let samples = SampleSet::from_cloud(&cloud).unwrap();
        tree::build(&samples, &TreeParams::default(), threads, &mut Progress::none()).unwrap()
    }

    fn assert_closed_2_manifold(c: Contour) {
        let report = topology::analyze(&Mesh::new(c.positions, None, c.triangles));
        assert!(report.is_watertight() && report.non_manifold_vertices == 0, "{report:?}");
    }

    #[test]
    fn leaves_at_non_manifold_vertices_are_split_until_the_surface_is_a_2_manifold() {
        // A cube whose field wobbles by 3% of its side, as the winding number's side wobbles
        // near noisy or sharp samples: over the T-layer's leaves some vertices are non-manifold
        // (no result when no leaf may be split), and splitting those leaves repairs them.
        let wobble = |p: Vec3| cube(p) + 0.03 * (p.x * 91.0).sin() * (p.y * 77.0).sin() * (p.z * 83.0).sin();
        let threads = Threads::new(0).unwrap();
        let t = cube_tree(&threads);
        assert!(contour(&t, &wobble, &|_, _, _| false, 10.0, &threads).is_none(), "no split needed");
        assert_closed_2_manifold(contour(&t, &wobble, &|_, _, _| false, 1e-4, &threads).expect("repaired by splits"));
    }

    #[test]
    fn leaves_at_the_finest_level_are_split_further_where_still_not_a_2_manifold() {
        // A cube whose field wobbles faster (a sixth of the side a period) and no leaf to be
        // split below twice the smallest T-node: the wobble's sheets pass within those leaves,
        // and only the repair levels below them tell them apart (REPAIR_LEVELS 0 gives none).
        let wobble = |p: Vec3| cube(p) + 0.03 * (p.x * 136.5).sin() * (p.y * 115.5).sin() * (p.z * 124.5).sin();
        let threads = Threads::new(0).unwrap();
        let t = cube_tree(&threads);
        let smallest =
            t.nodes.iter().filter(|n| n.kind == NodeKind::Transition).map(|n| 2.0 * n.half).fold(f32::MAX, f32::min);
        let c = contour(&t, &wobble, &|_, _, _| false, 2.0 * smallest, &threads).expect("repaired below the finest");
        assert_closed_2_manifold(c);
    }
}
