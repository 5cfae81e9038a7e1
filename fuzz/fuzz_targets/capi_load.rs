//! The C API from a file's bytes: vstree_mesh_load_memory, then, when it parses, the calls a
//! host makes next (counts, copies, simplify, tree build). Every call must return a status;
//! VSTREE_STATUS_INTERNAL (a caught panic) is a bug and fails the run.
#![no_main]
use libfuzzer_sys::fuzz_target;
use std::ptr::null_mut;
use vstree::ffi::mesh::*;
use vstree::ffi::simplify::*;
use vstree::ffi::tree::*;
use vstree::ffi::vstree_status;

mod tolerate_tobj;

const NAMES: [&std::ffi::CStr; 8] = [
    c"f.ply", c"f.obj", c"f.off", c"f.xyz", c"f.pwn", c"ply", c"x.stl", c"",
];

fn ok(status: vstree_status) -> bool {
    assert_ne!(status, vstree_status::Internal, "a panic was caught: a bug");
    status == vstree_status::Ok
}

fuzz_target!(init: tolerate_tobj::install(), |data: &[u8]| {
    let Some((&selector, bytes)) = data.split_first() else { return };
    let name = NAMES[selector as usize % NAMES.len()];
    let mut mesh = null_mut();
    unsafe {
        if !ok(vstree_mesh_load_memory(bytes.as_ptr().cast(), bytes.len(), name.as_ptr(), &mut mesh)) {
            assert!(mesh.is_null());
            return;
        }
        let n = vstree_mesh_vertex_count(mesh);
        let t = vstree_mesh_triangle_count(mesh);
        let mut p = vec![0f32; 3 * n];
        let mut i = vec![0u32; 3 * t];
        assert!(ok(vstree_mesh_copy_positions(mesh, p.as_mut_ptr(), p.len())));
        assert!(ok(vstree_mesh_copy_triangles(mesh, i.as_mut_ptr(), i.len())));
        assert!(i.iter().all(|&v| (v as usize) < n));
        let mut result = null_mut();
        if ok(vstree_simplify(mesh, std::ptr::null(), None, null_mut(), &mut result)) {
            let out = vstree_simplify_result_get_mesh(result);
            let stats = &*vstree_simplify_result_get_stats(result);
            assert_eq!(stats.output_vertices as usize, vstree_mesh_vertex_count(out));
            vstree_simplify_result_free(result);
        }
        let mut tree = null_mut();
        if ok(vstree_tree_build(mesh, std::ptr::null(), None, null_mut(), &mut tree)) {
            assert_eq!(vstree_tree_vertex_count(tree), n);
            vstree_tree_free(tree);
        }
        vstree_mesh_free(mesh);
    }
});
