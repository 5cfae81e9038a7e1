//! The reconstruction and normal-estimation exports called from Rust: results equal to the
//! Rust API's, cancellation at every progress report with outputs untouched, every bad
//! parameter refused by name, and bad input giving statuses. `tests/c` and `tests/python` test
//! the same calls from the host languages.

use std::ffi::{c_char, c_void, CStr};
use std::ptr::{null, null_mut};
use vstree::ffi::mesh::*;
use vstree::ffi::normals::*;
use vstree::ffi::reconstruct::*;
use vstree::ffi::*;
use vstree::normals::{ensure_normals, NormalParams, Orientation};
use vstree::reconstruct::{reconstruct, ReconstructParams, RefinementStop};
use vstree::{eval::shapes, topology, Mesh, Progress};

mod common;
use common::ffi::{handle, last_error, read_back};

/// A torus cloud small enough for the tests to be quick; `normals` keeps the sampled ones.
fn torus_cloud(normals: bool) -> Mesh {
    let mut cloud = shapes::sample_surface(&shapes::torus(1.0, 0.35, 96, 48), 8000, 7);
    if !normals {
        cloud.normals = None;
    }
    cloud
}

/// Quick reconstruction parameters, C and Rust.
fn quick() -> (vstree_reconstruct_params, ReconstructParams) {
    let mut c = vstree_reconstruct_params_default();
    c.max_levels = 2;
    c.max_grid_depth = 7;
    let rust = ReconstructParams { max_levels: 2, max_grid_depth: 7, ..ReconstructParams::default() };
    (c, rust)
}

/// Every refinement stop with its C value.
const STOPS: [(RefinementStop, u32); 4] = [
    (RefinementStop::Target, VSTREE_REFINEMENT_STOPPED_TARGET),
    (RefinementStop::NoDetail, VSTREE_REFINEMENT_STOPPED_NO_DETAIL),
    (RefinementStop::MaxLevels, VSTREE_REFINEMENT_STOPPED_MAX_LEVELS),
    (RefinementStop::TriangleBudget, VSTREE_REFINEMENT_STOPPED_TRIANGLE_BUDGET),
];

#[test]
fn refinement_stops_are_named_as_the_rust_enum_names_them() {
    let name = |value: u32| unsafe { CStr::from_ptr(vstree_refinement_stopped_str(value)) }.to_str().unwrap();
    assert_eq!(STOPS.map(|(stop, _)| stop), RefinementStop::ALL);
    for (stop, value) in STOPS {
        assert_eq!(name(value), stop.as_str());
    }
    assert_eq!(
        RefinementStop::ALL.map(RefinementStop::as_str),
        ["target", "no_detail", "max_levels", "triangle_budget"]
    );
    for value in [4, 1000, u32::MAX] {
        assert_eq!(name(value), "unknown");
    }
}

