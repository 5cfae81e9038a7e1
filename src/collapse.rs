//! Topology-preserving clustering of a triangle mesh: every edge whose ends share a label is
//! collapsed while the link condition (Dey et al. 1999) allows: the neighbours common to both
//! ends must be exactly the two corners opposite the edge. Such a collapse never changes the
//! topology of a 2-manifold, so the result keeps the input's genus and stays closed where it
//! was closed; where the link condition blocks the last collapses of a cluster (a cluster
//! wrapped around a handle), the cluster keeps a few vertices. On an open mesh, border edges
//! collapse along the border under the same condition (the border coned to a dummy vertex);
//! interior edges joining two border vertices never collapse (that would pinch the border).
//! Used for the reconstruction's base mesh and for simplification that keeps topology.

use crate::mesh::Mesh;
use glam::DVec3;

/// Ends a corner list of [`Collapser`].
const NO_CORNER: u32 = u32::MAX;

/// A triangle mesh under edge collapses: faces die, vertices merge into survivors.
pub(crate) struct Collapser {
    triangles: Vec<[u32; 3]>,
    alive_face: Vec<bool>,
    /// The corners around each vertex, as linked lists: corner `3 t + k` is corner k of
    /// triangle t; `head[v]` is v's first, `next[c]` the one after c ([`NO_CORNER`] ends a
    /// list). Corners of dead faces are dropped lazily. Two flat arrays rather than a `Vec`
    /// per vertex: a fraction of the memory on millions of vertices.
    head: Vec<u32>,
    next: Vec<u32>,
    alive_vertex: Vec<bool>,
    sum: Vec<DVec3>,
    count: Vec<u32>,
    /// Scratch marks of the link test: a vertex marked `stamp` is in the first ring, one
    /// marked `stamp + 1` has been seen in the second. Older marks mean "not seen".
    mark: Vec<u32>,
    stamp: u32,
    /// Vertices on a border (an edge with one face), which keep their border manifold.
    border: Vec<bool>,
    /// Vertices that may be on an edge with more than two faces (a superset: a vertex merged
    /// into another passes its flag on); see [`Collapser::holds_non_manifold_edge`].
    non_manifold: Vec<bool>,
    /// With [`Collapser::limit_border_runs`]: the longest box diagonal of the border
    /// vertices one border vertex may absorb, and per vertex the box (low, high corners) of
    /// those it has.
    border_runs: Option<(f64, Vec<[DVec3; 2]>)>,
}

impl Collapser {
    pub(crate) fn new(mesh: &Mesh) -> Collapser {
        let mut head = vec![NO_CORNER; mesh.positions.len()];
        let mut next = vec![NO_CORNER; 3 * mesh.triangles.len()];
        for (t, tri) in mesh.triangles.iter().enumerate() {
            for (k, &v) in tri.iter().enumerate() {
                next[3 * t + k] = head[v as usize];
                head[v as usize] = (3 * t + k) as u32;
            }
        }
        let (border, non_manifold) = edge_vertices(mesh, &head, &next);
        Collapser {
            triangles: mesh.triangles.clone(),
            alive_face: vec![true; mesh.triangles.len()],
            head,
            next,
            alive_vertex: vec![true; mesh.positions.len()],
            sum: mesh.positions.iter().map(|p| p.as_dvec3()).collect(),
            count: vec![1; mesh.positions.len()],
            mark: vec![0; mesh.positions.len()],
            stamp: 1,
            border,
            non_manifold,
            border_runs: None,
        }
    }

    /// From now on, border vertices merge along the border only while the border vertices
    /// merged lie in a box whose diagonal is at most `length`. A border vertex sits at the mean
    /// of those it absorbed, so a long run of border cut short to one vertex cuts off the
    /// surface beside the run's bends; bounding the runs keeps the border within about
    /// `length` of where it was, however large the clusters are inside.
    pub(crate) fn limit_border_runs(&mut self, length: f32) {
        let boxes = self.sum.iter().map(|&p| [p, p]).collect();
        self.border_runs = Some((f64::from(length), boxes));
    }

    /// Whether [`Collapser::limit_border_runs`] lets border vertices `u` and `v` merge.
    fn border_run_fits(&self, u: u32, v: u32) -> bool {
        let Some((length, boxes)) = &self.border_runs else { return true };
        let ([lu, hu], [lv, hv]) = (boxes[u as usize], boxes[v as usize]);
        (hu.max(hv) - lu.min(lv)).length() <= *length
    }

