//! Quadric edge collapse (Garland & Heckbert 1997) down to a triangle count, under the link
//! condition of [`crate::collapse`]: the cheapest edge goes first, its vertices merge at the
//! point that minimises their summed quadric, and a collapse that would change the topology or
//! fold a face over is skipped. The quadrics are the clusters' (their samples' tangent planes),
//! so the cost is the distance to the input surface, not to the clustered mesh. Borders shrink
//! by collapses along them that keep them manifold, with a plane through each border edge
//! across the surface added to its ends' quadrics (Garland & Heckbert's border constraint), so
//! a border keeps its course. Used after clustering, to bring a simplification to the exact
//! size asked for.

mod chunks;

use crate::chunks::SECOND_CUT;
use crate::collapse::Collapser;
use crate::error::Result;
use crate::linalg::Sym3;
use crate::mesh::Mesh;
use crate::progress::{Progress, Threads};
use crate::quad_heap::QuadHeap;
use crate::quadric::CellStats;
use chunks::{decimate_in_chunks, Near};
use glam::DVec3;
use rayon::prelude::*;
use std::cmp::Ordering;

/// A collapse is refused when it would turn one of the faces around it by more than the angle
/// with this cosine (unitless; 0 = a right angle): beyond that the face folds over its
/// neighbours, which a quadric cannot see because it only measures distances to planes.
const FOLD_COSINE: f64 = 0.0;

/// A collapse that removes a folded face (one facing against the samples at its corners, see
/// [`Decimator::is_folded`]) is queued at this fraction of its quadric error (unitless), so it
/// goes before unfolded ones up to a thousand times cheaper: clustering leaves faces folded
/// where neighbouring clusters' points crossed (slivers, creases, thin parts), and those that
/// survive the decimation are the output's spikes.
const FOLDED_FIRST: f64 = 1e-3;

/// The queue is cleared of stale candidates when it holds more than this many per triangle
/// left (unitless; a mesh has about 1.5 edges per triangle, so about twice the live ones).
const STALE_RATIO: usize = 3;

/// Where the grids of the chunked passes lie (a fraction of the mesh's box, see
/// [`crate::chunks::morton_chunks`]): the second pass, its seams elsewhere, takes what the
/// first left locked along its seams, in parallel too, so the serial pass has little left.
const CHUNK_SHIFTS: [f32; 2] = [0.0, SECOND_CUT];

/// A candidate collapse: `gone` merges into `keep`, for `cost`; `versions` are the two
/// vertices' versions when it was planned (stale once either changes). Where they meet is
/// worked out again when it is taken ([`Decimator::placement`], the same answer while the
/// versions hold), which keeps the heap's entries at 32 bytes instead of 56: the heap is most
/// of a decimation's memory traffic.
struct Candidate {
    cost: f64,
    gone: u32,
    keep: u32,
    versions: [u32; 2],
    /// Along a border edge.
    border: bool,
    /// Whether it was planned as edge gone-keep (else keep-gone): the placement's ties follow
    /// the order.
    gone_first: bool,
}

impl Candidate {
    /// Whether it was planned on the vertices as they are (`versions` per vertex).
    fn is_current(&self, versions: &[u32]) -> bool {
        versions[self.gone as usize] == self.versions[0] && versions[self.keep as usize] == self.versions[1]
    }
}