#[test]
fn reconstruct_through_the_abi_equals_the_rust_call() {
    for with_normals in [true, false] {
        let cloud = torus_cloud(with_normals);
        let h = handle(&cloud);
        let (c, rust) = quick();
        let mut result = null_mut();
        let status = unsafe { vstree_reconstruct(h, &c, None, null_mut(), &mut result) };
        assert_eq!(status, vstree_status::Ok, "{}", last_error());
        let out = read_back(unsafe { vstree_reconstruct_result_get_mesh(result) });
        let stats = unsafe { *vstree_reconstruct_result_get_stats(result) };
        let (expected, s) = reconstruct(&cloud, &rust, &mut Progress::none()).unwrap();
        assert_eq!(out, expected);
        assert_eq!(stats.struct_size as usize, std::mem::size_of::<vstree_reconstruct_stats>());
        assert_eq!(stats.input_points as usize, cloud.positions.len());
        assert_eq!(stats.output_vertices as usize, expected.positions.len());
        assert_eq!(stats.output_triangles as usize, expected.triangles.len());
        assert_eq!(stats.t_nodes as usize, s.tree.t_nodes);
        assert_eq!(stats.base_vertices as usize, s.base_vertices);
        assert_eq!(stats.base_genus, s.base_genus.map_or(-1, |g| g as i32));
        assert_eq!(stats.base_genus, 1, "a torus");
        assert_eq!(stats.levels as usize, s.levels.len());
        assert_eq!(stats.grid_cells, s.grid_cells);
        // The mesh is bitwise equal; the RMS error's parallel sum may differ in its last bit.
        assert!((stats.final_error - s.final_error).abs() <= 1e-12 * s.final_error, "{stats:?}");
        assert_eq!(stats.normals_estimated as usize, if with_normals { 0 } else { cloud.positions.len() });
        assert!(stats.final_max_error >= stats.final_error && stats.final_error < 1e-2);
        assert!(stats.seconds_total >= stats.seconds_tree);
        assert_eq!(stats.thickened, u32::from(s.thickened));
        assert!(STOPS.contains(&(s.stopped, stats.stopped)), "{:?} vs {}", s.stopped, stats.stopped);
        assert_eq!(topology::analyze(&out).genus(), Some(1));

        // take_mesh moves the same mesh out and frees the result.
        let mut taken = null_mut();
        assert_eq!(unsafe { vstree_reconstruct_result_take_mesh(result, &mut taken) }, vstree_status::Ok);
        assert_eq!(read_back(taken), expected);
        unsafe { vstree_mesh_free(taken) };
        unsafe { vstree_mesh_free(h) };
    }
}

#[test]
fn params_null_means_the_defaults() {
    let p = vstree_reconstruct_params_default();
    assert_eq!(p.struct_size as usize, std::mem::size_of::<vstree_reconstruct_params>());
    assert_eq!(p.orient, VSTREE_ORIENTATION_PROPAGATE_OUTWARD);
    let d = ReconstructParams::default();
    assert_eq!(
        (p.error, p.max_levels, p.max_grid_depth, p.trim),
        (d.tree.error, d.max_levels, d.max_grid_depth, d.trim)
    );
    let n = vstree_normal_params_default();
    assert_eq!(n.struct_size as usize, std::mem::size_of::<vstree_normal_params>());
    assert_eq!((n.neighbours as usize, n.orient, n.reorient_given), (NormalParams::default().neighbours, 3, 0));
}

#[test]
fn estimate_normals_through_the_abi_equals_ensure_normals() {
    let bare = torus_cloud(false);
    let h = handle(&bare);
    for orient in 0..4 {
        let mut p = vstree_normal_params_default();
        p.orient = orient;
        p.neighbours = 12;
        let mut out = null_mut();
        let mut report = vstree_normals_report {
            struct_size: std::mem::size_of::<vstree_normals_report>() as u32,
            ..Default::default()
        };
        let status = unsafe { vstree_estimate_normals(h, &p, None, null_mut(), &mut out, &mut report) };
        assert_eq!(status, vstree_status::Ok, "{}", last_error());
        let got = read_back(out);
        unsafe { vstree_mesh_free(out) };
        let mut expected = bare.clone();
        let orientation = [
            Orientation::Unoriented,
            Orientation::Propagate,
            Orientation::PropagateMajority,
            Orientation::PropagateOutward,
        ][orient as usize];
        let params = NormalParams { neighbours: 12, orient: orientation, ..NormalParams::default() };
        let r = ensure_normals(&mut expected, &params, &mut Progress::none()).unwrap();
        assert_eq!(got, expected, "orient {orient}");
        assert_eq!(report.estimated as usize, bare.positions.len());
        assert_eq!(report.neighbours, 12);
        assert_eq!(report.oriented == 1, r.orient.is_some());
        assert_eq!(report.flipped as usize, r.orient.map_or(0, |o| o.flipped));
        assert_eq!(report.struct_size as usize, std::mem::size_of::<vstree_normals_report>());
    }
    // The input handle is unchanged (handles are immutable) and NULL report / params are fine.
    assert_eq!(unsafe { vstree_mesh_has_normals(h) }, 0);
    let mut out = null_mut();
    assert_eq!(
        unsafe { vstree_estimate_normals(h, null(), None, null_mut(), &mut out, null_mut()) },
        vstree_status::Ok
    );
    assert_eq!(unsafe { vstree_mesh_has_normals(out) }, 1);
    unsafe { vstree_mesh_free(out) };
    unsafe { vstree_mesh_free(h) };

    // Outward normals of a closed torus: given ones are kept by default, re-oriented on request.
    let mut flipped = torus_cloud(true);
    for n in flipped.normals.as_mut().unwrap().iter_mut().step_by(3) {
        *n = -*n;
    }
    let h = handle(&flipped);
    let mut p = vstree_normal_params_default();
    let mut out = null_mut();
    assert_eq!(unsafe { vstree_estimate_normals(h, &p, None, null_mut(), &mut out, null_mut()) }, vstree_status::Ok);
    assert_eq!(read_back(out), flipped, "kept as given");
    unsafe { vstree_mesh_free(out) };
    p.reorient_given = 1;
    let mut report = vstree_normals_report { struct_size: 4096, ..Default::default() };
    assert_eq!(unsafe { vstree_estimate_normals(h, &p, None, null_mut(), &mut out, &mut report) }, vstree_status::Ok);
    assert_eq!(report.struct_size as usize, std::mem::size_of::<vstree_normals_report>(), "a larger caller struct");
    assert!(report.oriented == 1 && report.estimated == 0 && report.flipped > 0);
    let fixed = read_back(out);
    let truth = torus_cloud(true);
    let agree = fixed.normals.unwrap().iter().zip(truth.normals.unwrap()).filter(|(a, b)| a.dot(*b) > 0.0).count();
    assert!(agree > truth.positions.len() * 99 / 100, "{agree} of {} outward", truth.positions.len());
    unsafe { vstree_mesh_free(out) };
    unsafe { vstree_mesh_free(h) };
}