    /// Takes face `t` out, with its three corners' vertices.
    pub(crate) fn remove_face_and_corners(&mut self, t: usize) {
        self.alive_face[t] = false;
        for v in self.triangles[t] {
            self.alive_vertex[v as usize] = false;
        }
    }

    /// Takes vertex `v` out (one that no face uses, which would otherwise survive alone).
    pub(crate) fn remove_vertex(&mut self, v: usize) {
        self.alive_vertex[v] = false;
    }

    /// Collapses every edge whose ends share a label, while the link condition allows. In
    /// rounds, each vertex in at most one collapse per round (a greedy matching), so clusters
    /// shrink evenly and rings stay small; merging everything into one growing vertex instead
    /// makes every link test cost the cluster's whole perimeter. On an open mesh, border edges
    /// go first: a cluster's stretch of border shrinks to one vertex before its inside merges
    /// into it, or else an inside vertex merged into two border vertices leaves an edge
    /// between them across the inside, which no collapse may then take (it would pinch the
    /// border).
    pub(crate) fn collapse_within(&mut self, labels: &[u32]) {
        if self.has_border() {
            self.collapse_rounds(labels, true);
        }
        self.collapse_rounds(labels, false);
    }

    /// [`Collapser::collapse_within`]'s rounds, over border edges only or over every edge.
    fn collapse_rounds(&mut self, labels: &[u32], border_only: bool) {
        let same_label = |t: &[u32; 3]| (0..3).any(|k| labels[t[k] as usize] == labels[t[(k + 1) % 3] as usize]);
        let mut candidates: Vec<u32> = (0..self.triangles.len() as u32)
            .filter(|&t| self.alive_face[t as usize] && same_label(&self.triangles[t as usize]))
            .collect();
        if border_only {
            candidates
                .retain(|&t| self.triangles[t as usize].iter().filter(|&&v| self.border[v as usize]).count() >= 2);
        }
        let mut touched = vec![false; self.alive_vertex.len()];
        loop {
            let mut collapsed = 0usize;
            touched.fill(false);
            for &t in &candidates {
                for k in 0..3 {
                    if !self.alive_face[t as usize] {
                        break;
                    }
                    let tri = self.triangles[t as usize];
                    let (u, v) = (tri[k], tri[(k + 1) % 3]);
                    if labels[u as usize] == labels[v as usize]
                        && !touched[u as usize]
                        && !touched[v as usize]
                        && (!border_only
                            || self.border[u as usize] && self.border[v as usize] && self.border_run_fits(u, v))
                        && (self.try_collapse(u.max(v), u.min(v)) || border_only && self.cut_ear(u, v))
                    {
                        touched[u as usize] = true;
                        touched[v as usize] = true;
                        collapsed += 1;
                    }
                }
            }
            if collapsed == 0 {
                break;
            }
            candidates.retain(|&t| self.alive_face[t as usize] && same_label(&self.triangles[t as usize]));
        }
    }

    /// Where `u` and `v` are border vertices joined by an inside edge, one of whose faces is
    /// an ear (its third corner has no other face: the border runs u, tip, v), takes the ear
    /// off: the border then runs along u-v, which can collapse. A disk stays a disk. The tip
    /// is of another label (or its border edge to `u` or `v` would have collapsed), and the
    /// ear is what keeps `u` and `v`'s stretch of border from shrinking to one vertex.
    fn cut_ear(&mut self, u: u32, v: u32) -> bool {
        if !self.border[u as usize] || !self.border[v as usize] {
            return false;
        }
        let ear = self.faces(u).find(|&f| {
            let t = self.triangles[f as usize];
            t.contains(&v) && t.iter().any(|&w| w != u && w != v && self.faces(w).count() == 1)
        });
        let Some(f) = ear else { return false };
        if self.holds_non_manifold_edge(f) {
            return false;
        }
        let tip = self.triangles[f as usize].into_iter().find(|&w| w != u && w != v).unwrap_or(u);
        self.alive_face[f as usize] = false;
        self.alive_vertex[tip as usize] = false;
        true
    }