impl PartialEq for Candidate {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}
impl Eq for Candidate {}
impl PartialOrd for Candidate {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Candidate {
    /// Reversed, so the heap's top is the cheapest; ties by vertex indices, so the order is
    /// always the same.
    fn cmp(&self, other: &Self) -> Ordering {
        other.cost.total_cmp(&self.cost).then_with(|| (other.gone, other.keep).cmp(&(self.gone, self.keep)))
    }
}

/// Where a collapse puts its vertex, and what it costs.
struct Placement {
    gone: u32,
    keep: u32,
    position: DVec3,
    cost: f64,
    border: bool,
}

/// The state of a decimation.
struct Decimator {
    collapser: Collapser,
    /// Positions relative to the quadrics' origin.
    positions: Vec<DVec3>,
    quadrics: Vec<CellStats>,
    versions: Vec<u32>,
    heap: QuadHeap<Candidate>,
    /// Vertices no collapse may move or take (a chunk's seams).
    locked: Vec<bool>,
    /// Live triangles.
    faces: usize,
}

/// Collapses edges of `mesh` (proper triangles, every vertex used) until it has at most
/// `target + 1` triangles (an interior collapse removes two, a border one one), or no allowed
/// collapse is left.
/// `quadrics[v]` is vertex v's quadric, over positions relative to `origin` (in the mesh's
/// frame). A large mesh is first brought near the target in chunks, in parallel
/// ([`decimate_in_chunks`]), twice. Returns the mesh, with the input's winding, and the input vertex
/// each output vertex is.
pub(crate) fn decimate(
    mesh: &Mesh,
    mut quadrics: Vec<CellStats>,
    origin: DVec3,
    target: usize,
    threads: &Threads,
    progress: &mut Progress,
) -> Result<(Mesh, Vec<u32>)> {
    debug_assert_eq!(quadrics.len(), mesh.positions.len());
    let positions: Vec<DVec3> = mesh.positions.iter().map(|p| p.as_dvec3() - origin).collect();
    add_border_planes(mesh, &positions, &mut quadrics);
    let mut near = Near { mesh: mesh.clone(), positions, quadrics, from: (0..mesh.positions.len() as u32).collect() };
    for (pass, shift) in CHUNK_SHIFTS.into_iter().enumerate() {
        let passes = CHUNK_SHIFTS.len() as f32 + 1.0;
        let mut stage = progress.stage(pass as f32 / passes, (pass + 1) as f32 / passes);
        if let Some(next) = decimate_in_chunks(&near, target, shift, threads, &mut stage)? {
            near = next;
        }
    }
    let Near { mesh: near, positions, quadrics, from } = near;
    let mut d = Decimator::new(&near, positions, quadrics, None);
    d.run(target);
    let identity: Vec<u32> = (0..near.positions.len() as u32).collect();
    let (mut out, kept) = d.collapser.finish(&identity);
    for (p, &v) in out.positions.iter_mut().zip(&kept) {
        *p = (d.positions[v as usize] + origin).as_vec3();
    }
    Ok((out, kept.iter().map(|&v| from[v as usize]).collect()))
}

/// Whether a face's `normal` points against each of its corners' `sample_normals`.
fn faces_against(normal: DVec3, sample_normals: [DVec3; 3]) -> bool {
    sample_normals.iter().all(|n| normal.dot(*n) < 0.0)
}

/// Adds to the quadric of each border edge's ends the plane through the edge across its
/// face, weighted like one vertex's samples (the mean count of samples per vertex), so a
/// border that moves costs as much as a surface that does.
fn add_border_planes(mesh: &Mesh, positions: &[DVec3], quadrics: &mut [CellStats]) {
    let n = quadrics.len().max(1) as f64;
    let weight = quadrics.iter().map(|q| q.count as f64).sum::<f64>() / n;
    let mut edges: Vec<((u32, u32), u32)> = Vec::new();
    for (t, tri) in mesh.triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            edges.push(((a.min(b), a.max(b)), t as u32));
        }
    }
    edges.par_sort_unstable();
    for (i, &((a, b), t)) in edges.iter().enumerate() {
        let alone = (i == 0 || edges[i - 1].0 != (a, b)) && edges.get(i + 1).is_none_or(|e| e.0 != (a, b));
        if !alone {
            continue;
        }
        let [x, y, z] = mesh.triangles[t as usize].map(|v| positions[v as usize]);
        let normal = (y - x).cross(z - x);
        let (pa, pb) = (positions[a as usize], positions[b as usize]);
        let across = (pb - pa).cross(normal).normalize_or_zero();
        if across == DVec3::ZERO {
            continue;
        }
        let d = across.dot(pa);
        for v in [a, b] {
            let q = &mut quadrics[v as usize];
            q.nn.add(&Sym3::outer(across).scaled(weight));
            q.b += across * (d * weight);
            q.c += d * d * weight;
        }
    }
}

