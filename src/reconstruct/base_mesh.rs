//! The coarse base mesh M0 (paper §5.2): the fine polygonisation of the implicit function is
//! clustered at the T-layer, one vertex per T-node.
//!
//! Plain vertex clustering can tear a mesh or fuse sheets (it keeps neither manifoldness nor
//! genus), so the clustering is done by edge collapses restricted to each T-node's vertices,
//! each allowed only under the link condition (Dey et al. 1999): the neighbours common to both
//! ends must be exactly the two opposite corners of the edge. Such a collapse never changes the
//! topology of a closed 2-manifold, so M0 is watertight with the polygonisation's genus. Where
//! the link condition blocks the last collapses of a cluster (a cluster wrapped around a
//! handle), the cluster keeps a few vertices: correct topology comes first.

use super::adjacency::Rows;
use crate::mesh::Mesh;
use crate::tree::{NodeKind, VsTree};
use glam::{DVec3, Vec3};
use rayon::prelude::*;
use std::collections::VecDeque;

/// No T-node.
const UNLABELLED: u32 = u32::MAX;

/// The T-node whose cube contains `p`, if the octree's descent reaches one.
pub(crate) fn t_node_at(tree: &VsTree, p: Vec3) -> Option<u32> {
    let node = tree.locate(p)?;
    let mut i = node;
    // `locate` returns the deepest node: climb from an S-node back to its T-node.
    while tree.nodes[i].kind == NodeKind::Surface {
        i = tree.nodes[i].parent as usize;
    }
    (tree.nodes[i].kind == NodeKind::Transition).then_some(i as u32)
}

/// A T-node for every vertex: the one whose cube holds it, or else (the vertex lies in an empty
/// cell) the label of the nearest labelled vertex along the mesh's edges.
pub(crate) fn label_vertices(tree: &VsTree, mesh: &Mesh, neighbours: &Rows) -> Vec<u32> {
    let mut labels: Vec<u32> = mesh.positions.par_iter().map(|&p| t_node_at(tree, p).unwrap_or(UNLABELLED)).collect();
    let mut queue: VecDeque<u32> = (0..labels.len() as u32).filter(|&v| labels[v as usize] != UNLABELLED).collect();
    while let Some(v) = queue.pop_front() {
        for &w in neighbours.of(v) {
            if labels[w as usize] == UNLABELLED {
                labels[w as usize] = labels[v as usize];
                queue.push_back(w);
            }
        }
    }
    labels
}

/// A closed surface needs at least this many vertices: a component that spans fewer T-nodes
/// cannot be represented at the T-layer (it is a bubble of the implicit function).
const MIN_T_NODES_PER_COMPONENT: usize = 4;

/// Marks the vertices of components that span fewer than [`MIN_T_NODES_PER_COMPONENT`]
/// T-nodes, or that fit in a box of two grid cells (`cell`) a side. The latter is the
/// polygoniser's smallest closed shell: one grid point whose sign differs from all its
/// neighbours', wrapped in the 14 vertices of its star. It is below the grid's resolution,
/// so it is not a part of the surface that the grid resolves but a bubble of the implicit
/// function, such as the winding number leaves inside the tube of a sparsely sampled torus.
fn stray_components(mesh: &Mesh, labels: &[u32], neighbours: &Rows, cell: f32) -> Vec<bool> {
    let mut component = vec![u32::MAX; mesh.positions.len()];
    let mut dropped = vec![false; mesh.positions.len()];
    for start in 0..mesh.positions.len() {
        if component[start] != u32::MAX || neighbours.of(start as u32).is_empty() {
            continue;
        }
        let mut members = vec![start as u32];
        component[start] = start as u32;
        let mut k = 0;
        while k < members.len() {
            for &w in neighbours.of(members[k]) {
                if component[w as usize] == u32::MAX {
                    component[w as usize] = start as u32;
                    members.push(w);
                }
            }
            k += 1;
        }
        let mut t_nodes: Vec<u32> = members.iter().map(|&v| labels[v as usize]).collect();
        t_nodes.sort_unstable();
        t_nodes.dedup();
        let (low, high) = members
            .iter()
            .map(|&v| mesh.positions[v as usize])
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| (lo.min(p), hi.max(p)));
        let sub_resolution = (high - low).max_element() <= 2.0 * cell;
        if t_nodes.len() < MIN_T_NODES_PER_COMPONENT || sub_resolution {
            for &v in &members {
                dropped[v as usize] = true;
            }
        }
    }
    dropped
}

/// M0 with, per vertex, its T-node and how many fine vertices it stands for.
pub(crate) struct BaseMesh {
    pub mesh: Mesh,
    pub labels: Vec<u32>,
}

