//! The C API from arrays, as hosts call it: fuzz-chosen vertices (wild floats or small
//! integers), normals, triangle indices, parameter fields (struct_size included), buffer
//! capacities, label kinds and the progress report at which to cancel, then (bytes after the
//! arrays) reconstruction and normal-estimation parameters. The arrays always hold
//! what the counts say (the caller's side of the contract); everything else is arbitrary.
//! Every call must return a status, never VSTREE_STATUS_INTERNAL, and outputs must be
//! consistent with their statistics.
#![no_main]
use libfuzzer_sys::fuzz_target;
use std::ffi::{c_char, c_void};
use std::ptr::{null, null_mut};
use vstree::ffi::mesh::*;
use vstree::ffi::normals::*;
use vstree::ffi::reconstruct::*;
use vstree::ffi::simplify::*;
use vstree::ffi::tree::*;
use vstree::ffi::vstree_status;

fn status_ok(status: vstree_status) -> bool {
    assert_ne!(status, vstree_status::Internal, "a panic was caught: a bug");
    status == vstree_status::Ok
}

/// Reads bytes off the front of the input; zeros once it runs out.
struct Bytes<'a>(&'a [u8]);

impl Bytes<'_> {
    fn u8(&mut self) -> u8 {
        match self.0.split_first() {
            Some((&b, rest)) => {
                self.0 = rest;
                b
            }
            None => 0,
        }
    }
    fn f32(&mut self) -> f32 {
        f32::from_le_bytes([self.u8(), self.u8(), self.u8(), self.u8()])
    }
}

struct Stop {
    calls: u32,
    at: u32,
}

unsafe extern "C" fn progress(user: *mut c_void, fraction: f32, _stage: *const c_char) -> i32 {
    let stop = &mut *(user as *mut Stop);
    assert!((0.0..=1.0).contains(&fraction));
    stop.calls += 1;
    i32::from(stop.calls != stop.at)
}