struct Stopper {
    calls: usize,
    stop_at: Option<usize>,
    last: f32,
}

unsafe extern "C" fn stop_cb(user_data: *mut c_void, fraction: f32, stage: *const c_char) -> i32 {
    let s = unsafe { &mut *user_data.cast::<Stopper>() };
    assert!(fraction >= s.last && fraction <= 1.0 && !stage.is_null());
    s.last = fraction;
    let go_on = Some(s.calls) != s.stop_at;
    s.calls += 1;
    i32::from(go_on)
}

/// Runs `call` once in full, then cancelled at each of its progress reports in turn.
fn cancel_at_every_report(name: &str, call: impl Fn(&mut Stopper) -> (vstree_status, bool)) {
    let mut full = Stopper { calls: 0, stop_at: None, last: 0.0 };
    let (status, _) = call(&mut full);
    assert_eq!(status, vstree_status::Ok, "{}", last_error());
    assert!(full.calls >= 3 && full.last == 1.0, "{name}: {} reports", full.calls);
    for k in 0..full.calls {
        let mut s = Stopper { calls: 0, stop_at: Some(k), last: 0.0 };
        let (status, untouched) = call(&mut s);
        assert_eq!(status, vstree_status::Cancelled, "{name} at {k}");
        assert!(untouched, "{name} at {k}: an output was written");
        assert_eq!(s.calls, k + 1, "{name}: a report after the stop");
        assert!(last_error().contains("cancel"), "{}", last_error());
    }
    eprintln!("{name}: cancelled at each of its {} progress reports", full.calls);
}

#[test]
fn cancel_at_every_progress_report_writes_nothing() {
    let cloud = torus_cloud(false);
    let h = handle(&cloud);
    let (p, _) = quick();
    let sentinel = 0x10 as *mut vstree_reconstruct_result;
    cancel_at_every_report("vstree_reconstruct", |s| {
        let mut out = sentinel;
        let status = unsafe { vstree_reconstruct(h, &p, Some(stop_cb), (s as *mut Stopper).cast(), &mut out) };
        if status == vstree_status::Ok {
            unsafe { vstree_reconstruct_result_free(out) };
        }
        (status, out == sentinel)
    });
    let sentinel = 0x10 as *mut vstree_mesh;
    cancel_at_every_report("vstree_estimate_normals", |s| {
        let mut out = sentinel;
        let mut report = vstree_normals_report { struct_size: 64, estimated: 77, ..Default::default() };
        let status = unsafe {
            vstree_estimate_normals(h, null(), Some(stop_cb), (s as *mut Stopper).cast(), &mut out, &mut report)
        };
        let untouched = out == sentinel && report.estimated == 77;
        if status == vstree_status::Ok {
            unsafe { vstree_mesh_free(out) };
        }
        (status, untouched)
    });
    unsafe { vstree_mesh_free(h) };
}

