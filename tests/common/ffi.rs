//! Helpers for the tests that call the C ABI from Rust: a mesh handle from a Rust mesh and
//! back, and the thread's last error message.

use std::ffi::CStr;
use std::ptr::{null, null_mut};
use vstree::ffi::mesh::*;
use vstree::ffi::*;
use vstree::Mesh;

pub fn last_error() -> String {
    unsafe { CStr::from_ptr(vstree_last_error_message()) }.to_string_lossy().into_owned()
}

/// A mesh handle from a Rust mesh, through vstree_mesh_create.
pub fn handle(mesh: &Mesh) -> *mut vstree_mesh {
    let positions: Vec<f32> = mesh.positions.iter().flat_map(|p| p.to_array()).collect();
    let normals: Option<Vec<f32>> = mesh.normals.as_ref().map(|n| n.iter().flat_map(|p| p.to_array()).collect());
    let triangles: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
    let mut out = null_mut();
    let status = unsafe {
        vstree_mesh_create(
            positions.as_ptr(),
            mesh.positions.len(),
            normals.as_ref().map_or(null(), |n| n.as_ptr()),
            triangles.as_ptr(),
            mesh.triangles.len(),
            &mut out,
        )
    };
    assert_eq!(status, vstree_status::Ok, "{}", last_error());
    out
}

/// A Rust mesh back from a handle, through the copy functions.
pub fn read_back(mesh: *const vstree_mesh) -> Mesh {
    unsafe {
        let n = vstree_mesh_vertex_count(mesh);
        let t = vstree_mesh_triangle_count(mesh);
        let mut p = vec![0f32; 3 * n];
        let mut i = vec![0u32; 3 * t];
        assert_eq!(vstree_mesh_copy_positions(mesh, p.as_mut_ptr(), p.len()), vstree_status::Ok);
        assert_eq!(vstree_mesh_copy_triangles(mesh, i.as_mut_ptr(), i.len()), vstree_status::Ok);
        let normals = (vstree_mesh_has_normals(mesh) == 1).then(|| {
            let mut v = vec![0f32; 3 * n];
            assert_eq!(vstree_mesh_copy_normals(mesh, v.as_mut_ptr(), v.len()), vstree_status::Ok);
            v.chunks(3).map(glam::Vec3::from_slice).collect()
        });
        Mesh::new(
            p.chunks(3).map(glam::Vec3::from_slice).collect(),
            normals,
            i.chunks(3).map(|c| [c[0], c[1], c[2]]).collect(),
        )
    }
}
