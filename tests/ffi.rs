//! The C ABI called from Rust: results equal to the Rust API's, labels consistent with the
//! tree, cancellation at every progress report, concurrency, and randomized bad input that must
//! give a status (never a panic or abort). The C and Python suites test the same boundary from
//! the host languages.

use std::ffi::{c_char, c_void, CStr, CString};
use std::ptr::{null, null_mut};
use vstree::ffi::mesh::*;
use vstree::ffi::simplify::*;
use vstree::ffi::tree::*;
use vstree::ffi::*;
use vstree::rng::Rng;
use vstree::simplify::{simplify, SimplifyParams};
use vstree::{eval::shapes, Mesh, Progress};

mod common;
use common::ffi::{handle, last_error, read_back};

fn ffi_simplify(mesh: *const vstree_mesh, params: &vstree_simplify_params) -> (Mesh, vstree_simplify_stats) {
    let mut result = null_mut();
    let status = unsafe { vstree_simplify(mesh, params, None, null_mut(), &mut result) };
    assert_eq!(status, vstree_status::Ok, "{}", last_error());
    let out = read_back(unsafe { vstree_simplify_result_get_mesh(result) });
    let stats = unsafe { *vstree_simplify_result_get_stats(result) };
    unsafe { vstree_simplify_result_free(result) };
    (out, stats)
}

#[test]
fn simplify_through_the_abi_equals_the_rust_call() {
    let sphere = shapes::bumpy_sphere(1.0, 0.1, 5.0, 4);
    let h = handle(&sphere);
    for (metric, error, sampling) in [(0, 1e-3, 0), (1, 0.05, 0), (2, 20.0, 1)] {
        let mut p = vstree_simplify_params_default();
        p.metric = metric;
        p.error = error;
        p.sampling = sampling;
        let (out, stats) = ffi_simplify(h, &p);
        let rust_params = SimplifyParams {
            tree: vstree::TreeParams {
                metric: [vstree::Metric::L2, vstree::Metric::L21, vstree::Metric::Density][metric as usize],
                error,
                ..Default::default()
            },
            sampling: [vstree::MeshSampling::Vertices, vstree::MeshSampling::FaceCenters][sampling as usize],
            threads: 0,
            ..Default::default()
        };
        let (expected, s) = simplify(&sphere, &rust_params, &mut Progress::none()).unwrap();
        assert_eq!(out, expected);
        assert_eq!(stats.output_vertices as usize, expected.positions.len());
        assert_eq!(stats.clusters as usize, s.tree.leaves);
        assert_eq!(stats.t_nodes as usize, s.tree.t_nodes);
        assert_eq!(stats.struct_size as usize, std::mem::size_of::<vstree_simplify_stats>());
        assert!(stats.seconds_total >= stats.seconds_tree);
    }
    unsafe { vstree_mesh_free(h) };
}

#[test]
fn point_clouds_simplify_to_points_with_normals() {
    let cloud = shapes::sample_surface(&shapes::icosphere(1.0, 3), 5000, 3);
    assert!(cloud.normals.is_some());
    let h = handle(&cloud);
    let (out, stats) = ffi_simplify(h, &vstree_simplify_params_default());
    assert!(out.triangles.is_empty() && out.normals.is_some());
    assert_eq!(stats.output_vertices, stats.clusters);
    unsafe { vstree_mesh_free(h) };
}