#[test]
fn bad_parameters_are_refused_by_name() {
    let cloud = torus_cloud(true);
    let h = handle(&cloud);
    type Spoil = fn(&mut vstree_reconstruct_params);
    let cases: [(&str, vstree_status, Spoil); 22] = [
        ("`orient`", vstree_status::InvalidParameter, |p| p.orient = -1),
        ("`orient`", vstree_status::InvalidParameter, |p| p.orient = 4),
        ("`error`", vstree_status::InvalidParameter, |p| p.error = 0.0),
        ("`error`", vstree_status::InvalidParameter, |p| p.error = f64::NAN),
        ("`error`", vstree_status::InvalidParameter, |p| p.error = f64::INFINITY),
        ("`d_a`", vstree_status::InvalidParameter, |p| p.d_a = -0.5),
        ("`d_d`", vstree_status::InvalidParameter, |p| p.d_d = f32::NAN),
        ("`max_depth`", vstree_status::InvalidParameter, |p| p.max_depth = 31),
        ("`max_levels`", vstree_status::InvalidParameter, |p| p.max_levels = 13),
        ("`min_cell_size`", vstree_status::InvalidParameter, |p| p.min_cell_size = -1.0),
        ("`target_distance`", vstree_status::InvalidParameter, |p| p.target_distance = f64::NAN),
        ("`min_displaced`", vstree_status::InvalidParameter, |p| p.min_displaced = 1.5),
        ("`max_triangles`", vstree_status::InvalidParameter, |p| p.max_triangles = 0),
        ("`max_grid_depth`", vstree_status::InvalidParameter, |p| p.max_grid_depth = 3),
        ("`max_grid_depth`", vstree_status::InvalidParameter, |p| p.max_grid_depth = 21),
        ("`trim`", vstree_status::InvalidParameter, |p| p.trim = f32::INFINITY),
        ("`neighbours`", vstree_status::InvalidParameter, |p| p.neighbours = 2),
        ("`reorient_given`", vstree_status::InvalidParameter, |p| p.reorient_given = 2),
        ("`threads`", vstree_status::InvalidParameter, |p| p.threads = 1025),
        ("params->struct_size", vstree_status::InvalidArgument, |p| p.struct_size = 0),
        ("params->struct_size", vstree_status::InvalidArgument, |p| p.struct_size = 79),
        ("newer vstree.h", vstree_status::InvalidArgument, |p| p.struct_size = 4096),
    ];
    let sentinel = 0x10 as *mut vstree_reconstruct_result;
    for (needle, expected, spoil) in cases {
        let mut p = vstree_reconstruct_params_default();
        spoil(&mut p);
        let mut out = sentinel;
        let status = unsafe { vstree_reconstruct(h, &p, None, null_mut(), &mut out) };
        assert_eq!(status, expected, "{needle}: {}", last_error());
        assert!(last_error().starts_with("vstree_reconstruct: ") && last_error().contains(needle), "{}", last_error());
        assert_eq!(out, sentinel);
    }
    type SpoilN = fn(&mut vstree_normal_params);
    let cases: [(&str, vstree_status, SpoilN); 8] = [
        ("`orient`", vstree_status::InvalidParameter, |p| p.orient = 99),
        ("`neighbours`", vstree_status::InvalidParameter, |p| p.neighbours = 0),
        ("`neighbours`", vstree_status::InvalidParameter, |p| p.neighbours = 257),
        ("`reorient_given`", vstree_status::InvalidParameter, |p| p.reorient_given = u32::MAX),
        ("`threads`", vstree_status::InvalidParameter, |p| p.threads = u32::MAX),
        ("params->struct_size", vstree_status::InvalidArgument, |p| p.struct_size = 4),
        ("params->struct_size", vstree_status::InvalidArgument, |p| p.struct_size = 19),
        ("newer vstree.h", vstree_status::InvalidArgument, |p| p.struct_size = 21),
    ];
    let sentinel = 0x10 as *mut vstree_mesh;
    for (needle, expected, spoil) in cases {
        let mut p = vstree_normal_params_default();
        spoil(&mut p);
        let mut out = sentinel;
        let status = unsafe { vstree_estimate_normals(h, &p, None, null_mut(), &mut out, null_mut()) };
        assert_eq!(status, expected, "{needle}: {}", last_error());
        assert!(
            last_error().starts_with("vstree_estimate_normals: ") && last_error().contains(needle),
            "{}",
            last_error()
        );
        assert_eq!(out, sentinel);
    }
    unsafe { vstree_mesh_free(h) };
}

