//! The connectivity of a triangle mesh: counts, manifoldness, orientation, components, Euler
//! characteristic and genus ([`analyze`]), which the simplifier's topology guard, the
//! reconstruction and the tests all rely on, and the edge walks the reconstruction makes (its
//! edges, border vertices and the pairs of faces across each edge).
//!
//! The edge analysis sorts the 3F half-edges by their undirected key, so a million triangles
//! take a fraction of a second.

use crate::mesh::Mesh;
use crate::union_find::UnionFind;
use glam::Vec3;
use rayon::prelude::*;

/// Topological figures of a mesh, as computed by [`analyze`].
///
/// Faces with a repeated vertex index or an index out of range are *degenerate*: they are counted
/// in `degenerate_faces` and ignored by every other figure.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct TopologyReport {
    /// Vertices referenced by at least one non-degenerate face.
    pub vertices: usize,
    /// Vertices in `positions` that no non-degenerate face references.
    pub unreferenced_vertices: usize,
    /// Distinct undirected edges.
    pub edges: usize,
    /// Non-degenerate faces.
    pub faces: usize,
    /// Edges used by exactly one face.
    pub boundary_edges: usize,
    /// Edges shared by more than two faces.
    pub non_manifold_edges: usize,
    /// Vertices whose incident faces do not form a single disk (closed fan) or half-disk (open
    /// fan), e.g. two cones touching at their tips, or a vertex on a non-manifold edge.
    pub non_manifold_vertices: usize,
    /// Edges shared by exactly two faces that traverse them in the same direction (one of the two
    /// faces is flipped relative to the other).
    pub inconsistently_oriented_edges: usize,
    /// Connected components, where faces sharing an edge are connected.
    pub components: usize,
    /// V - E + F over the whole mesh (referenced vertices, distinct edges, non-degenerate faces).
    pub euler_characteristic: i64,
    /// Euler characteristic of each component, in the order of each component's first face. A
    /// vertex shared by several components (a non-manifold vertex) counts in the first one only,
    /// so these sum to `euler_characteristic`.
    pub component_euler_characteristics: Vec<i64>,
    /// Faces with a repeated vertex index or an index out of range.
    pub degenerate_faces: usize,
}

impl TopologyReport {
    /// True for a closed, oriented 2-manifold: at least one face, no degenerate faces, no boundary
    /// edges, no non-manifold edges or vertices, and every edge traversed once in each direction.
    pub fn is_watertight(&self) -> bool {
        self.faces > 0
            && self.degenerate_faces == 0
            && self.boundary_edges == 0
            && self.non_manifold_edges == 0
            && self.non_manifold_vertices == 0
            && self.inconsistently_oriented_edges == 0
    }

    /// The genus (number of handles, summed over components) of a watertight mesh:
    /// the sum over components c of (2 - chi_c) / 2. `None` when the mesh is not watertight (the
    /// genus of a surface with boundary or singularities is not what tests mean by "genus").
    pub fn genus(&self) -> Option<u32> {
        if !self.is_watertight() {
            return None;
        }
        let mut total = 0u32;
        for &chi in &self.component_euler_characteristics {
            // A closed orientable surface has chi = 2 - 2g <= 2, even.
            if chi > 2 || (2 - chi) % 2 != 0 {
                return None;
            }
            total = total.checked_add(u32::try_from((2 - chi) / 2).ok()?)?;
        }
        Some(total)
    }
}

/// True when `tri` has three distinct indices below `vertex_count`.
pub(crate) fn is_valid_face(tri: &[u32; 3], vertex_count: usize) -> bool {
    tri.iter().all(|&v| (v as usize) < vertex_count) && tri[0] != tri[1] && tri[1] != tri[2] && tri[0] != tri[2]
}

/// One directed half-edge: the undirected key (low index in the high 32 bits), and the face index
/// shifted left by one with the low bit set when the face traverses the edge from high to low.
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
struct HalfEdge {
    key: u64,
    face_and_direction: u64,
}

/// The half-edges of the given faces, sorted by undirected key (then face), so the faces of each
/// edge are consecutive.
fn sorted_half_edges(faces: &[[u32; 3]]) -> Vec<HalfEdge> {
    let mut half_edges: Vec<HalfEdge> = faces
        .par_iter()
        .enumerate()
        .flat_map_iter(|(f, tri)| {
            (0..3).map(move |k| {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                let (lo, hi, reversed) = if a < b { (a, b, 0) } else { (b, a, 1) };
                HalfEdge {
                    key: (u64::from(lo) << 32) | u64::from(hi),
                    face_and_direction: ((f as u64) << 1) | reversed,
                }
            })
        })
        .collect();
    half_edges.par_sort_unstable();
    half_edges
}