fuzz_target!(|data: &[u8]| {
    let mut b = Bytes(data);
    let n = b.u8() as usize;
    let t = b.u8() as usize;
    let flags = b.u8();
    let mut p = vstree_simplify_params_default();
    p.struct_size = [48, 48, 48, 48, 0, 4, 49, 4096][b.u8() as usize % 8];
    p.tree_kind = i32::from(b.u8() % 3) - i32::from(flags & 0x80 != 0);
    p.metric = i32::from(b.u8() % 4);
    p.sampling = i32::from(b.u8() % 3);
    p.error = [
        1e-3,
        1e-2,
        0.1,
        1.0,
        0.0,
        -1.0,
        f64::NAN,
        16.0,
        1e-9,
        f64::INFINITY,
    ][b.u8() as usize % 10];
    p.d_a = f32::from(b.u8()) / 200.0;
    p.d_d = f32::from(b.u8()) / 200.0;
    p.max_depth = u32::from(b.u8() % 33);
    // 0 (the global pool) or an out-of-range count. A private pool (1..=1024) is dropped at
    // the end of its call without joining its threads (rayon), so LeakSanitizer would count
    // a worker still exiting as a leak; tests/c and tests/python cover private pools.
    p.threads = [0, 2000][b.u8() as usize % 2];
    p.min_cell_size = [1e-7, 0.0, 0.5, 1.0, f64::NAN, 1e-3][b.u8() as usize % 6];
    let stop_at = u32::from(b.u8() % 12); // 0: never
    let capacity_cut = usize::from(b.u8() % 4); // how short output buffers are
    let label_kind = i32::from(b.u8() % 3);

    let small_ints = flags & 1 != 0;
    let positions: Vec<f32> = (0..3 * n)
        .map(|_| {
            if small_ints {
                f32::from(b.u8() as i8) / 16.0
            } else {
                b.f32()
            }
        })
        .collect();
    let normals: Option<Vec<f32>> =
        (flags & 2 != 0).then(|| (0..3 * n).map(|_| f32::from(b.u8() as i8) / 64.0).collect());
    let triangles: Vec<u32> = (0..3 * t)
        .map(|_| match b.u8() {
            255 => u32::MAX,
            v => u32::from(v),
        })
        .collect();

    unsafe {
        let mut mesh = null_mut();
        let created = vstree_mesh_create(
            positions.as_ptr(),
            n,
            normals.as_ref().map_or(null(), |v| v.as_ptr()),
            triangles.as_ptr(),
            t,
            &mut mesh,
        );
        let valid = n > 0
            && positions.iter().all(|x| x.abs() <= vstree::mesh::MAX_COORDINATE) // NaN fails too
            && normals
                .as_ref()
                .is_none_or(|v| v.iter().all(|x| x.is_finite()))
            && triangles.iter().all(|&i| (i as usize) < n);
        assert_eq!(status_ok(created), valid);
        if !valid {
            assert!(mesh.is_null());
            return;
        }

        let mut out = vec![0f32; (3 * n).saturating_sub(capacity_cut)];
        let copied = vstree_mesh_copy_positions(mesh, out.as_mut_ptr(), out.len());
        assert_eq!(status_ok(copied), capacity_cut == 0);

        let mut stop = Stop {
            calls: 0,
            at: stop_at,
        };
        let mut result = null_mut();
        let cb = (flags & 4 != 0).then_some(progress as unsafe extern "C" fn(_, _, _) -> _);
        let user = (&mut stop as *mut Stop).cast();
        if status_ok(vstree_simplify(mesh, &p, cb, user, &mut result)) {
            let s = &*vstree_simplify_result_get_stats(result);
            let m = vstree_simplify_result_get_mesh(result);
            assert_eq!(s.output_vertices as usize, vstree_mesh_vertex_count(m));
            assert_eq!(s.output_triangles as usize, vstree_mesh_triangle_count(m));
            let mut idx = vec![0u32; vstree_mesh_triangle_count(m) * 3];
            assert!(status_ok(vstree_mesh_copy_triangles(
                m,
                idx.as_mut_ptr(),
                idx.len()
            )));
            assert!(idx
                .iter()
                .all(|&i| (i as usize) < vstree_mesh_vertex_count(m)));
            vstree_simplify_result_free(result);
        } else {
            assert!(result.is_null());
        }

        let mut stop = Stop {
            calls: 0,
            at: stop_at,
        };
        let user = (&mut stop as *mut Stop).cast();
        let mut tree = null_mut();
        if status_ok(vstree_tree_build(mesh, &p, cb, user, &mut tree)) {
            let s = &*vstree_tree_get_stats(tree);
            let count = vstree_tree_node_count(tree);
            assert_eq!(count as u64, s.nodes);
            let mut nodes = Vec::with_capacity(count);
            let cap = count.saturating_sub(capacity_cut);
            let copied = vstree_tree_copy_nodes(tree, nodes.as_mut_ptr(), cap);
            assert_eq!(status_ok(copied), capacity_cut == 0);
            let mut labels = vec![0u32; vstree_tree_vertex_count(tree)];
            let copied =
                vstree_tree_copy_vertex_labels(tree, label_kind, labels.as_mut_ptr(), labels.len());
            assert_eq!(status_ok(copied), label_kind < 2);
            let mut layer = Vec::with_capacity(vstree_tree_t_node_count(tree));
            let copied = vstree_tree_copy_t_nodes(tree, layer.as_mut_ptr(), layer.capacity());
            assert!(status_ok(copied));
            vstree_tree_free(tree);
        } else {
            assert!(tree.is_null());
        }

        // Reconstruction and normal estimation, with parameters from the bytes after the
        // arrays (zeros, i.e. the first choice of each, when the input ends there). Grid depth
        // and levels stay small so a run never nears the fuzzer's timeout.
        let mut r = vstree_reconstruct_params_default();
        r.struct_size = [80, 80, 80, 0, 79, 4096][b.u8() as usize % 6];
        r.orient = [3, 0, 1, 2, 4, -1][b.u8() as usize % 6];
        r.error = [1e-5, 1e-3, 0.0, f64::NAN, 1e-9][b.u8() as usize % 5];
        r.max_levels = [1, 0, 2, 13][b.u8() as usize % 4];
        r.max_grid_depth = [5, 4, 6, 3, 21][b.u8() as usize % 5];
        r.trim = [0.0, 1.5, -1.0, f32::NAN][b.u8() as usize % 4];
        r.target_distance = [0.0, 1e-3, -1.0][b.u8() as usize % 3];
        r.neighbours = [16, 3, 8, 0, 257][b.u8() as usize % 5];
        r.reorient_given = u32::from(b.u8() % 3);
        r.threads = [0, 2000][b.u8() as usize % 2];
        let mut q = vstree_normal_params_default();
        q.struct_size = [20, 20, 20, 0, 19, 21][b.u8() as usize % 6];
        q.orient = r.orient;
        q.neighbours = r.neighbours;
        q.reorient_given = r.reorient_given;
        q.threads = r.threads;
        let with_report = b.u8();

        let mut stop = Stop {
            calls: 0,
            at: stop_at,
        };
        let user = (&mut stop as *mut Stop).cast();
        let mut out = null_mut();
        let mut report = vstree_normals_report {
            struct_size: [64u32, 0, 4096][usize::from(with_report % 3)],
            ..Default::default()
        };
        let report_ptr = if with_report & 4 != 0 {
            null_mut()
        } else {
            &mut report as *mut _
        };
        if status_ok(vstree_estimate_normals(
            mesh, &q, cb, user, &mut out, report_ptr,
        )) {
            assert_eq!(
                vstree_mesh_vertex_count(out),
                vstree_mesh_vertex_count(mesh)
            );
            assert_eq!(vstree_mesh_has_normals(out), 1);
            assert!(
                report_ptr.is_null() || report.estimated as usize <= vstree_mesh_vertex_count(mesh)
            );
            vstree_mesh_free(out);
        } else {
            assert!(out.is_null());
        }

        let mut stop = Stop {
            calls: 0,
            at: stop_at,
        };
        let user = (&mut stop as *mut Stop).cast();
        let mut result = null_mut();
        if status_ok(vstree_reconstruct(mesh, &r, cb, user, &mut result)) {
            let s = &*vstree_reconstruct_result_get_stats(result);
            let m = vstree_reconstruct_result_get_mesh(result);
            assert_eq!(s.output_vertices as usize, vstree_mesh_vertex_count(m));
            assert_eq!(s.output_triangles as usize, vstree_mesh_triangle_count(m));
            let mut idx = vec![0u32; vstree_mesh_triangle_count(m) * 3];
            assert!(status_ok(vstree_mesh_copy_triangles(
                m,
                idx.as_mut_ptr(),
                idx.len()
            )));
            assert!(idx
                .iter()
                .all(|&i| (i as usize) < vstree_mesh_vertex_count(m)));
            vstree_reconstruct_result_free(result);
        } else {
            assert!(result.is_null());
        }
        vstree_mesh_free(mesh);
    }
});