    /// The corners around `v`, dead faces' included.
    fn corners(&self, v: u32) -> impl Iterator<Item = u32> + '_ {
        let mut c = self.head[v as usize];
        std::iter::from_fn(move || {
            (c != NO_CORNER).then(|| {
                let this = c;
                c = self.next[c as usize];
                this
            })
        })
    }

    /// The live faces around `v`.
    fn faces(&self, v: u32) -> impl Iterator<Item = u32> + '_ {
        self.corners(v).map(|c| c / 3).filter(|&f| self.alive_face[f as usize])
    }

    /// The link test of edge u-v, with marks instead of sorted rings: the sizes of the two
    /// rings (the other vertices of the live faces around `u`, and around `v`) and how many
    /// vertices they share.
    fn rings_and_common(&mut self, u: u32, v: u32) -> (usize, usize, usize) {
        if self.stamp >= u32::MAX - 2 {
            self.mark.fill(0);
            self.stamp = 1;
        }
        self.stamp += 2;
        let (first, seen) = (self.stamp, self.stamp + 1);
        let mut mark = std::mem::take(&mut self.mark);
        let mut ring_u = 0;
        for f in self.faces(u) {
            for w in self.triangles[f as usize] {
                if w != u && mark[w as usize] != first {
                    mark[w as usize] = first;
                    ring_u += 1;
                }
            }
        }
        let (mut ring_v, mut common) = (0, 0);
        for f in self.faces(v) {
            for w in self.triangles[f as usize] {
                let m = &mut mark[w as usize];
                if w == v || *m == seen {
                    continue;
                }
                common += usize::from(*m == first);
                ring_v += 1;
                *m = seen;
            }
        }
        self.mark = mark;
        (ring_u, ring_v, common)
    }

    /// Merges `u` into `v` if the edge exists and the link condition holds.
    fn try_collapse(&mut self, u: u32, v: u32) -> bool {
        if self.border[u as usize] && self.border[v as usize] && !self.border_run_fits(u, v) {
            return false;
        }
        let ok = if self.edge_faces(u, v) == 1 { self.can_collapse_border(u, v) } else { self.can_collapse(u, v) };
        if ok {
            self.merge(u, v);
        }
        ok
    }

    /// Whether merging `u` into `v` keeps the topology: both alive, the edge shared by exactly
    /// two faces, not an interior edge between border vertices, the link condition, and no
    /// closed component shrunk below a tetrahedron.
    pub(crate) fn can_collapse(&mut self, u: u32, v: u32) -> bool {
        if u == v || !self.alive_vertex[u as usize] || !self.alive_vertex[v as usize] {
            return false;
        }
        let mut shared_count = 0;
        for f in self.faces(u) {
            if self.triangles[f as usize].contains(&v) {
                if shared_count == 2 {
                    return false; // more than two faces on the edge: not a manifold edge
                }
                if self.holds_non_manifold_edge(f) {
                    return false;
                }
                shared_count += 1;
            }
        }
        if shared_count != 2 {
            return false; // a border or non-manifold edge (or no edge at all)
        }
        if self.border[u as usize] && self.border[v as usize] {
            return false; // an interior edge between two border vertices: would pinch the border
        }
        let (ring_u, ring_v, common) = self.rings_and_common(u, v);
        // Link condition; and never shrink a closed component below a tetrahedron.
        common == 2 && ring_u + ring_v > 6
    }

    /// Whether merging border vertex `u` into border vertex `v` along their border edge (one
    /// face) keeps the border manifold: the link condition with the border coned to a virtual
    /// vertex, i.e. the face's third vertex `w` is the only neighbour they share, and `w` is
    /// not joined to both by border edges (a border loop of three edges, which would shrink
    /// to two).
    pub(crate) fn can_collapse_border(&mut self, u: u32, v: u32) -> bool {
        if u == v || !self.alive_vertex[u as usize] || !self.alive_vertex[v as usize] {
            return false;
        }
        let mut shared = None;
        for f in self.faces(u) {
            if self.triangles[f as usize].contains(&v) {
                if shared.is_some() {
                    return false; // an interior edge
                }
                shared = Some(f);
            }
        }
        let Some(f) = shared else { return false };
        if self.holds_non_manifold_edge(f) {
            return false;
        }
        let t = self.triangles[f as usize];
        let w = t.into_iter().find(|&x| x != u && x != v).unwrap_or(u);
        if self.border[w as usize] && self.edge_faces(u, w) == 1 && self.edge_faces(v, w) == 1 {
            return false;
        }
        let (_, _, common) = self.rings_and_common(u, v);
        common == 1
    }

    /// Whether face `f` has an edge with more than two faces. Such a face never dies: the link
    /// condition assumes a manifold, and where sheets meet at an edge (a flap on a closed
    /// surface) a collapse that takes the flap's last face off the edge leaves it manifold and
    /// the flap, with its border, gone.
    fn holds_non_manifold_edge(&self, f: u32) -> bool {
        let t = self.triangles[f as usize];
        (0..3).any(|k| {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            self.non_manifold[a as usize] && self.non_manifold[b as usize] && self.edge_faces(a, b) > 2
        })
    }

    /// The live faces on edge u-v.
    pub(crate) fn edge_faces(&self, u: u32, v: u32) -> usize {
        self.faces(u).filter(|&f| self.triangles[f as usize].contains(&v)).count()
    }

    /// Merges `u` into `v` along their edge, which [`Collapser::can_collapse`] (or
    /// [`Collapser::can_collapse_border`]) has accepted: the edge's faces die, `u`'s faces move
    /// to `v`.
    pub(crate) fn merge(&mut self, u: u32, v: u32) {
        let mut c = self.head[u as usize];
        while c != NO_CORNER {
            let f = (c / 3) as usize;
            if self.alive_face[f] && self.triangles[f].contains(&v) {
                self.alive_face[f] = false;
            }
            c = self.next[c as usize];
        }
        // v's new list: its own live corners, then u's, now v's.
        let mut list = NO_CORNER;
        for x in [v, u] {
            let mut c = self.head[x as usize];
            while c != NO_CORNER {
                let after = self.next[c as usize];
                let (f, k) = ((c / 3) as usize, (c % 3) as usize);
                if self.alive_face[f] {
                    self.triangles[f][k] = v;
                    self.next[c as usize] = list;
                    list = c;
                }
                c = after;
            }
        }
        self.head[v as usize] = list;
        self.head[u as usize] = NO_CORNER;
        self.alive_vertex[u as usize] = false;
        self.non_manifold[v as usize] |= self.non_manifold[u as usize];
        // A border vertex stays at the mean of the border vertices it absorbed, so the
        // border keeps its place.
        let (u, v) = (u as usize, v as usize);
        match (self.border[u], self.border[v]) {
            (false, true) => {}
            (true, false) => {
                (self.sum[v], self.count[v]) = (self.sum[u], self.count[u]);
                if let Some((_, boxes)) = &mut self.border_runs {
                    boxes[v] = boxes[u];
                }
            }
            _ => {
                let (sum, count) = (self.sum[u], self.count[u]);
                self.sum[v] += sum;
                self.count[v] += count;
                if let Some((_, boxes)) = &mut self.border_runs {
                    let ([lu, hu], [lv, hv]) = (boxes[u], boxes[v]);
                    boxes[v] = [lu.min(lv), hu.max(hv)];
                }
            }
        }
        self.border[v] |= self.border[u];
    }

    /// Whether `v` is alive (not merged into another vertex, not removed).
    pub(crate) fn is_alive(&self, v: u32) -> bool {
        self.alive_vertex[v as usize]
    }

    /// Whether any vertex is on a border.
    pub(crate) fn has_border(&self) -> bool {
        self.border.iter().any(|&b| b)
    }

    /// Whether `v` is on a border (or has absorbed a border vertex).
    pub(crate) fn is_border(&self, v: u32) -> bool {
        self.border[v as usize]
    }

    /// The live faces around `v`, as vertex triples.
    pub(crate) fn faces_around(&self, v: u32) -> impl Iterator<Item = [u32; 3]> + '_ {
        self.faces(v).map(|f| self.triangles[f as usize])
    }

    /// The live faces, in their order, with the vertices' own numbers.
    pub(crate) fn live_triangles(&self) -> Vec<[u32; 3]> {
        self.triangles.iter().zip(&self.alive_face).filter(|(_, &alive)| alive).map(|(t, _)| *t).collect()
    }

    /// The mesh of the surviving vertices, each at the mean of the vertices it absorbed, and
    /// the survivors' labels.
    pub(crate) fn finish(self, labels: &[u32]) -> (Mesh, Vec<u32>) {
        let mut index = vec![u32::MAX; self.alive_vertex.len()];
        let mut positions = Vec::new();
        let mut out_labels = Vec::new();
        for (v, _) in self.alive_vertex.iter().enumerate().filter(|(_, &a)| a) {
            index[v] = positions.len() as u32;
            positions.push((self.sum[v] / f64::from(self.count[v])).as_vec3());
            out_labels.push(labels[v]);
        }
        let triangles = self
            .triangles
            .iter()
            .zip(&self.alive_face)
            .filter(|(_, &alive)| alive)
            .map(|(t, _)| t.map(|v| index[v as usize]))
            .collect();
        (Mesh::new(positions, None, triangles), out_labels)
    }
}

