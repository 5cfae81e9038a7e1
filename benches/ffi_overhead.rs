//! What the C ABI costs on a 1M-triangle simplification, compared with the Rust call.
//!
//! The mesh is a torus of 500,000 vertices and 1,000,000 triangles; each L2 error setting in
//! [`ERRORS`] is measured `RUNS` times, the ways in rotating order:
//! - `rust`: `vstree::simplify(&mesh, ...)`, the reference;
//! - `c call`: `vstree_simplify` on an existing mesh handle, then `vstree_simplify_result_free`;
//! - `c host`: what a host does end to end: `vstree_mesh_create` from flat arrays (a copy and a
//!   check of every coordinate and index), `vstree_simplify`, copying the output arrays out,
//!   freeing everything.
//!
//! A 50 ms call on a shared machine varies by more than the boundary costs, so the overhead is
//! measured within each run: the run's wall time minus the time the library spent in its own
//! stages (`seconds_samples + seconds_tree + seconds_cluster` of that run's statistics). The
//! median of that, over the median Rust time, is the overhead.
//!
//! The mesh goes to `target/ffi-bench/torus_1m.ply` and the Rust medians to
//! `target/ffi-bench/rust.txt`, for `benches/ffi_overhead.c` and `benches/ffi_overhead.py`
//! (the same host path through the shared library, from C and from Python). Run all with
//! `bash benches/ffi_overhead.sh`.

use std::fmt::Write as _;
use std::path::Path;
use std::ptr::{null, null_mut};
use std::time::Instant;
use vstree::ffi::mesh::*;
use vstree::ffi::simplify::*;
use vstree::ffi::vstree_status;
use vstree::simplify::{simplify, SimplifyParams};
use vstree::{eval::shapes, Progress, TreeParams};

const RUNS: usize = 15;
/// The L2 error settings measured: the default (coarse) to fine.
const ERRORS: [f64; 3] = [1e-3, 1e-4, 1e-5];

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// The library's own time in a simplification: its three stages.
fn inside(result: *const vstree_simplify_result) -> f64 {
    let s = unsafe { &*vstree_simplify_result_get_stats(result) };
    s.seconds_samples + s.seconds_tree + s.seconds_cluster
}

fn main() {
    // `cargo bench` passes `--bench`; `cargo test --benches` does not: then just check it runs.
    let quick = !std::env::args().any(|a| a == "--bench");
    let (major, minor) = if quick { (100, 50) } else { (1000, 500) };
    let runs = if quick { 1 } else { RUNS };
    let mesh = shapes::torus(1.0, 0.3, major, minor);
    let (n, t) = (mesh.positions.len(), mesh.triangles.len());
    println!("ffi_overhead: torus, {n} vertices, {t} triangles; median of {runs} runs");
    let out_dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("target/ffi-bench");
    if !quick {
        std::fs::create_dir_all(&out_dir).expect("target/ffi-bench");
        vstree::io::write(&out_dir.join("torus_1m.ply"), &mesh).expect("write the mesh");
    }
    let positions: Vec<f32> = mesh.positions.iter().flat_map(|p| p.to_array()).collect();
    let triangles: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
    let create = || {
        let mut m = null_mut();
        let s = unsafe { vstree_mesh_create(positions.as_ptr(), n, null(), triangles.as_ptr(), t, &mut m) };
        assert_eq!(s, vstree_status::Ok);
        m
    };
    let handle = create();

    println!(
        "{:>6} {:>8} {:>9} | {:>10} {:>7} | {:>10} {:>10} {:>7}",
        "error", "out tris", "rust ms", "call: +ms", "%", "host ms", "host: +ms", "%"
    );
    let mut record = String::new();
    for error in ERRORS {
        let mut c_params = vstree_simplify_params_default();
        c_params.error = error;
        let params =
            SimplifyParams { tree: TreeParams { error, ..TreeParams::default() }, ..SimplifyParams::default() };
        let (mut rust, mut call_extra, mut host, mut host_extra) = (vec![], vec![], vec![], vec![]);
        let mut output_triangles = 0;
        for run in 0..runs {
            for way in 0..3 {
                let start = Instant::now();
                match (run + way) % 3 {
                    0 => {
                        let (out, _) = simplify(&mesh, &params, &mut Progress::none()).expect("ok");
                        output_triangles = out.triangles.len();
                        drop(out);
                        rust.push(start.elapsed().as_secs_f64());
                    }
                    1 => unsafe {
                        let mut result = null_mut();
                        let s = vstree_simplify(handle, &c_params, None, null_mut(), &mut result);
                        assert_eq!(s, vstree_status::Ok);
                        let library = inside(result);
                        vstree_simplify_result_free(result);
                        call_extra.push(start.elapsed().as_secs_f64() - library);
                    },
                    _ => unsafe {
                        let m = create();
                        let mut result = null_mut();
                        let s = vstree_simplify(m, &c_params, None, null_mut(), &mut result);
                        assert_eq!(s, vstree_status::Ok);
                        let out = vstree_simplify_result_get_mesh(result);
                        let mut p = vec![0f32; 3 * vstree_mesh_vertex_count(out)];
                        let mut i = vec![0u32; 3 * vstree_mesh_triangle_count(out)];
                        let s = vstree_mesh_copy_positions(out, p.as_mut_ptr(), p.len());
                        assert_eq!(s, vstree_status::Ok);
                        let s = vstree_mesh_copy_triangles(out, i.as_mut_ptr(), i.len());
                        assert_eq!(s, vstree_status::Ok);
                        let library = inside(result);
                        vstree_simplify_result_free(result);
                        vstree_mesh_free(m);
                        let wall = start.elapsed().as_secs_f64();
                        host.push(wall);
                        host_extra.push(wall - library);
                    },
                }
            }
        }
        let rust = median(rust);
        let (call_extra, host, host_extra) = (median(call_extra), median(host), median(host_extra));
        println!(
            "{error:>6.0e} {output_triangles:>8} {:>9.1} | {:>10.2} {:>6.1}% | {:>10.1} {:>10.2} {:>6.1}%",
            1e3 * rust,
            1e3 * call_extra,
            100.0 * call_extra / rust,
            1e3 * host,
            1e3 * host_extra,
            100.0 * host_extra / rust
        );
        writeln!(record, "{error:e} {rust}").expect("string");
    }
    unsafe { vstree_mesh_free(handle) };
    if !quick {
        std::fs::write(out_dir.join("rust.txt"), record).expect("target/ffi-bench/rust.txt");
    }
}
