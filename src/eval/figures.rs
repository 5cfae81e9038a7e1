//! Figures of a mesh's shape that only tests and benchmarks need: vertex valences, the enclosed
//! volume and the area.

use crate::mesh::Mesh;
use crate::topology::{edges_and_face_counts, is_valid_face};
use glam::DVec3;

/// The valence (number of distinct neighbours along edges) of every vertex in `positions`;
/// unreferenced vertices have valence 0. Degenerate faces are ignored.
pub fn valences(mesh: &Mesh) -> Vec<u32> {
    let faces: Vec<[u32; 3]> =
        mesh.triangles.iter().filter(|tri| is_valid_face(tri, mesh.positions.len())).copied().collect();
    let mut valence = vec![0u32; mesh.positions.len()];
    for ((a, b), _) in edges_and_face_counts(&faces) {
        valence[a as usize] += 1;
        valence[b as usize] += 1;
    }
    valence
}

/// `histogram[k]` = the number of referenced vertices with valence k (unreferenced vertices, of
/// valence 0, are not counted). Empty for a mesh without faces.
pub fn valence_histogram(mesh: &Mesh) -> Vec<u32> {
    let mut histogram: Vec<u32> = Vec::new();
    for v in valences(mesh).into_iter().filter(|&v| v > 0) {
        if histogram.len() <= v as usize {
            histogram.resize(v as usize + 1, 0);
        }
        histogram[v as usize] += 1;
    }
    histogram
}

/// The corners, in double precision, of every triangle whose indices are in range.
fn corners(mesh: &Mesh) -> impl Iterator<Item = [DVec3; 3]> + '_ {
    let p = &mesh.positions;
    mesh.triangles
        .iter()
        .filter(|tri| tri.iter().all(|&v| (v as usize) < p.len()))
        .map(|tri| tri.map(|v| p[v as usize].as_dvec3()))
}

/// The signed volume enclosed by the triangles (sum of the signed tetrahedra from the origin), in
/// double precision. Positive for a closed mesh with outward (counter-clockwise seen from
/// outside) winding. Faces with out-of-range indices are skipped.
pub fn signed_volume(mesh: &Mesh) -> f64 {
    corners(mesh).map(|[a, b, c]| a.dot(b.cross(c))).sum::<f64>() / 6.0
}

/// The total area of the triangles, in double precision. Faces with out-of-range indices are
/// skipped.
pub fn surface_area(mesh: &Mesh) -> f64 {
    corners(mesh).map(|[a, b, c]| (b - a).cross(c - a).length()).sum::<f64>() / 2.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn tetrahedron_and_point_cloud() {
        let m = Mesh::new(
            vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z],
            None,
            vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
        );
        assert!((signed_volume(&m) - 1.0 / 6.0).abs() < 1e-12);
        assert!((surface_area(&m) - (1.5 + 3f64.sqrt() / 2.0)).abs() < 1e-6);
        assert_eq!(valences(&m), vec![3, 3, 3, 3]);
        assert_eq!(valence_histogram(&m), vec![0, 0, 0, 4]);
        let cloud = Mesh::from_points(vec![Vec3::ONE; 3], None);
        assert_eq!(signed_volume(&cloud), 0.0);
        assert!(valence_histogram(&cloud).is_empty());
    }
}