/// Whether no edge of `mesh` has more than two faces (degenerate and invalid faces aside): a
/// closed surface or one with borders, as most scans are, whose topology edge collapses can
/// keep. One parallel sort of the edges, none of [`analyze`]'s other passes.
pub fn is_edge_manifold(mesh: &Mesh) -> bool {
    let n = mesh.positions.len();
    sorted_edge_keys(&mesh.triangles, |t| is_valid_face(t, n)).par_windows(3).all(|w| w[0] != w[2])
}

/// The edges of the `triangles` that `keep` takes, one key (low index in the high 32 bits) per
/// face that has it, sorted.
fn sorted_edge_keys(triangles: &[[u32; 3]], keep: impl Fn(&[u32; 3]) -> bool + Sync) -> Vec<u64> {
    let mut keys: Vec<u64> = triangles
        .par_iter()
        .filter(|t| keep(t))
        .flat_map_iter(|t| {
            (0..3).map(move |k| {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                u64::from(a.min(b)) << 32 | u64::from(a.max(b))
            })
        })
        .collect();
    keys.par_sort_unstable();
    keys
}

/// The components of a mesh that is known to be a closed 2-manifold (as the polygoniser makes
/// it), and the genus summed over them: components − χ/2, in one pass and without the checks
/// of [`analyze`]. For any other mesh the figures mean nothing.
pub(crate) fn closed_surface_parts_and_genus(mesh: &Mesh) -> (i64, i64) {
    let mut components = UnionFind::new(mesh.positions.len());
    let mut used = vec![false; mesh.positions.len()];
    for t in &mesh.triangles {
        components.union(t[0], t[1]);
        components.union(t[1], t[2]);
        t.iter().for_each(|&v| used[v as usize] = true);
    }
    let vertices = used.iter().filter(|&&u| u).count() as i64;
    let count =
        (0..mesh.positions.len() as u32).filter(|&v| used[v as usize] && components.find(v) == v).count() as i64;
    // Closed: every edge has two faces, E = 3F/2, so χ = V − F/2.
    let chi = vertices - mesh.triangles.len() as i64 / 2;
    (count, count - chi / 2)
}