#[test]
fn tree_labels_nodes_and_t_layer_agree() {
    let torus = shapes::torus(1.0, 0.3, 96, 32);
    let h = handle(&torus);
    let mut tree = null_mut();
    let p = vstree_simplify_params_default();
    let status = unsafe { vstree_tree_build(h, &p, None, null_mut(), &mut tree) };
    assert_eq!(status, vstree_status::Ok, "{}", last_error());
    let stats = unsafe { *vstree_tree_get_stats(tree) };
    let n = unsafe { vstree_tree_node_count(tree) };
    let t = unsafe { vstree_tree_t_node_count(tree) };
    let levels_n = unsafe { vstree_tree_level_count(tree) };
    assert_eq!(n as u64, stats.nodes);
    assert_eq!(t as u64, stats.t_nodes);
    assert_eq!(levels_n, stats.max_depth as usize + 1);
    assert!(stats.t_nodes > 0, "a torus gets a T-layer");
    assert!(stats.max_cluster_error <= p.error * 1.0001, "{}", stats.max_cluster_error);
    assert!(stats.mean_cluster_error <= stats.max_cluster_error);

    let zero_node = vstree_node {
        parent: 0,
        first_child: 0,
        child_count: 0,
        kind: 0,
        depth: 0,
        sample_count: 0,
        t_node: 0,
        cluster: 0,
        center: [0.0; 3],
        half: 0.0,
    };
    let mut nodes = vec![zero_node; n];
    let mut levels = vec![vstree_tree_level::default(); levels_n];
    let mut labels = vec![0u32; torus.positions.len()];
    let mut t_labels = vec![0u32; torus.positions.len()];
    let mut t_nodes: Vec<vstree_t_node> = Vec::with_capacity(t);
    unsafe {
        assert_eq!(vstree_tree_copy_nodes(tree, nodes.as_mut_ptr(), n), vstree_status::Ok);
        assert_eq!(vstree_tree_copy_levels(tree, levels.as_mut_ptr(), levels_n), vstree_status::Ok);
        assert_eq!(vstree_tree_copy_t_nodes(tree, t_nodes.as_mut_ptr(), t), vstree_status::Ok);
        t_nodes.set_len(t);
        assert_eq!(vstree_tree_copy_vertex_labels(tree, 0, labels.as_mut_ptr(), labels.len()), vstree_status::Ok);
        assert_eq!(vstree_tree_copy_vertex_labels(tree, 1, t_labels.as_mut_ptr(), t_labels.len()), vstree_status::Ok);
    }
    // Level counts sum to the kind counts; leaves are the clusters.
    let sum = |f: fn(&vstree_tree_level) -> u64| levels.iter().map(f).sum::<u64>();
    assert_eq!(sum(|l| l.v_nodes), stats.v_nodes);
    assert_eq!(sum(|l| l.t_nodes), stats.t_nodes);
    assert_eq!(sum(|l| l.s_nodes), stats.s_nodes);
    assert_eq!(sum(|l| l.leaves), stats.clusters);
    // Every leaf has a cluster, clusters are numbered in node order, T-nodes point at themselves.
    let leaf_clusters: Vec<u32> = nodes.iter().filter(|n| n.child_count == 0).map(|n| n.cluster).collect();
    assert_eq!(leaf_clusters, (0..stats.clusters as u32).collect::<Vec<_>>());
    for (k, tn) in t_nodes.iter().enumerate() {
        let node = &nodes[tn.node as usize];
        assert_eq!(node.kind, vstree_node_kind::Transition as i32);
        assert_eq!(node.t_node, k as u32);
        assert!((glam::Vec3::from(tn.normal).length() - 1.0).abs() < 1e-4);
        assert!(glam::Vec3::from(tn.u).dot(glam::Vec3::from(tn.normal)).abs() < 1e-4);
    }
    let clusters_in_t: u64 = t_nodes.iter().map(|t| u64::from(t.cluster_count)).sum();
    assert!(clusters_in_t <= stats.clusters);
    // A vertex's T-node label is the T-node of its cluster's leaf.
    for (v, (&c, &tl)) in labels.iter().zip(&t_labels).enumerate() {
        assert!(c < stats.clusters as u32, "vertex {v} has no cluster");
        let leaf = nodes.iter().find(|n| n.child_count == 0 && n.cluster == c).unwrap();
        assert_eq!(leaf.t_node, tl);
    }
    // The clusters are the simplification's: as many distinct labels as clusters used.
    let (out, _) = ffi_simplify(h, &p);
    let mut distinct = labels.clone();
    distinct.sort_unstable();
    distinct.dedup();
    assert!(out.positions.len() <= distinct.len());
    unsafe {
        vstree_tree_free(tree);
        vstree_mesh_free(h);
    }
}