#[test]
fn bad_input_gives_statuses() {
    let sentinel_r = 0x10 as *mut vstree_reconstruct_result;
    let sentinel_m = 0x10 as *mut vstree_mesh;
    let mut r = sentinel_r;
    let mut m = sentinel_m;
    let cloud = torus_cloud(false);
    let h = handle(&cloud);
    unsafe {
        assert_eq!(vstree_reconstruct(h, null(), None, null_mut(), null_mut()), vstree_status::NullPointer);
        assert!(last_error().contains("`out_result`"));
        assert_eq!(vstree_reconstruct(null(), null(), None, null_mut(), &mut r), vstree_status::NullPointer);
        assert!(last_error().contains("`cloud`"));
        assert_eq!(
            vstree_estimate_normals(h, null(), None, null_mut(), null_mut(), null_mut()),
            vstree_status::NullPointer
        );
        assert!(last_error().contains("`out_mesh`"));
        assert_eq!(
            vstree_estimate_normals(null(), null(), None, null_mut(), &mut m, null_mut()),
            vstree_status::NullPointer
        );
        assert!(last_error().contains("`mesh`"));
        let mut report = vstree_normals_report { struct_size: 8, ..Default::default() };
        assert_eq!(
            vstree_estimate_normals(h, null(), None, null_mut(), &mut m, &mut report),
            vstree_status::InvalidArgument
        );
        assert!(last_error().contains("out_report->struct_size"), "{}", last_error());
        assert_eq!(report.struct_size, 8);

        // Too few points; all points on a line.
        let few = Mesh::from_points(cloud.positions[..5].to_vec(), None);
        let hf = handle(&few);
        assert_eq!(vstree_reconstruct(hf, null(), None, null_mut(), &mut r), vstree_status::InvalidInput);
        assert!(last_error().contains("5 points"), "{}", last_error());
        vstree_mesh_free(hf);
        let two = Mesh::from_points(cloud.positions[..2].to_vec(), None);
        let h2 = handle(&two);
        assert_eq!(
            vstree_estimate_normals(h2, null(), None, null_mut(), &mut m, null_mut()),
            vstree_status::InvalidInput
        );
        vstree_mesh_free(h2);
        let line = Mesh::from_points((0..50).map(|i| glam::Vec3::new(i as f32, 0.0, 0.0)).collect(), None);
        let hl = handle(&line);
        assert_eq!(
            vstree_estimate_normals(hl, null(), None, null_mut(), &mut m, null_mut()),
            vstree_status::InvalidInput
        );
        assert_eq!(vstree_reconstruct(hl, null(), None, null_mut(), &mut r), vstree_status::InvalidInput);
        vstree_mesh_free(hl);

        assert!(vstree_reconstruct_result_get_mesh(null()).is_null());
        assert!(vstree_reconstruct_result_get_stats(null()).is_null());
        vstree_reconstruct_result_free(null_mut());
        assert_eq!(vstree_reconstruct_result_take_mesh(null_mut(), &mut m), vstree_status::NullPointer);
        assert!(last_error().contains("`result`"));
        vstree_mesh_free(h);
    }
    assert_eq!((r, m), (sentinel_r, sentinel_m));
}