/// Computes the [`TopologyReport`] of `mesh`. Point clouds (no triangles) give a report with zero
/// faces. Never panics on bad indices: such faces count as degenerate.
pub fn analyze(mesh: &Mesh) -> TopologyReport {
    let n_vertices = mesh.positions.len();
    // From here on faces are numbered by their rank among the valid faces.
    let faces: Vec<[u32; 3]> = mesh.triangles.iter().filter(|tri| is_valid_face(tri, n_vertices)).copied().collect();
    let degenerate_faces = mesh.triangles.len() - faces.len();
    let half_edges = sorted_half_edges(&faces);

    let mut report = TopologyReport { faces: faces.len(), degenerate_faces, ..TopologyReport::default() };
    let mut components = UnionFind::new(faces.len());
    // The first half-edge of every undirected edge, for counting edges per component.
    let mut edge_first_faces: Vec<u32> = Vec::new();
    // Endpoints of non-manifold edges: their vertices are non-manifold too.
    let mut on_non_manifold_edge = vec![false; n_vertices];
    for run in half_edges.chunk_by(|a, b| a.key == b.key) {
        report.edges += 1;
        let first_face = (run[0].face_and_direction >> 1) as u32;
        edge_first_faces.push(first_face);
        for h in &run[1..] {
            components.union(first_face, (h.face_and_direction >> 1) as u32);
        }
        match run.len() {
            1 => report.boundary_edges += 1,
            2 => {
                if (run[0].face_and_direction & 1) == (run[1].face_and_direction & 1) {
                    report.inconsistently_oriented_edges += 1;
                }
            }
            _ => {
                report.non_manifold_edges += 1;
                on_non_manifold_edge[(run[0].key >> 32) as usize] = true;
                on_non_manifold_edge[(run[0].key & 0xFFFF_FFFF) as usize] = true;
            }
        }
    }

    // Incident faces per vertex (compressed rows), for fans and per-component vertex counts.
    let mut row_start = vec![0u32; n_vertices + 1];
    for tri in &faces {
        for &v in tri {
            row_start[v as usize + 1] += 1;
        }
    }
    for v in 0..n_vertices {
        row_start[v + 1] += row_start[v];
    }
    let mut fill = row_start.clone();
    let mut incident = vec![0u32; faces.len() * 3];
    for (f, tri) in faces.iter().enumerate() {
        for &v in tri {
            incident[fill[v as usize] as usize] = f as u32;
            fill[v as usize] += 1;
        }
    }

    report.vertices = (0..n_vertices).filter(|&v| row_start[v + 1] > row_start[v]).count();
    report.unreferenced_vertices = n_vertices - report.vertices;
    report.non_manifold_vertices = (0..n_vertices)
        .into_par_iter()
        .filter(|&v| {
            let fan = &incident[row_start[v] as usize..row_start[v + 1] as usize];
            !fan.is_empty() && (on_non_manifold_edge[v] || !is_single_fan(v as u32, fan, &faces))
        })
        .count();
    report.euler_characteristic = report.vertices as i64 - report.edges as i64 + report.faces as i64;

    // Per-component Euler characteristics, components numbered by their first face.
    let mut component_of_root = vec![u32::MAX; faces.len()];
    let mut component_of_face = vec![0u32; faces.len()];
    for (f, component) in component_of_face.iter_mut().enumerate() {
        let root = components.find(f as u32) as usize;
        if component_of_root[root] == u32::MAX {
            component_of_root[root] = report.components as u32;
            report.components += 1;
        }
        *component = component_of_root[root];
    }
    let mut chi = vec![0i64; report.components];
    for &c in &component_of_face {
        chi[c as usize] += 1;
    }
    for &f in &edge_first_faces {
        chi[component_of_face[f as usize] as usize] -= 1;
    }
    for v in 0..n_vertices {
        if row_start[v + 1] > row_start[v] {
            let f = incident[row_start[v] as usize];
            chi[component_of_face[f as usize] as usize] += 1;
        }
    }
    report.component_euler_characteristics = chi;
    report
}

/// Per vertex of a mesh of `vertex_count` vertices: whether the faces around it form more than
/// one disk or half-disk, or one of its edges has more than two faces.
pub(crate) fn non_manifold_vertices(triangles: &[[u32; 3]], vertex_count: usize) -> Vec<bool> {
    let mut flagged = vec![false; vertex_count];
    for ((a, b), faces) in edges_and_face_counts(triangles) {
        if faces > 2 {
            flagged[a as usize] = true;
            flagged[b as usize] = true;
        }
    }
    let mut fans: Vec<Vec<u32>> = vec![Vec::new(); vertex_count];
    for (f, t) in triangles.iter().enumerate() {
        for &v in t {
            fans[v as usize].push(f as u32);
        }
    }
    for (v, fan) in fans.iter().enumerate() {
        flagged[v] |= !fan.is_empty() && !is_single_fan(v as u32, fan, triangles);
    }
    flagged
}

/// True when the faces `fan` around vertex `v` form one disk or half-disk: in the *link* of `v`
/// (each face contributes the edge between its two other vertices) every vertex has degree at
/// most 2 and the link is connected, so it is a single cycle or a single path.
fn is_single_fan(v: u32, fan: &[u32], faces: &[[u32; 3]]) -> bool {
    let link_edges: Vec<(u32, u32)> = fan
        .iter()
        .map(|&f| {
            let tri = faces[f as usize];
            let k = tri.iter().position(|&x| x == v).unwrap_or(0);
            (tri[(k + 1) % 3], tri[(k + 2) % 3])
        })
        .collect();
    let mut link_vertices: Vec<u32> = link_edges.iter().flat_map(|&(a, b)| [a, b]).collect();
    link_vertices.sort_unstable();
    link_vertices.dedup();
    let local = |x: u32| link_vertices.binary_search(&x).unwrap_or(0) as u32;
    let mut degree = vec![0u32; link_vertices.len()];
    let mut uf = UnionFind::new(link_vertices.len());
    for &(a, b) in &link_edges {
        let (a, b) = (local(a), local(b));
        degree[a as usize] += 1;
        degree[b as usize] += 1;
        uf.union(a, b);
    }
    let root = uf.find(0);
    degree.iter().all(|&d| d <= 2) && (1..link_vertices.len() as u32).all(|x| uf.find(x) == root)
}