/// Counts progress reports, and stops at report `stop_at` (never if `None`).
struct Stopper {
    calls: usize,
    stop_at: Option<usize>,
    last_fraction: f32,
    stages: Vec<String>,
}

unsafe extern "C" fn stopper(user: *mut c_void, fraction: f32, stage: *const c_char) -> i32 {
    let s = &mut *(user as *mut Stopper);
    assert!(fraction >= s.last_fraction && (0.0..=1.0).contains(&fraction));
    s.last_fraction = fraction;
    s.stages.push(CStr::from_ptr(stage).to_string_lossy().into_owned());
    let go_on = Some(s.calls) != s.stop_at;
    s.calls += 1;
    i32::from(go_on)
}

#[test]
fn cancelling_at_every_report_frees_everything_and_writes_nothing() {
    let mesh = shapes::icosphere(1.0, 5);
    let h = handle(&mesh);
    let p = vstree_simplify_params_default();
    type Call = unsafe fn(*const vstree_mesh, &vstree_simplify_params, *mut Stopper) -> (vstree_status, bool);
    unsafe fn simplify_call(
        h: *const vstree_mesh,
        p: &vstree_simplify_params,
        s: *mut Stopper,
    ) -> (vstree_status, bool) {
        let sentinel = 0x5 as *mut vstree_simplify_result;
        let mut out = sentinel;
        let status = vstree_simplify(h, p, Some(stopper), s.cast(), &mut out);
        let untouched = out == sentinel;
        if status == vstree_status::Ok {
            vstree_simplify_result_free(out);
        }
        (status, untouched)
    }
    unsafe fn tree_call(h: *const vstree_mesh, p: &vstree_simplify_params, s: *mut Stopper) -> (vstree_status, bool) {
        let sentinel = 0x5 as *mut vstree_tree;
        let mut out = sentinel;
        let status = vstree_tree_build(h, p, Some(stopper), s.cast(), &mut out);
        let untouched = out == sentinel;
        if status == vstree_status::Ok {
            vstree_tree_free(out);
        }
        (status, untouched)
    }
    for (name, call) in [("simplify", simplify_call as Call), ("tree", tree_call as Call)] {
        let mut full = Stopper { calls: 0, stop_at: None, last_fraction: 0.0, stages: vec![] };
        let (status, _) = unsafe { call(h, &p, &mut full) };
        assert_eq!(status, vstree_status::Ok);
        assert!(full.calls >= 3, "{name}: {} reports", full.calls);
        assert_eq!(full.stages.last().map(String::as_str), Some("done"));
        assert_eq!(full.last_fraction, 1.0);
        for k in 0..full.calls {
            let mut s = Stopper { calls: 0, stop_at: Some(k), last_fraction: 0.0, stages: vec![] };
            let (status, untouched) = unsafe { call(h, &p, &mut s) };
            assert_eq!(status, vstree_status::Cancelled, "{name}: stop at report {k}");
            assert!(untouched, "{name}: output written after cancel at {k}");
            assert_eq!(s.calls, k + 1, "{name}: reports after the stop");
            assert!(last_error().contains("cancelled"));
        }
    }
    unsafe { vstree_mesh_free(h) };
}