/// The vertices on an edge that only one face has (the border), and those on an edge that
/// more than two faces have, from the corner lists `head`/`next` of [`Collapser`]: each vertex
/// counts its edges in the faces around it (a face with the vertex at two corners once), so no
/// sort of all the edges is needed: a quarter of the time on 270k triangles.
fn edge_vertices(mesh: &Mesh, head: &[u32], next: &[u32]) -> (Vec<bool>, Vec<bool>) {
    let mut border = vec![false; mesh.positions.len()];
    let mut non_manifold = vec![false; mesh.positions.len()];
    let mut ends: Vec<u32> = Vec::new();
    for v in 0..mesh.positions.len() {
        ends.clear();
        let (mut c, mut last_face) = (head[v], u32::MAX);
        while c != NO_CORNER {
            let f = c / 3;
            // A face's corners are listed next to each other: count each face once.
            if f != last_face {
                let t = mesh.triangles[f as usize];
                for k in 0..3 {
                    let (a, b) = (t[k], t[(k + 1) % 3]);
                    if a as usize == v {
                        ends.push(b);
                    } else if b as usize == v {
                        ends.push(a);
                    }
                }
                last_face = f;
            }
            c = next[c as usize];
        }
        ends.sort_unstable();
        for faces in ends.chunk_by(|a, b| a == b).map(<[u32]>::len) {
            border[v] |= faces == 1;
            non_manifold[v] |= faces > 2;
        }
    }
    (border, non_manifold)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::shapes;

    /// The border by the definition: vertices of an edge (a, b) that one face-side has, every
    /// triangle's three sides counted, found by sorting them all.
    fn border_by_sorting(mesh: &Mesh) -> Vec<bool> {
        let mut edges: Vec<(u32, u32)> = mesh
            .triangles
            .iter()
            .flat_map(|t| (0..3).map(move |k| (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3]))))
            .collect();
        edges.sort_unstable();
        let mut border = vec![false; mesh.positions.len()];
        for (i, e) in edges.iter().enumerate() {
            if (i == 0 || edges[i - 1] != *e) && edges.get(i + 1) != Some(e) {
                border[e.0 as usize] = true;
                border[e.1 as usize] = true;
            }
        }
        border
    }

    #[test]
    fn the_border_from_the_corner_lists_is_the_border_by_definition() {
        let sphere = shapes::icosphere(1.0, 3);
        let cap: Vec<[u32; 3]> = sphere
            .triangles
            .iter()
            .filter(|t| t.iter().all(|&v| sphere.positions[v as usize].z < 0.4))
            .copied()
            .collect();
        // A cap, its border's vertices; a closed sphere, none; and a cap with a fin (an edge with
        // three faces), a degenerate face (a vertex twice) and a face alone.
        let mut odd = cap.clone();
        let [a, b, _] = cap[0];
        let far = sphere.triangles.iter().flatten().copied().find(|v| !cap.iter().flatten().any(|w| w == v)).unwrap();
        odd.extend([[a, b, far], [a, a, b], [far, a, 7]]);
        for triangles in [cap, sphere.triangles.clone(), odd] {
            let mesh = Mesh::new(sphere.positions.clone(), None, triangles);
            let c = Collapser::new(&mesh);
            assert_eq!(c.border, border_by_sorting(&mesh));
        }
        let c = Collapser::new(&sphere);
        assert!(!c.has_border());
    }
}