impl Decimator {
    /// A decimation of `mesh` (proper triangles) with its vertices' `positions` and
    /// `quadrics`, the `locked` ones fixed; vertices no triangle uses are left out.
    fn new(mesh: &Mesh, positions: Vec<DVec3>, quadrics: Vec<CellStats>, locked: Option<Vec<bool>>) -> Decimator {
        let n = mesh.positions.len();
        let mut d = Decimator {
            collapser: Collapser::new(mesh),
            positions,
            quadrics,
            versions: vec![0; n],
            heap: QuadHeap::new(),
            locked: locked.unwrap_or_else(|| vec![false; n]),
            faces: mesh.triangles.len(),
        };
        let mut used = vec![false; n];
        for &v in mesh.triangles.iter().flatten() {
            used[v as usize] = true;
        }
        for (v, _) in used.iter().enumerate().filter(|(_, &u)| !u) {
            d.collapser.remove_vertex(v);
        }
        d
    }

    /// Takes the cheapest allowed collapse while more than `target + 1` triangles are left.
    fn run(&mut self, target: usize) {
        while self.faces >= target + 2 {
            self.seed();
            let before = self.faces;
            while self.faces >= target + 2 {
                let Some(c) = self.next() else { break };
                self.take(c);
            }
            if self.faces == before {
                break; // a whole pass over every edge found nothing to collapse
            }
        }
    }

    /// The cheapest candidate, off the queue (stale ones are dropped now and then).
    fn next(&mut self) -> Option<Candidate> {
        self.drop_stale(self.faces);
        self.heap.pop()
    }

    /// Takes collapse `c` if it still holds (its vertices unchanged since it was planned) and
    /// is allowed (topology, folds); whether it did.
    fn take(&mut self, c: Candidate) -> bool {
        if !c.is_current(&self.versions) {
            return false;
        }
        let allowed = if c.border {
            self.collapser.can_collapse_border(c.gone, c.keep)
        } else {
            self.collapser.can_collapse(c.gone, c.keep)
        };
        let (u, v) = if c.gone_first { (c.gone, c.keep) } else { (c.keep, c.gone) };
        let Some(Placement { position, .. }) = self.placement(u, v) else { return false };
        if !allowed || self.folds(c.gone, c.keep, position) {
            return false;
        }
        self.faces -= if c.border { 1 } else { 2 };
        self.apply(&c, position);
        true
    }

    /// Fills the heap with every live edge (once each).
    fn seed(&mut self) {
        self.heap.clear();
        let mut edges: Vec<(u32, u32)> = Vec::new();
        for v in 0..self.positions.len() as u32 {
            if !self.collapser.is_alive(v) {
                continue;
            }
            for t in self.collapser.faces_around(v) {
                edges.extend(t.iter().filter(|&&w| w > v).map(|&w| (v, w)));
            }
        }
        edges.sort_unstable();
        edges.dedup();
        for (u, v) in edges {
            self.plan(u, v);
        }
    }

    /// Queues the best collapse of edge u-v, if one is allowed: a border vertex stays where
    /// it is (so borders keep their shape), along a border the cheaper end stays; otherwise
    /// the merged quadric's minimiser (the middle where it has none) or either end, whichever
    /// costs least (Garland & Heckbert's choice).
    fn plan(&mut self, u: u32, v: u32) {
        let Some(Placement { gone, keep, position: _, cost, border }) = self.placement(u, v) else { return };
        let versions = [self.versions[gone as usize], self.versions[keep as usize]];
        self.heap.push(Candidate { cost, gone, keep, versions, border, gone_first: gone == u });
    }