#[test]
fn threads_simplifying_different_meshes_get_the_single_threaded_results() {
    let meshes: Vec<Mesh> =
        (0..4).map(|i| shapes::bumpy_sphere(1.0, 0.05 * (i + 1) as f32, 4.0 + i as f32, 4)).collect();
    let handles: Vec<usize> = meshes.iter().map(|m| handle(m) as usize).collect();
    let mut one = vstree_simplify_params_default();
    one.threads = 1;
    let expected: Vec<Mesh> = handles.iter().map(|&h| ffi_simplify(h as *const _, &one).0).collect();
    let p = vstree_simplify_params_default();
    std::thread::scope(|scope| {
        let workers: Vec<_> = handles
            .iter()
            .map(|&h| scope.spawn(move || (0..3).map(|_| ffi_simplify(h as *const _, &p).0).collect::<Vec<_>>()))
            .collect();
        for (w, e) in workers.into_iter().zip(&expected) {
            for out in w.join().unwrap() {
                assert_eq!(&out, e);
            }
        }
    });
    for h in handles {
        unsafe { vstree_mesh_free(h as *mut _) };
    }
}

#[test]
fn load_save_and_memory_round_trip() {
    let dir = std::env::temp_dir().join(format!("vstree-ffi-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mesh = shapes::icosphere(1.0, 2);
    let h = handle(&mesh);
    for (name, flags) in [("a.ply", 0), ("b.ply", VSTREE_SAVE_ASCII), ("c.obj", 0), ("d.off", 0)] {
        let path = CString::new(dir.join(name).to_str().unwrap()).unwrap();
        assert_eq!(unsafe { vstree_mesh_save(h, path.as_ptr(), flags) }, vstree_status::Ok, "{}", last_error());
        let mut loaded = null_mut();
        assert_eq!(unsafe { vstree_mesh_load(path.as_ptr(), &mut loaded) }, vstree_status::Ok);
        let back = read_back(loaded);
        assert_eq!(back.triangles.len(), mesh.triangles.len(), "{name}");
        assert_eq!(back.positions.len(), mesh.positions.len(), "{name}");
        if !name.ends_with(".obj") {
            // OBJ readers may renumber vertices; the others keep the order.
            assert_eq!(back.triangles, mesh.triangles, "{name}");
        }
        let bytes = std::fs::read(dir.join(name)).unwrap();
        let mut parsed = null_mut();
        let ext = CString::new(name.rsplit('.').next().unwrap()).unwrap();
        let status = unsafe { vstree_mesh_load_memory(bytes.as_ptr().cast(), bytes.len(), ext.as_ptr(), &mut parsed) };
        assert_eq!(status, vstree_status::Ok, "{}", last_error());
        assert_eq!(read_back(parsed), back);
        unsafe {
            vstree_mesh_free(loaded);
            vstree_mesh_free(parsed);
        }
    }
    let missing = CString::new(dir.join("missing.ply").to_str().unwrap()).unwrap();
    let mut out = null_mut();
    assert_eq!(unsafe { vstree_mesh_load(missing.as_ptr(), &mut out) }, vstree_status::Io);
    assert!(last_error().contains("missing.ply"));
    let bad = CString::new(dir.join("x.stl").to_str().unwrap()).unwrap();
    assert_eq!(unsafe { vstree_mesh_save(h, bad.as_ptr(), 0) }, vstree_status::UnsupportedFormat);
    let garbage = b"ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nend_header\n1\n";
    let status =
        unsafe { vstree_mesh_load_memory(garbage.as_ptr().cast(), garbage.len(), c"g.ply".as_ptr(), &mut out) };
    assert_eq!(status, vstree_status::Parse);
    assert!(out.is_null());
    unsafe { vstree_mesh_free(h) };
    std::fs::remove_dir_all(dir).unwrap();
}

/// Random counts, pointers and values: every call returns a status, and only `Ok` when the
/// input was valid.
#[test]
fn random_bad_input_gives_statuses_never_panics() {
    let mut rng = Rng::new(7);
    let pool: Vec<f32> = (0..3000).map(|i| (i % 17) as f32 * 0.1).collect();
    let mut ok = 0;
    for _ in 0..2000 {
        let mut positions = pool.clone();
        let n = (rng.next_u64() % 1001) as usize;
        let t = (rng.next_u64() % 1001) as usize;
        let spoil = rng.next_u64() % 6;
        match spoil {
            0 if n > 0 => positions[(rng.next_u64() as usize) % (3 * n)] = f32::NAN,
            1 if n > 0 => positions[(rng.next_u64() as usize) % (3 * n)] = f32::INFINITY,
            _ => {}
        }
        let mut tris: Vec<u32> = (0..3 * t).map(|_| (rng.next_u64() % n.max(1) as u64) as u32).collect();
        if spoil == 2 && t > 0 {
            tris[(rng.next_u64() as usize) % (3 * t)] = (rng.next_u64() % 5000) as u32;
        }
        let mut mesh = null_mut();
        let status = unsafe { vstree_mesh_create(positions.as_ptr(), n, null(), tris.as_ptr(), t, &mut mesh) };
        let valid = n > 0
            && positions[..3 * n].iter().all(|x| x.is_finite())
            && tris[..3 * t].iter().all(|&i| (i as usize) < n);
        assert_eq!(status == vstree_status::Ok, valid, "n={n} t={t} spoil={spoil}: {}", last_error());
        if status != vstree_status::Ok {
            assert!(mesh.is_null());
            continue;
        }
        let mut p = vstree_simplify_params_default();
        p.error = [1e-3, 0.0, -1.0, f64::NAN, 1e9][(rng.next_u64() % 5) as usize];
        p.max_depth = (rng.next_u64() % 33) as u32;
        p.threads = [0, 1, 2, 2000][(rng.next_u64() % 4) as usize];
        let mut result = null_mut();
        let status = unsafe { vstree_simplify(mesh, &p, None, null_mut(), &mut result) };
        assert!(
            matches!(status, vstree_status::Ok | vstree_status::InvalidParameter | vstree_status::InvalidInput),
            "{status:?}: {}",
            last_error()
        );
        ok += usize::from(status == vstree_status::Ok);
        unsafe {
            vstree_simplify_result_free(result);
            vstree_mesh_free(mesh);
        }
    }
    assert!(ok > 20, "only {ok} valid runs");
}

#[test]
fn a_ply_file_simplified_through_the_abi_equals_the_rust_call() {
    let scratch = common::scratch::Scratch::new("ffi-stream");
    let path = scratch.0.join("torus.ply");
    vstree::io::write(&path, &shapes::torus(1.0, 0.3, 120, 60)).unwrap();
    let c_path = CString::new(path.to_str().unwrap()).unwrap();
    let mut p = vstree_simplify_params_default();
    p.target_faces = 1000;
    let mut result = null_mut();
    let status = unsafe { vstree_simplify_ply_file(c_path.as_ptr(), &p, None, null_mut(), &mut result) };
    assert_eq!(status, vstree_status::Ok, "{}", last_error());
    let out = read_back(unsafe { vstree_simplify_result_get_mesh(result) });
    let stats = unsafe { *vstree_simplify_result_get_stats(result) };
    unsafe { vstree_simplify_result_free(result) };
    let params = SimplifyParams { target_faces: 1000, ..Default::default() };
    let (expected, _) = vstree::simplify::simplify_ply_streaming(&path, &params, &mut Progress::none()).unwrap();
    assert_eq!(out, expected);
    assert_eq!((stats.input_triangles, stats.output_triangles, stats.kept_topology), (14_400, 1000, 0));
    // What a stream refuses, and null pointers, are statuses with a message; nothing is written.
    p.keep_topology = 1;
    let mut result = null_mut();
    let status = unsafe { vstree_simplify_ply_file(c_path.as_ptr(), &p, None, null_mut(), &mut result) };
    assert_eq!(status, vstree_status::InvalidParameter);
    assert!(last_error().contains("keeping the topology needs the whole mesh"), "{}", last_error());
    assert!(result.is_null());
    let status = unsafe { vstree_simplify_ply_file(null(), &p, None, null_mut(), &mut result) };
    assert_eq!(status, vstree_status::NullPointer);
    let status = unsafe { vstree_simplify_ply_file(c_path.as_ptr(), &p, None, null_mut(), null_mut()) };
    assert_eq!(status, vstree_status::NullPointer);
}
