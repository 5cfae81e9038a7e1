//! Folds: adjacent faces turned back onto each other, which distances barely see and a picture
//! shows as spikes and creases.

use vstree::{topology, Mesh};

/// Adjacent faces whose normals differ by more than this many degrees make a fold.
pub const FOLD_DEGREES: f64 = 150.0;

/// Edges whose faces' normals differ by more than [`FOLD_DEGREES`] (every pair of faces on a
/// non-manifold edge counts; degenerate faces have no normal and never fold).
pub fn folds(mesh: &Mesh) -> usize {
    let pairs = topology::adjacent_face_pairs(&mesh.triangles);
    topology::folded_face_pairs(&mesh.positions, &mesh.triangles, &pairs, FOLD_DEGREES as f32).len()
}
