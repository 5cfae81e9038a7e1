//! Clustering simplification: distance to the input within the bound, orientation kept,
//! no collapsed or repeated triangles, works on real and non-manifold models.

mod common;

use glam::Vec3;
use std::collections::HashSet;
use vstree::eval::distance::{one_sided, Target};
use vstree::simplify::{simplify, SimplifyParams};
use vstree::tree::{Metric, TreeKind, TreeParams};
use vstree::{eval::shapes, Mesh, MeshSampling, Progress};

fn run(
    mesh: &Mesh,
    kind: TreeKind,
    error: f64,
    sampling: MeshSampling,
    threads: usize,
) -> (Mesh, vstree::SimplifyStats) {
    let params = SimplifyParams {
        tree: TreeParams { kind, error, ..TreeParams::default() },
        sampling,
        threads,
        keep_topology: vstree::KeepTopology::Off,
        target_faces: 0,
    };
    simplify(mesh, &params, &mut Progress::none()).unwrap()
}

/// No triangle repeats a vertex, and no two triangles use the same three vertices.
fn assert_clean(out: &Mesh) {
    let mut seen = HashSet::new();
    for t in &out.triangles {
        assert!(t[0] != t[1] && t[1] != t[2] && t[0] != t[2], "collapsed triangle {t:?}");
        let mut key = *t;
        key.sort_unstable();
        assert!(seen.insert(key), "repeated triangle {t:?}");
        assert!(t.iter().all(|&i| (i as usize) < out.positions.len()));
    }
    // Every output vertex is used.
    let used: HashSet<u32> = out.triangles.iter().flatten().copied().collect();
    assert_eq!(used.len(), out.positions.len());
}

/// Checks the simplified mesh's one-sided distance to the input against the L2 bound: every
/// sample's tangent plane passes within √e · diagonal of its cluster's point.
fn assert_within_bound(name: &str, input: &Mesh, out: &Mesh, error: f64) {
    let diagonal = input.bounds().unwrap().diagonal();
    let bound = (error.sqrt() as f32) * diagonal;
    let vertices = one_sided(&out.positions, Target::of(input));
    let surface = one_sided(&shapes::sample_surface(out, 50_000, 1).positions, Target::of(input));
    eprintln!(
        "{name} e={error}: vertices max {:.3} mean {:.3}; surface mean {:.3} p99 {:.3} max {:.3} (x bound)",
        vertices.max / bound,
        vertices.mean / bound,
        surface.mean / bound,
        surface.p99 / bound,
        surface.max / bound
    );
    assert!(vertices.max <= bound, "{name}: a vertex is {} from the input (bound {bound})", vertices.max);
    assert!(surface.mean <= 0.5 * bound, "{name}: mean surface distance {} (bound {bound})", surface.mean);
    assert!(surface.p99 <= 2.0 * bound, "{name}: 99th percentile {} (bound {bound})", surface.p99);
}

#[test]
fn sphere_simplifies_within_the_bound_keeping_orientation() {
    let sphere = shapes::icosphere(1.0, 6);
    for kind in [TreeKind::VsTree, TreeKind::Octree] {
        for error in [1e-5, 1e-4, 2e-3] {
            let (out, stats) = run(&sphere, kind, error, MeshSampling::Vertices, 0);
            assert_clean(&out);
            assert!(
                out.positions.len() < sphere.positions.len() / 4,
                "{kind:?} {error}: {} vertices",
                out.positions.len()
            );
            assert_eq!(stats.output_vertices, out.positions.len());
            assert_within_bound("sphere", &sphere, &out, error);
            let volume = vstree::eval::figures::signed_volume(&out);
            let expected = vstree::eval::figures::signed_volume(&sphere);
            assert!(volume > 0.9 * expected, "{kind:?} {error}: volume {volume} vs {expected}: orientation lost?");
        }
    }
}

#[test]
fn real_models_simplify_within_the_bound() {
    for name in ["bunny_zipper.ply", "igea.ply", "armadillo_43k.obj", "happy_buddha_100k.obj", "fandisk.off"] {
        let Some(mesh) = common::load(name) else {
            continue;
        };
        for error in [1e-4, 2e-3] {
            let (out, _) = run(&mesh, TreeKind::VsTree, error, MeshSampling::Vertices, 0);
            assert_clean(&out);
            assert!(out.triangles.len() < mesh.triangles.len() / 2, "{name}: {} triangles", out.triangles.len());
            assert_within_bound(name, &mesh, &out, error);
        }
    }
}

#[test]
fn face_centre_samples_give_a_clean_mesh_within_the_bound() {
    let torus = shapes::torus(1.0, 0.3, 128, 64);
    let (out, stats) = run(&torus, TreeKind::VsTree, 1e-4, MeshSampling::FaceCenters, 0);
    assert_eq!(stats.tree.samples, torus.triangles.len());
    assert_clean(&out);
    assert_within_bound("torus (faces)", &torus, &out, 1e-4);
}

#[test]
fn a_point_cloud_simplifies_to_one_point_per_cluster() {
    let cloud = shapes::sample_surface(&shapes::icosphere(1.0, 4), 20_000, 5);
    let (out, stats) = run(&cloud, TreeKind::VsTree, 1e-4, MeshSampling::Vertices, 0);
    assert!(out.triangles.is_empty());
    assert_eq!(out.positions.len(), stats.tree.leaves);
    let normals = out.normals.as_ref().unwrap();
    for (p, n) in out.positions.iter().zip(normals) {
        assert!((p.length() - 1.0).abs() < 0.02, "point {p} off the sphere");
        assert!(n.dot(p.normalize()) > 0.9, "normal {n} not outward at {p}");
    }
}

#[test]
fn same_output_with_one_or_two_threads() {
    let mesh = shapes::bumpy_sphere(1.0, 0.1, 5.0, 6);
    let a = run(&mesh, TreeKind::VsTree, 1e-5, MeshSampling::Vertices, 1).0;
    let b = run(&mesh, TreeKind::VsTree, 1e-5, MeshSampling::Vertices, 2).0;
    assert_eq!(a, b);
}

#[test]
fn non_manifold_input_is_fine() {
    // Three triangles on one edge, plus a repeated triangle with the opposite winding.
    let mesh = Mesh::new(
        vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z, -Vec3::Y],
        None,
        vec![[0, 1, 2], [0, 1, 3], [1, 0, 4], [2, 1, 0]],
    );
    // (All these faces' planes contain the x axis, so under L2 one cluster would represent
    // them exactly; one sample per cluster keeps every vertex.)
    let params = SimplifyParams {
        tree: TreeParams { metric: Metric::Density, error: 1.0, ..TreeParams::default() },
        ..Default::default()
    };
    let (out, _) = simplify(&mesh, &params, &mut Progress::none()).unwrap();
    assert_clean(&out);
    assert_eq!(out.triangles.len(), 3, "the repeat is dropped, the rest kept: {:?}", out.triangles);
    let first = out.triangles[0].map(|i| out.positions[i as usize]);
    assert_eq!(first, [0, 1, 2].map(|i| mesh.positions[i]), "the first of a repeated pair keeps its winding");
}
