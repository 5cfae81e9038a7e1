//! The tree's input: oriented samples (position + unit normal), taken from a mesh's vertices or
//! face centres, or from a point cloud that carries normals.

use crate::error::{Error, Result};
use crate::mesh::Mesh;
use glam::Vec3;

/// Which elements of a mesh become samples.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum MeshSampling {
    /// One sample per referenced vertex, normal = area-weighted average of its faces' normals.
    #[default]
    Vertices,
    /// One sample per non-degenerate face, at its barycentre, with the face's normal.
    FaceCenters,
}

/// Oriented samples. `origin[i]` is the mesh element (vertex or face index, or point index for
/// clouds) sample `i` came from.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SampleSet {
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    pub origin: Vec<u32>,
}

impl SampleSet {
    pub fn len(&self) -> usize {
        self.positions.len()
    }

    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }

    /// Samples of a mesh (triangles required) as `sampling` says. Only triangles with non-zero
    /// area count: vertices used by no such triangle, and zero-area faces, give no sample.
    pub fn from_mesh(mesh: &Mesh, sampling: MeshSampling) -> Result<SampleSet> {
        mesh.check()?;
        if mesh.triangles.is_empty() {
            return Err(Error::input("the mesh has no triangles"));
        }
        let samples = match sampling {
            MeshSampling::Vertices => vertex_samples(mesh),
            MeshSampling::FaceCenters => face_samples(mesh),
        };
        if samples.is_empty() {
            return Err(Error::input("every triangle of the mesh is degenerate (zero area)"));
        }
        Ok(samples)
    }

    /// Samples of a point cloud with normals. Normals are normalised; a zero-length normal is
    /// an error naming the point (estimate normals instead, or fix the input).
    pub fn from_cloud(cloud: &Mesh) -> Result<SampleSet> {
        cloud.check()?;
        let normals = cloud
            .normals
            .as_ref()
            .ok_or_else(|| Error::input("the point cloud has no normals (estimate them first)"))?;
        let mut unit = Vec::with_capacity(normals.len());
        for (i, n) in normals.iter().enumerate() {
            let length = n.length();
            if length < 1e-20 {
                return Err(Error::input(format!("point {i} has a zero-length normal")));
            }
            unit.push(*n / length);
        }
        Ok(SampleSet {
            positions: cloud.positions.clone(),
            normals: unit,
            origin: (0..cloud.positions.len() as u32).collect(),
        })
    }
}

/// The face's normal scaled by twice its area (zero for a degenerate face).
fn area_normal(mesh: &Mesh, tri: &[u32; 3]) -> Vec3 {
    let [a, b, c] = tri.map(|i| mesh.positions[i as usize]);
    (b - a).cross(c - a)
}

fn vertex_samples(mesh: &Mesh) -> SampleSet {
    let mut sums = vec![Vec3::ZERO; mesh.positions.len()];
    let mut used = vec![false; mesh.positions.len()];
    for tri in mesh.triangles.iter().filter(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2]) {
        let n = area_normal(mesh, tri);
        if n == Vec3::ZERO {
            continue; // zero area: no orientation, no sample
        }
        for &i in tri {
            sums[i as usize] += n;
            used[i as usize] = true;
        }
    }
    let mut samples = SampleSet::default();
    for (i, (&p, sum)) in mesh.positions.iter().zip(&sums).enumerate() {
        if used[i] {
            samples.positions.push(p);
            // Opposite faces can still cancel out (a folded sheet): such a vertex keeps a zero
            // normal, belongs to a cluster, and adds nothing to the quadric.
            samples.normals.push(sum.normalize_or_zero());
            samples.origin.push(i as u32);
        }
    }
    samples
}

fn face_samples(mesh: &Mesh) -> SampleSet {
    let mut samples = SampleSet::default();
    for (f, tri) in mesh.triangles.iter().enumerate() {
        let n = area_normal(mesh, tri);
        if n.length_squared() > 0.0 {
            let [a, b, c] = tri.map(|i| mesh.positions[i as usize]);
            samples.positions.push((a + b + c) / 3.0);
            samples.normals.push(n.normalize());
            samples.origin.push(f as u32);
        }
    }
    samples
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad() -> Mesh {
        Mesh::new(
            vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y, Vec3::splat(9.0)],
            None,
            vec![[0, 1, 2], [0, 2, 3], [0, 0, 1]],
        )
    }

    #[test]
    fn vertex_samples_skip_unreferenced_and_average_normals() {
        let s = SampleSet::from_mesh(&quad(), MeshSampling::Vertices).unwrap();
        assert_eq!(s.origin, vec![0, 1, 2, 3]);
        assert!(s.normals.iter().all(|n| (*n - Vec3::Z).length() < 1e-6));
    }

    #[test]
    fn face_samples_skip_degenerate_faces() {
        let s = SampleSet::from_mesh(&quad(), MeshSampling::FaceCenters).unwrap();
        assert_eq!(s.origin, vec![0, 1]);
        assert!((s.positions[0] - Vec3::new(2.0 / 3.0, 1.0 / 3.0, 0.0)).length() < 1e-6);
    }

    #[test]
    fn cloud_with_zero_normal_is_refused_by_index() {
        let cloud = Mesh::from_points(vec![Vec3::ZERO, Vec3::X], Some(vec![Vec3::Z, Vec3::ZERO]));
        let err = SampleSet::from_cloud(&cloud).unwrap_err().to_string();
        assert!(err.contains("point 1"), "{err}");
        let no_normals = Mesh::from_points(vec![Vec3::ZERO], None);
        assert!(SampleSet::from_cloud(&no_normals).is_err());
    }
}