    /// The collapse [`Decimator::plan`] queues for edge u-v: which end goes, where they meet,
    /// at what cost; `None` when it is not allowed.
    fn placement(&self, u: u32, v: u32) -> Option<Placement> {
        if self.locked[u as usize] || self.locked[v as usize] {
            return None;
        }
        let (bu, bv) = (self.collapser.is_border(u), self.collapser.is_border(v));
        let border = bu && bv;
        if border && self.collapser.edge_faces(u, v) != 1 {
            return None; // an interior edge between border vertices: it would pinch the border
        }
        let mut q = self.quadrics[u as usize];
        q.merge(&self.quadrics[v as usize]);
        let (pu, pv) = (self.positions[u as usize], self.positions[v as usize]);
        let (gone, keep, position) = if border {
            if q.quadric_at(pu) <= q.quadric_at(pv) {
                (v, u, pu)
            } else {
                (u, v, pv)
            }
        } else if bu {
            (v, u, pu)
        } else if bv {
            (u, v, pv)
        } else {
            // Where the quadric pins no single point (flat or creased), the middle or an end.
            let x = q.quadric_minimizer_if_regular().unwrap_or(0.5 * (pu + pv));
            let best = [x, pu, pv].into_iter().min_by(|a, b| q.quadric_at(*a).total_cmp(&q.quadric_at(*b)));
            (u.max(v), u.min(v), best.unwrap_or(x))
        };
        let cost = q.quadric_at(position);
        let folded = self.collapser.faces_around(u).any(|t| t.contains(&v) && self.is_folded(&t));
        Some(Placement { gone, keep, position, cost: if folded { FOLDED_FIRST * cost } else { cost }, border })
    }

    /// Whether face `t` is folded: it faces against the samples' normals at each of its
    /// corners (their sums in the quadrics). Every corner must agree, so a face across a thin
    /// part, whose corners' samples face opposite ways, is not folded.
    fn is_folded(&self, t: &[u32; 3]) -> bool {
        let [a, b, c] = t.map(|v| self.positions[v as usize]);
        faces_against((b - a).cross(c - a), t.map(|v| self.quadrics[v as usize].sum_n))
    }

    /// Whether moving the ends of edge gone-keep to `position` would turn a surviving face by
    /// more than [`FOLD_COSINE`] allows (or make it degenerate), unless the turn unfolds it:
    /// the face faced against the surface and no longer does.
    fn folds(&self, gone: u32, keep: u32, position: DVec3) -> bool {
        let p = |v: u32| if v == gone || v == keep { position } else { self.positions[v as usize] };
        let old = |v: u32| self.positions[v as usize];
        for x in [gone, keep] {
            let other = if x == gone { keep } else { gone };
            for t in self.collapser.faces_around(x) {
                if t.contains(&other) {
                    continue; // dies with the edge
                }
                let before = (old(t[1]) - old(t[0])).cross(old(t[2]) - old(t[0]));
                let after = (p(t[1]) - p(t[0])).cross(p(t[2]) - p(t[0]));
                let scale = before.length() * after.length();
                if scale == 0.0 {
                    return true;
                }
                if before.dot(after) <= FOLD_COSINE * scale {
                    let mut sample_normals = t.map(|v| self.quadrics[v as usize].sum_n);
                    let folded = faces_against(before, sample_normals);
                    // The merged vertex has both ends' samples.
                    let k = t.iter().position(|&v| v == x).unwrap_or(0);
                    sample_normals[k] += self.quadrics[other as usize].sum_n;
                    if !folded || faces_against(after, sample_normals) {
                        return true;
                    }
                }
            }
        }
        false
    }

    /// Drops the candidates made stale by collapses once they outnumber the live edges of a mesh
    /// of `faces` triangles (about 1.5 per triangle): each would cost a pop, and most get
    /// popped, since a collapse raises its neighbours' costs and the stale entries keep the
    /// old, lower ones. The pops that remain come in the same order.
    fn drop_stale(&mut self, faces: usize) {
        if self.heap.len() > STALE_RATIO * faces {
            let versions = &self.versions;
            self.heap.retain(|c| c.is_current(versions));
        }
    }