/// Every edge of `triangles` once, as (low, high) vertex index, in sorted order, with the number
/// of faces that have it (1 on a border, 2 inside a manifold).
pub fn edges_and_face_counts(triangles: &[[u32; 3]]) -> Vec<((u32, u32), u32)> {
    sorted_edge_keys(triangles, |_| true)
        .chunk_by(|a, b| a == b)
        .map(|run| (((run[0] >> 32) as u32, run[0] as u32), run.len() as u32))
        .collect()
}

/// Which of `vertex_count` vertices lie on an edge that only one of `triangles` has.
pub fn border_vertices(triangles: &[[u32; 3]], vertex_count: usize) -> Vec<bool> {
    let mut border = vec![false; vertex_count];
    for ((a, b), faces) in edges_and_face_counts(triangles) {
        if faces == 1 {
            border[a as usize] = true;
            border[b as usize] = true;
        }
    }
    border
}

/// The pairs of faces that share an edge (every pair on a non-manifold edge).
pub fn adjacent_face_pairs(triangles: &[[u32; 3]]) -> Vec<[u32; 2]> {
    let mut pairs = Vec::with_capacity(3 * triangles.len() / 2);
    for run in sorted_half_edges(triangles).chunk_by(|a, b| a.key == b.key) {
        for (i, first) in run.iter().enumerate() {
            for second in &run[i + 1..] {
                pairs.push([first, second].map(|h| (h.face_and_direction >> 1) as u32));
            }
        }
    }
    pairs
}

