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
use crate::collapse::Collapser;
use crate::mesh::Mesh;
use crate::tree::{NodeKind, VsTree};
use glam::Vec3;
use rayon::prelude::*;
use std::collections::VecDeque;

/// No T-node.
pub(crate) const UNLABELLED: u32 = u32::MAX;

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
    let labels: Vec<u32> = mesh.positions.par_iter().map(|&p| t_node_at(tree, p).unwrap_or(UNLABELLED)).collect();
    spread_labels(labels, neighbours)
}

/// Gives every vertex without a T-node ([`UNLABELLED`]) the label of the nearest labelled vertex
/// along the mesh's edges.
pub(crate) fn spread_labels(mut labels: Vec<u32>, neighbours: &Rows) -> Vec<u32> {
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
pub(crate) fn stray_components(mesh: &Mesh, labels: &[u32], neighbours: &Rows, cell: f32) -> Vec<bool> {
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
pub(crate) struct Clustered {
    pub mesh: Mesh,
    pub labels: Vec<u32>,
}

impl Clustered {
    /// Removes the vertices no triangle uses, with their labels.
    pub fn drop_unused_vertices(&mut self) {
        let kept = super::renumber_used_vertices(&mut self.mesh.triangles, self.mesh.positions.len());
        self.mesh.positions = kept.iter().map(|&v| self.mesh.positions[v]).collect();
        self.labels = kept.iter().map(|&v| self.labels[v]).collect();
    }
}

/// Collapses every edge whose ends share a label, while the link condition allows, and places
/// each remaining vertex at the mean of the fine vertices it absorbed. Stray components
/// (bubbles of the implicit function, see [`stray_components`]) are dropped.
/// `neighbours` are the fine mesh's ([`Rows::neighbours`]). On an open mesh, one vertex of
/// M0 stands for a stretch of border at most `border_run` long (see
/// [`Collapser::limit_border_runs`]).
pub(crate) fn cluster_at_t_layer(
    fine: &Mesh,
    labels: &[u32],
    neighbours: &Rows,
    cell: f32,
    border_run: f32,
) -> Clustered {
    let mut c = Collapser::new(fine);
    c.limit_border_runs(border_run);
    let dropped = stray_components(fine, labels, neighbours, cell);
    for (t, tri) in fine.triangles.iter().enumerate() {
        if tri.iter().any(|&v| labels[v as usize] == UNLABELLED || dropped[v as usize]) {
            c.remove_face_and_corners(t);
        }
    }
    // Vertices of faces taken out before (an open M0's unsupported part).
    for v in 0..fine.positions.len() {
        if neighbours.of(v as u32).is_empty() {
            c.remove_vertex(v);
        }
    }
    c.collapse_within(labels);
    let (mesh, labels) = c.finish(labels);
    Clustered { mesh, labels }
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
            (crate::eval::shapes::icosphere(1.0, 3), 0),
            (crate::eval::shapes::torus(1.0, 0.4, 48, 24), 1),
            (crate::eval::shapes::double_torus(), 2),
        ] {
            // Eight clusters, the octants: collapse as far as topology allows.
            let base = cluster_at_t_layer(
                &mesh,
                &octant_labels(&mesh),
                &Rows::neighbours(&mesh.triangles, mesh.positions.len()),
                0.0,
                f32::INFINITY,
            );
            let r = analyze(&base.mesh);
            assert!(r.is_watertight(), "{r:?}");
            assert_eq!(r.genus(), Some(genus));
            assert!(base.mesh.positions.len() < 40, "{} vertices left", base.mesh.positions.len());
        }
    }

    #[test]
    fn an_open_mesh_collapses_along_its_border() {
        // The upper half of a sphere in four clusters (the quadrants around z): a few vertices
        // each, and the border stays one manifold loop.
        let sphere = crate::eval::shapes::icosphere(1.0, 4);
        let upper = sphere
            .triangles
            .iter()
            .copied()
            .filter(|t| t.iter().all(|&v| sphere.positions[v as usize].z > -1e-6))
            .collect();
        let mesh = Mesh::new(sphere.positions.clone(), None, upper);
        let quadrants: Vec<u32> =
            mesh.positions.iter().map(|p| (p.x > 0.0) as u32 | ((p.y > 0.0) as u32) << 1).collect();
        let base = cluster_at_t_layer(
            &mesh,
            &quadrants,
            &Rows::neighbours(&mesh.triangles, mesh.positions.len()),
            0.0,
            f32::INFINITY,
        );
        let r = analyze(&base.mesh);
        assert_eq!(r.non_manifold_edges, 0, "{r:?}");
        assert!(r.boundary_edges >= 3, "{r:?}");
        assert!(base.mesh.positions.len() <= 8, "{} vertices left", base.mesh.positions.len());
    }

    #[test]
    fn a_large_open_cluster_keeps_its_border_within_the_run_length() {
        // A flat 20 x 20 square in four clusters, vertical strips: unbounded, each outer
        // strip's border (a side and two bits of the others) shrinks to one vertex at its
        // mean, cutting the square's corners off; with runs of at most 0.3, every corner
        // stays within 0.3 of an M0 vertex.
        let mesh = crate::eval::shapes::square_grid(20);
        let labels: Vec<u32> = mesh.positions.iter().map(|p| ((4.0 * p.x) as u32).min(3)).collect();
        let rows = Rows::neighbours(&mesh.triangles, mesh.positions.len());
        let corner_gap = |base: &Clustered| {
            [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 0.0)]
                .iter()
                .map(|c| base.mesh.positions.iter().map(|p| p.distance(*c)).fold(f32::INFINITY, f32::min))
                .fold(0.0f32, f32::max)
        };
        let bounded = cluster_at_t_layer(&mesh, &labels, &rows, 0.0, 0.3);
        let unbounded = cluster_at_t_layer(&mesh, &labels, &rows, 0.0, f32::INFINITY);
        assert!(corner_gap(&bounded) < 0.3, "{}", corner_gap(&bounded));
        assert!(corner_gap(&unbounded) > 0.3, "{}", corner_gap(&unbounded));
        let r = analyze(&bounded.mesh);
        assert_eq!(r.non_manifold_edges, 0, "{r:?}");
        assert!(bounded.mesh.positions.len() < 30, "{} vertices", bounded.mesh.positions.len());
    }

    #[test]
    fn components_spanning_fewer_than_four_t_nodes_are_dropped() {
        let mesh = crate::eval::shapes::icosphere(1.0, 2);
        let base = cluster_at_t_layer(
            &mesh,
            &vec![0; mesh.positions.len()],
            &Rows::neighbours(&mesh.triangles, mesh.positions.len()),
            0.0,
            f32::INFINITY,
        );
        assert!(base.mesh.positions.is_empty() && base.mesh.triangles.is_empty());
    }

    #[test]
    fn labels_partition_a_sphere_into_clusters() {
        let mesh = crate::eval::shapes::icosphere(1.0, 4);
        // Eight clusters: the octants.
        let base = cluster_at_t_layer(
            &mesh,
            &octant_labels(&mesh),
            &Rows::neighbours(&mesh.triangles, mesh.positions.len()),
            0.0,
            f32::INFINITY,
        );
        let r = analyze(&base.mesh);
        assert!(r.is_watertight() && r.genus() == Some(0));
        assert_eq!(base.mesh.positions.len(), 8, "one vertex per octant");
        assert_eq!(base.mesh.triangles.len(), 12);
    }
}