/// Collapses every edge whose ends share a label, while the link condition allows, and places
/// each remaining vertex at the mean of the fine vertices it absorbed. Stray components
/// (bubbles of the implicit function, see [`stray_components`]) are dropped.
/// `neighbours` are the fine mesh's ([`Rows::neighbours`]).
pub(crate) fn cluster_at_t_layer(fine: &Mesh, labels: &[u32], neighbours: &Rows, cell: f32) -> BaseMesh {
    let mut c = Collapser::new(fine);
    let dropped = stray_components(fine, labels, neighbours, cell);
    for (t, tri) in fine.triangles.iter().enumerate() {
        if tri.iter().any(|&v| labels[v as usize] == UNLABELLED || dropped[v as usize]) {
            c.alive_face[t] = false;
            for &v in tri {
                c.alive_vertex[v as usize] = false;
            }
        }
    }
    // Collapse in rounds, each vertex in at most one collapse per round (a greedy matching),
    // so clusters shrink evenly and rings stay small; merging everything into one growing
    // vertex instead makes every link test cost the cluster's whole perimeter.
    let same_label = |t: &[u32; 3]| (0..3).any(|k| labels[t[k] as usize] == labels[t[(k + 1) % 3] as usize]);
    let mut candidates: Vec<u32> = (0..c.triangles.len() as u32)
        .filter(|&t| c.alive_face[t as usize] && same_label(&c.triangles[t as usize]))
        .collect();
    let mut touched = vec![false; fine.positions.len()];
    loop {
        let mut collapsed = 0usize;
        touched.fill(false);
        for &t in &candidates {
            for k in 0..3 {
                if !c.alive_face[t as usize] {
                    break;
                }
                let tri = c.triangles[t as usize];
                let (u, v) = (tri[k], tri[(k + 1) % 3]);
                if labels[u as usize] == labels[v as usize]
                    && !touched[u as usize]
                    && !touched[v as usize]
                    && c.try_collapse(u.max(v), u.min(v))
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
        candidates.retain(|&t| c.alive_face[t as usize] && same_label(&c.triangles[t as usize]));
    }
    c.finish(labels)
}

/// Ends a corner list of [`Collapser`].
const NO_CORNER: u32 = u32::MAX;

/// A triangle mesh under edge collapses: faces die, vertices merge into survivors.
struct Collapser {
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
}

impl Collapser {
    fn new(mesh: &Mesh) -> Collapser {
        let mut head = vec![NO_CORNER; mesh.positions.len()];
        let mut next = vec![NO_CORNER; 3 * mesh.triangles.len()];
        for (t, tri) in mesh.triangles.iter().enumerate() {
            for (k, &v) in tri.iter().enumerate() {
                next[3 * t + k] = head[v as usize];
                head[v as usize] = (3 * t + k) as u32;
            }
        }
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
        }
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
        if !self.alive_vertex[u as usize] || !self.alive_vertex[v as usize] {
            return false;
        }
        let mut shared = [0u32; 2];
        let mut shared_count = 0;
        for f in self.faces(u) {
            if self.triangles[f as usize].contains(&v) {
                if shared_count == 2 {
                    return false; // more than two faces on the edge: not a manifold edge
                }
                shared[shared_count] = f;
                shared_count += 1;
            }
        }
        if shared_count != 2 {
            return false; // not an edge of a closed manifold (or no edge at all)
        }
        let (ring_u, ring_v, common) = self.rings_and_common(u, v);
        // Link condition; and never shrink a closed component below a tetrahedron.
        if common != 2 || ring_u + ring_v <= 6 {
            return false;
        }
        for &f in &shared {
            self.alive_face[f as usize] = false;
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
        let (sum, count) = (self.sum[u as usize], self.count[u as usize]);
        self.sum[v as usize] += sum;
        self.count[v as usize] += count;
        true
    }

    fn finish(self, labels: &[u32]) -> BaseMesh {
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
        BaseMesh { mesh: Mesh::new(positions, None, triangles), labels: out_labels }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::topology::analyze;

    /// Eight labels: the octant of each vertex.
    fn octant_labels(mesh: &Mesh) -> Vec<u32> {
        mesh.positions
            .iter()
            .map(|p| (p.x > 0.0) as u32 | ((p.y > 0.0) as u32) << 1 | ((p.z > 0.0) as u32) << 2)
            .collect()
    }

    #[test]
    fn collapsing_keeps_the_genus() {
        for (mesh, genus) in [
            (crate::shapes::icosphere(1.0, 3), 0),
            (crate::shapes::torus(1.0, 0.4, 48, 24), 1),
            (crate::shapes::double_torus(), 2),
        ] {
            // Eight clusters, the octants: collapse as far as topology allows.
            let base = cluster_at_t_layer(
                &mesh,
                &octant_labels(&mesh),
                &Rows::neighbours(&mesh.triangles, mesh.positions.len()),
                0.0,
            );
            let r = analyze(&base.mesh);
            assert!(r.is_watertight(), "{r:?}");
            assert_eq!(r.genus(), Some(genus));
            assert!(base.mesh.positions.len() < 40, "{} vertices left", base.mesh.positions.len());
        }
    }

    #[test]
    fn components_spanning_fewer_than_four_t_nodes_are_dropped() {
        let mesh = crate::shapes::icosphere(1.0, 2);
        let base = cluster_at_t_layer(
            &mesh,
            &vec![0; mesh.positions.len()],
            &Rows::neighbours(&mesh.triangles, mesh.positions.len()),
            0.0,
        );
        assert!(base.mesh.positions.is_empty() && base.mesh.triangles.is_empty());
    }

    #[test]
    fn labels_partition_a_sphere_into_clusters() {
        let mesh = crate::shapes::icosphere(1.0, 4);
        // Eight clusters: the octants.
        let base = cluster_at_t_layer(
            &mesh,
            &octant_labels(&mesh),
            &Rows::neighbours(&mesh.triangles, mesh.positions.len()),
            0.0,
        );
        let r = analyze(&base.mesh);
        assert!(r.is_watertight() && r.genus() == Some(0));
        assert_eq!(base.mesh.positions.len(), 8, "one vertex per octant");
        assert_eq!(base.mesh.triangles.len(), 12);
    }
}