/// Of `pairs` ([`adjacent_face_pairs`]), those whose normals differ by more than `degrees`:
/// folds, where one face lies back over the other (faces with an index out of range or no
/// area have no normal and never fold).
pub fn folded_face_pairs(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    pairs: &[[u32; 2]],
    degrees: f32,
) -> Vec<[u32; 2]> {
    let normals: Vec<Vec3> = triangles
        .par_iter()
        .map(|tri| {
            if !is_valid_face(tri, positions.len()) {
                return Vec3::ZERO;
            }
            let [a, b, c] = tri.map(|v| positions[v as usize]);
            (b - a).cross(c - a).normalize_or_zero()
        })
        .collect();
    let limit = degrees.to_radians().cos();
    pairs
        .par_iter()
        .copied()
        .filter(|&[f, g]| {
            let (m, n) = (normals[f as usize], normals[g as usize]);
            m != Vec3::ZERO && n != Vec3::ZERO && m.dot(n) < limit
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn border_vertices_are_those_of_the_edges_one_face_has() {
        let sphere = crate::eval::shapes::icosphere(1.0, 2);
        assert!(!border_vertices(&sphere.triangles, sphere.positions.len()).contains(&true));
        // A 4 x 4 grid of squares: the 16 vertices round its edge, not the 9 inside.
        let grid = crate::eval::shapes::square_grid(4);
        let border = border_vertices(&grid.triangles, grid.positions.len());
        assert_eq!(border.iter().filter(|&&b| b).count(), 16);
        for (v, p) in grid.positions.iter().enumerate() {
            let on_edge = [p.x, p.y].iter().any(|&c| c.abs() < 1e-6 || (c - 1.0).abs() < 1e-6);
            assert_eq!(border[v], on_edge, "vertex {v} at {p}");
        }
    }

    #[test]
    fn folded_face_pairs_are_the_pairs_turned_back_over_their_edge() {
        // Faces on the edge (0, 1): a flat neighbour, one folded back (179 degrees), one at
        // 90 degrees, and a degenerate one (no normal).
        let positions = vec![
            Vec3::ZERO,
            Vec3::X,
            Vec3::new(0.5, 1.0, 0.0),
            Vec3::new(0.5, -1.0, 0.0),
            Vec3::new(0.5, 0.8, 0.01),
            Vec3::new(0.5, 0.0, 1.0),
            Vec3::new(2.0, 0.0, 0.0),
        ];
        let flat = vec![[0, 1, 2], [1, 0, 3]];
        assert_eq!(adjacent_face_pairs(&flat), vec![[0, 1]]);
        assert!(folded_face_pairs(&positions, &flat, &adjacent_face_pairs(&flat), 150.0).is_empty());
        let faces = vec![[0, 1, 2], [1, 0, 4], [1, 0, 5], [1, 0, 6]];
        let pairs = adjacent_face_pairs(&faces);
        assert_eq!(pairs.len(), 6, "every pair of the four faces on one edge");
        assert_eq!(folded_face_pairs(&positions, &faces, &pairs, 150.0), vec![[0, 1]]);
        assert_eq!(folded_face_pairs(&positions, &faces, &pairs, 80.0).len(), 3);
    }

    #[test]
    fn closed_surface_parts_and_genus_agree_with_the_full_analysis() {
        use crate::eval::shapes;
        let mut two_shapes = shapes::torus(1.0, 0.3, 24, 12);
        let double = shapes::double_torus();
        let offset = two_shapes.positions.len() as u32;
        two_shapes.positions.extend(double.positions.iter().map(|p| *p + Vec3::splat(5.0)));
        two_shapes.triangles.extend(double.triangles.iter().map(|t| t.map(|v| v + offset)));
        for (mesh, parts, genus) in
            [(shapes::icosphere(1.0, 2), 1, 0), (shapes::torus(1.0, 0.3, 24, 12), 1, 1), (two_shapes, 2, 3)]
        {
            assert_eq!(analyze(&mesh).genus(), Some(genus as u32));
            assert_eq!(analyze(&mesh).components, parts as usize);
            assert_eq!(closed_surface_parts_and_genus(&mesh), (parts, genus));
        }
    }

    /// A unit tetrahedron with outward winding.
    fn tetrahedron() -> Mesh {
        Mesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z], None, vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    }

    #[test]
    fn edge_manifold_means_no_edge_with_three_faces() {
        let mut m = tetrahedron();
        assert!(is_edge_manifold(&m));
        // Open, flipped, or with degenerate and out-of-range faces: still no edge with three.
        m.triangles.pop();
        m.triangles[0].swap(1, 2);
        m.triangles.extend([[0, 0, 1], [0, 1, 99]]);
        assert!(is_edge_manifold(&m));
        // A fin on edge 0-1: three faces there.
        m.positions.push(Vec3::NEG_ONE);
        m.triangles.extend([[0, 1, 3], [1, 0, 4]]);
        assert!(!is_edge_manifold(&m));
    }

    #[test]
    fn tetrahedron_is_a_sphere() {
        let m = tetrahedron();
        let r = analyze(&m);
        assert_eq!((r.vertices, r.edges, r.faces), (4, 6, 4));
        assert_eq!(r.euler_characteristic, 2);
        assert!(r.is_watertight(), "{r:?}");
        assert_eq!(r.genus(), Some(0));
    }

    #[test]
    fn defects_are_counted() {
        let mut open = tetrahedron();
        open.triangles.pop();
        let r = analyze(&open);
        assert_eq!(r.boundary_edges, 3);
        assert!(!r.is_watertight());
        assert_eq!(r.genus(), None);

        let mut flipped = tetrahedron();
        flipped.triangles[0].swap(1, 2);
        let r = analyze(&flipped);
        assert_eq!(r.inconsistently_oriented_edges, 3);
        assert_eq!(r.boundary_edges, 0);

        let mut bad = tetrahedron();
        bad.triangles.push([0, 0, 1]);
        bad.triangles.push([0, 1, 99]);
        let r = analyze(&bad);
        assert_eq!(r.degenerate_faces, 2);
        assert_eq!(r.faces, 4);
        assert!(!r.is_watertight());
    }

    #[test]
    fn two_tetrahedra_sharing_a_vertex_are_non_manifold_there() {
        let mut m = tetrahedron();
        m.positions.extend([-Vec3::X, -Vec3::Y, -Vec3::Z]);
        // A second tetrahedron (0, 4, 5, 6), mirrored so its winding is outward too.
        m.triangles.extend([[0, 4, 5], [0, 6, 4], [0, 5, 6], [4, 6, 5]]);
        let r = analyze(&m);
        assert_eq!(r.non_manifold_vertices, 1);
        assert_eq!(r.non_manifold_edges, 0);
        assert_eq!(r.components, 2);
        // The shared vertex counts once, in the component of its first face.
        assert_eq!(r.component_euler_characteristics, vec![2, 1]);
        assert_eq!(r.euler_characteristic, 3);
        assert!(!r.is_watertight());
    }

    #[test]
    fn empty_and_point_cloud() {
        let r = analyze(&Mesh::default());
        assert_eq!(r, TopologyReport::default());
        assert!(!r.is_watertight());
        let cloud = Mesh::from_points(vec![Vec3::ONE; 3], None);
        let r = analyze(&cloud);
        assert_eq!((r.faces, r.unreferenced_vertices), (0, 3));
    }
}