    fn apply(&mut self, c: &Candidate, position: DVec3) {
        let q = self.quadrics[c.gone as usize];
        self.quadrics[c.keep as usize].merge(&q);
        self.positions[c.keep as usize] = position;
        self.versions[c.gone as usize] += 1;
        self.versions[c.keep as usize] += 1;
        self.collapser.merge(c.gone, c.keep);
        let mut around: Vec<u32> =
            self.collapser.faces_around(c.keep).flat_map(|t| t.into_iter()).filter(|&w| w != c.keep).collect();
        around.sort_unstable();
        around.dedup();
        for w in around {
            self.plan(c.keep, w);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::shapes;
    use crate::topology::analyze;

    fn serial() -> Threads {
        Threads::new(1).unwrap()
    }

    /// Each vertex's quadric: the planes of its faces (unit normals, as samples would give).
    pub(super) fn face_quadrics(mesh: &Mesh) -> Vec<CellStats> {
        let mut q = vec![CellStats::default(); mesh.positions.len()];
        for t in &mesh.triangles {
            let [a, b, c] = t.map(|v| mesh.positions[v as usize].as_dvec3());
            let n = (b - a).cross(c - a).normalize();
            for &v in t {
                q[v as usize].add(mesh.positions[v as usize].as_dvec3(), n);
            }
        }
        q
    }

    #[test]
    fn reaches_the_count_and_keeps_the_genus() {
        for (mesh, genus) in [(shapes::icosphere(1.0, 4), 0), (shapes::torus(1.0, 0.3, 64, 32), 1)] {
            for target in [2000, 500, 100] {
                let (out, kept) =
                    decimate(&mesh, face_quadrics(&mesh), DVec3::ZERO, target, &serial(), &mut Progress::none())
                        .unwrap();
                let r = analyze(&out);
                assert!(r.is_watertight(), "{r:?}");
                assert_eq!(r.genus(), Some(genus));
                assert!(out.triangles.len().abs_diff(target) <= 1, "{} for {target}", out.triangles.len());
                assert_eq!(kept.len(), out.positions.len());
            }
        }
    }

    #[test]
    fn a_sphere_stays_round_and_stops_at_a_tetrahedron() {
        let mesh = shapes::icosphere(1.0, 4);
        let (out, _) =
            decimate(&mesh, face_quadrics(&mesh), DVec3::ZERO, 200, &serial(), &mut Progress::none()).unwrap();
        for p in &out.positions {
            assert!((p.length() - 1.0).abs() < 0.1, "{p}");
        }
        let (tiny, _) =
            decimate(&mesh, face_quadrics(&mesh), DVec3::ZERO, 0, &serial(), &mut Progress::none()).unwrap();
        assert_eq!(tiny.triangles.len(), 4);
        assert!(analyze(&tiny).is_watertight());
    }

    #[test]
    fn an_open_cap_shrinks_along_its_border_which_stays_manifold() {
        let sphere = shapes::icosphere(1.0, 4);
        let low = |t: &&[u32; 3]| t.iter().all(|&v| sphere.positions[v as usize].z < 0.3);
        let triangles: Vec<[u32; 3]> = sphere.triangles.iter().filter(low).copied().collect();
        let open = Mesh::new(sphere.positions.clone(), None, triangles);
        let before = analyze(&open);
        for target in [300, 60, 10] {
            let (out, _) =
                decimate(&open, face_quadrics(&open), DVec3::ZERO, target, &serial(), &mut Progress::none()).unwrap();
            let r = analyze(&out);
            assert!(out.triangles.len().abs_diff(target) <= 1, "{} for {target}", out.triangles.len());
            assert_eq!((r.non_manifold_edges, r.non_manifold_vertices, r.components), (0, 0, 1), "{r:?}");
            assert_eq!(r.euler_characteristic, before.euler_characteristic, "a disk stays a disk");
            assert!(r.boundary_edges >= 3 && r.boundary_edges < before.boundary_edges);
        }
    }

    #[test]
    fn stale_candidates_are_dropped_once_they_crowd_the_queue() {
        let mesh = shapes::icosphere(1.0, 2);
        let positions = mesh.positions.iter().map(|p| p.as_dvec3()).collect();
        let mut d = Decimator::new(&mesh, positions, face_quadrics(&mesh), None);
        d.seed();
        let edges = d.heap.len();
        assert_eq!(edges, 3 * mesh.triangles.len() / 2);
        // Under the ratio nothing is dropped; above it, every candidate of a changed vertex.
        d.versions[0] += 1;
        d.drop_stale(mesh.triangles.len());
        assert_eq!(d.heap.len(), edges);
        d.drop_stale(edges / STALE_RATIO - 1);
        assert_eq!(d.heap.len(), edges - 5, "vertex 0 of an icosphere has 5 edges");
        while let Some(c) = d.heap.pop() {
            assert!(c.gone != 0 && c.keep != 0);
        }
    }

    #[test]
    fn a_collapse_that_folds_a_face_is_refused() {
        // A flat fan of four faces around vertex 0. Merging 0 and 2 kills faces 0-1-2 and 0-2-3
        // and moves 0 in the other two.
        assert_eq!(FOLD_COSINE, 0.0);
        let positions = vec![
            glam::Vec3::new(0.0, 0.0, 0.0),
            glam::Vec3::new(1.0, 0.0, 0.0),
            glam::Vec3::new(0.0, 1.0, 0.0),
            glam::Vec3::new(-1.0, 0.0, 0.0),
            glam::Vec3::new(0.0, -1.0, 0.0),
        ];
        let triangles = vec![[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 1]];
        let mesh = Mesh::new(positions, None, triangles);
        let positions = mesh.positions.iter().map(|p| p.as_dvec3()).collect();
        let d = Decimator::new(&mesh, positions, face_quadrics(&mesh), None);
        // Inside the fan nothing turns; past vertex 4 faces 0-3-4 and 0-4-1 turn over.
        assert!(!d.folds(2, 0, DVec3::new(0.0, 0.5, 0.0)));
        assert!(d.folds(2, 0, DVec3::new(0.0, -2.0, 0.0)));
        // Lifted 10 above the plane, the faces turn by 86° (cosine 1/sqrt(201)): allowed, as
        // anything short of a right angle is; onto the line 3-4, face 0-3-4 is degenerate.
        assert!(!d.folds(2, 0, DVec3::new(0.0, 0.0, 10.0)));
        assert!(d.folds(2, 0, DVec3::new(-0.5, -0.5, 0.0)));
    }

    #[test]
    fn a_folded_face_may_turn_back_and_its_collapses_go_first() {
        // The fan of the test above raised to a pyramid, its samples facing up and out; then
        // vertex 0 pushed past edge 1-2, so that face 0-1-2 faces down.
        let fan = |centre: glam::Vec3| {
            let ring = [(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)].map(|(x, y)| glam::Vec3::new(x, y, 0.0));
            Mesh::new([&[centre][..], &ring].concat(), None, vec![[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 1]])
        };
        let quadrics = face_quadrics(&fan(glam::Vec3::new(0.0, 0.0, 0.5)));
        let mesh = fan(glam::Vec3::new(0.8, 0.8, 0.5));
        let positions = mesh.positions.iter().map(|p| p.as_dvec3()).collect();
        let d = Decimator::new(&mesh, positions, quadrics, None);
        assert!(d.is_folded(&[0, 1, 2]) && !d.is_folded(&[0, 2, 3]));
        // Merging 0 and 3 at the apex turns 0-1-2 back up, by more than a right angle: allowed.
        assert!(!d.folds(0, 3, DVec3::new(0.0, 0.0, 0.5)));
        // Collapses along the folded face's edges come at a thousandth of their error.
        let error = |u: u32, v: u32| {
            let mut q = d.quadrics[u as usize];
            q.merge(&d.quadrics[v as usize]);
            q.quadric_at(d.placement(u, v).unwrap().position)
        };
        for (u, v) in [(0, 1), (1, 2), (0, 2)] {
            assert!(error(u, v) > 1e-3);
            assert_eq!(d.placement(u, v).unwrap().cost, FOLDED_FIRST * error(u, v));
        }
        assert!(error(0, 3) > 1e-3);
        assert_eq!(d.placement(0, 3).unwrap().cost, error(0, 3));
    }
}
