//! Every bad input gets a clear error (or a correct trivial result), never a panic.

use glam::Vec3;
use vstree::simplify::{simplify, SimplifyParams};
use vstree::tree::{Metric, TreeParams};
use vstree::{Error, Mesh, Progress};

fn simplify_with(mesh: &Mesh, tree: TreeParams) -> vstree::Result<(Mesh, vstree::SimplifyStats)> {
    simplify(mesh, &SimplifyParams { tree, ..Default::default() }, &mut Progress::none())
}

fn simplify_default(mesh: &Mesh) -> vstree::Result<(Mesh, vstree::SimplifyStats)> {
    simplify_with(mesh, TreeParams::default())
}

fn cloud(points: &[Vec3]) -> Mesh {
    Mesh::from_points(points.to_vec(), Some(vec![Vec3::Z; points.len()]))
}

fn message(result: vstree::Result<(Mesh, vstree::SimplifyStats)>) -> String {
    result.expect_err("expected an error").to_string()
}

#[test]
fn empty_inputs_are_refused() {
    assert!(message(simplify_default(&Mesh::default())).contains("no"));
    assert!(message(simplify_default(&cloud(&[]))).contains("no samples"));
}

#[test]
fn one_two_three_samples_give_trivial_results() {
    // One point is kept; two or three distinct ones, within any L2 bound of one plane, would
    // collapse into one: an error naming the bound (see a_cloud_collapsed_into_one_point_...).
    let (out, stats) = simplify_default(&cloud(&[Vec3::ONE])).unwrap();
    assert_eq!((out.positions, stats.tree.samples), (vec![Vec3::ONE], 1));
    for n in 2..=3 {
        let points: Vec<Vec3> = (0..n).map(|i| Vec3::new(i as f32, 0.0, 0.0)).collect();
        let m = message(simplify_default(&cloud(&points)));
        assert!(m.contains(&format!("all {n} points collapsed into one")), "{m}");
        let each = TreeParams { metric: Metric::Density, error: 1.0, ..Default::default() };
        let (out, stats) = simplify_with(&cloud(&points), each).unwrap();
        assert_eq!((out.positions.len(), stats.tree.samples), (n, n));
    }
    let triangle = Mesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::Y], None, vec![[0, 1, 2]]);
    // Flat: one cluster, no triangle left, which is an error rather than an empty mesh.
    let m = message(simplify_default(&triangle));
    assert!(m.contains("every triangle collapsed (1 cluster for the whole model)"), "{m}");
}

#[test]
fn coplanar_and_identical_points_work() {
    // A plane is one cluster under any L2 bound: refused (a_cloud_collapsed_into_one_point_...).
    let plane: Vec<Vec3> = (0..400).map(|i| Vec3::new((i % 20) as f32, (i / 20) as f32, 0.0)).collect();
    assert!(message(simplify_default(&cloud(&plane))).contains("all 400 points collapsed into one"));
    let same = cloud(&[Vec3::splat(3.0); 50]);
    let (out, _) = simplify_default(&same).unwrap();
    assert_eq!(out.positions, vec![Vec3::splat(3.0)]);
    // Identical points with disagreeing normals cannot be split apart: the depth and cell-size
    // guards stop the recursion.
    let mut spiky = same.clone();
    spiky.normals = Some((0..50).map(|i| if i % 2 == 0 { Vec3::Z } else { Vec3::X }).collect());
    let (out, _) = simplify_default(&spiky).unwrap();
    assert_eq!(out.positions.len(), 1);
}

#[test]
fn non_finite_values_are_refused_by_index() {
    let mut bad = cloud(&[Vec3::ZERO, Vec3::X, Vec3::new(f32::NAN, 0.0, 0.0)]);
    assert!(message(simplify_default(&bad)).contains("vertex 2"));
    bad.positions[2] = Vec3::new(0.0, f32::INFINITY, 0.0);
    assert!(message(simplify_default(&bad)).contains("vertex 2"));
    let mut bad_normal = cloud(&[Vec3::ZERO, Vec3::X]);
    bad_normal.normals.as_mut().unwrap()[1] = Vec3::NAN;
    assert!(message(simplify_default(&bad_normal)).contains("normal 1"));
}

#[test]
fn huge_and_tiny_coordinates() {
    // Beyond 1e18 the squares of 32-bit coordinates overflow: refused, naming the vertex.
    let far = |d: f32| cloud(&[Vec3::ZERO, Vec3::X * d, Vec3::Y * d, Vec3::Z * d]);
    let e = message(simplify_default(&far(1e20)));
    assert!(e.contains("vertex 1") && e.contains("rescale"), "{e}");
    // Within range the relative bound still means what it says: four points far apart, three
    // on the plane z = 0 and one above it (all normals +z), stay four clusters on a tight
    // bound. (At 1e-25 the diagonal, once computed in f32, underflowed to zero.)
    for d in [1e17, 1e-25] {
        let tight = TreeParams { error: 1e-9, ..TreeParams::default() };
        let (out, stats) = simplify_with(&far(d), tight).unwrap();
        assert_eq!((stats.tree.leaves, out.positions.len()), (4, 4), "spacing {d}");
    }
}

#[test]
fn normals_that_cancel_out_give_a_cluster_a_unit_normal() {
    // Two sheets facing away from each other in each of two clusters (of at most 2 samples):
    // the mean normal is zero.
    let mut c = cloud(&[Vec3::ZERO, Vec3::X, Vec3::X * 10.0, Vec3::X * 11.0]);
    c.normals = Some(vec![Vec3::Z, -Vec3::Z, Vec3::Z, -Vec3::Z]);
    let pairs = TreeParams { metric: Metric::Density, error: 2.0, ..TreeParams::default() };
    let (out, stats) = simplify_with(&c, pairs).unwrap();
    assert_eq!(stats.tree.leaves, 2);
    let n = out.normals.unwrap()[0];
    assert!((n.length() - 1.0).abs() < 1e-6 && n.z.abs() > 0.999, "{n}");
}

#[test]
fn zero_normals_in_a_cloud_are_refused() {
    let mut c = cloud(&[Vec3::ZERO, Vec3::X]);
    c.normals.as_mut().unwrap()[0] = Vec3::ZERO;
    assert!(message(simplify_default(&c)).contains("point 0"));
    let no_normals = Mesh::from_points(vec![Vec3::ZERO, Vec3::X], None);
    assert!(message(simplify_default(&no_normals)).contains("normals"));
}

#[test]
fn out_of_range_indices_are_refused() {
    let mesh = Mesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::Y], None, vec![[0, 1, 7]]);
    let m = message(simplify_default(&mesh));
    assert!(m.contains("triangle 0") && m.contains('7'), "{m}");
}

#[test]
fn degenerate_triangles_are_ignored() {
    let mesh = Mesh::new(
        vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(2.0, 0.0, 0.0)],
        None,
        vec![[0, 1, 2], [0, 0, 1], [0, 1, 3]],
    );
    // Flat, so every triangle collapses; the degenerate one is no cause of failure.
    assert!(message(simplify_default(&mesh)).contains("every triangle collapsed"));
    let all_degenerate = Mesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::Y], None, vec![[0, 0, 1]]);
    assert!(message(simplify_default(&all_degenerate)).contains("degenerate"));
}

#[test]
fn absurd_parameters_are_refused_by_name() {
    let mesh = cloud(&[Vec3::ZERO, Vec3::X]);
    let cases: Vec<(TreeParams, &str)> = vec![
        (TreeParams { error: 0.0, ..Default::default() }, "error"),
        (TreeParams { error: -1.0, ..Default::default() }, "error"),
        (TreeParams { error: f64::NAN, ..Default::default() }, "error"),
        (TreeParams { error: f64::INFINITY, ..Default::default() }, "error"),
        (TreeParams { metric: Metric::Density, error: 0.5, ..Default::default() }, "error"),
        (TreeParams { d_a: 1.5, ..Default::default() }, "d_a"),
        (TreeParams { d_d: f32::NAN, ..Default::default() }, "d_d"),
        (TreeParams { max_depth: 0, ..Default::default() }, "max_depth"),
        (TreeParams { max_depth: 99, ..Default::default() }, "max_depth"),
        (TreeParams { min_cell_size: -1.0, ..Default::default() }, "min_cell_size"),
    ];
    for (params, name) in cases {
        match simplify_with(&mesh, params) {
            Err(Error::InvalidParameter { name: got, .. }) => assert_eq!(got, name),
            other => panic!("{params:?}: expected an error naming {name}, got {other:?}"),
        }
    }
    let absurd_threads = SimplifyParams { threads: 1 << 20, ..Default::default() };
    assert!(simplify(&mesh, &absurd_threads, &mut Progress::none()).is_err());
}

#[test]
fn cancelling_stops_with_cancelled() {
    let mesh = vstree::eval::shapes::icosphere(1.0, 5);
    let mut stop = |_: f32, _: &str| false;
    let result = simplify(&mesh, &SimplifyParams::default(), &mut Progress::new(&mut stop));
    assert!(matches!(result, Err(Error::Cancelled)));
}

#[test]
fn a_mesh_with_a_non_finite_origin_is_refused() {
    let mut mesh = Mesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::Y], None, vec![[0, 1, 2]]);
    mesh.origin = glam::DVec3::new(f64::NAN, 0.0, 0.0);
    assert!(message(simplify_default(&mesh)).contains("the origin [NaN, 0, 0] is not finite"));
}

#[test]
fn targets_the_input_cannot_give_are_refused_or_give_the_nearest_mesh() {
    let sphere = vstree::eval::shapes::icosphere(1.0, 3); // 1280 triangles
    let with = |mesh: &Mesh, target_faces| {
        simplify(mesh, &SimplifyParams { target_faces, ..Default::default() }, &mut Progress::none())
    };
    // More triangles than the input has: refused, naming the parameter.
    let e = with(&sphere, 1281).unwrap_err();
    assert!(matches!(e, Error::InvalidParameter { name: "target_faces", .. }), "{e}");
    assert!(e.to_string().contains("more than the input's 1280 triangles"), "{e}");
    // A point cloud has no triangles to count.
    let e = with(&cloud(&[Vec3::ZERO, Vec3::X, Vec3::Y]), 10).unwrap_err();
    assert!(e.to_string().contains("a target needs a mesh"), "{e}");
    // The whole input: every triangle kept.
    assert_eq!(with(&sphere, 1280).unwrap().0.triangles.len(), 1280);
    // Below what a closed sphere allows: a tetrahedron, never an empty mesh.
    for target in [1, 2, 3] {
        let (out, _) = with(&sphere, target).unwrap();
        assert_eq!(out.triangles.len(), 4, "target {target}");
    }
    // 0 is the error bound, as without a target.
    assert_eq!(with(&sphere, 0).unwrap().0, simplify_default(&sphere).unwrap().0);
}

/// A cloud simplified into a single point (all its points within the bound of one plane: a
/// flat or 3-point cloud is within any L2 bound) is refused as a mesh whose every triangle
/// collapses is, naming the bound and what splits it; points at one place give that place.
#[test]
fn a_cloud_collapsed_into_one_point_is_refused() {
    let flat: Vec<Vec3> = (0..900).map(|i| Vec3::new((i % 30) as f32, (i / 30) as f32, 0.0)).collect();
    let e = simplify_default(&cloud(&flat)).unwrap_err();
    assert!(matches!(e, Error::InvalidParameter { name: "error", .. }), "{e:?}");
    assert_eq!(
        e.to_string(),
        "parameter `error`: 0.001: all 900 points collapsed into one (1 cluster for the whole model): the \
         model is within this bound of too few planes; use a smaller bound (a flat model, within any bound of one \
         plane, needs the density metric)"
    );
    // The density metric at its default bound splits it.
    let density = TreeParams { metric: Metric::Density, error: Metric::Density.default_error(), ..Default::default() };
    let (out, _) = simplify_with(&cloud(&flat), density).unwrap();
    assert!(out.positions.len() > 900 / 16, "{}", out.positions.len());
    let (out, _) = simplify_default(&cloud(&[Vec3::splat(0.5); 50])).unwrap();
    assert_eq!(out.positions, vec![Vec3::splat(0.5)]);
}

/// A tree made coarse by its depth or cell-size limit, not by its bound, names the limit.
#[test]
fn a_collapse_names_the_limit_that_caused_it() {
    // Two small spheres in opposite corners: each within one octant of the root.
    let mut mesh = vstree::eval::shapes::icosphere(0.1, 2);
    let n = mesh.positions.len() as u32;
    let other: Vec<Vec3> = mesh.positions.iter().map(|p| *p + Vec3::splat(10.0)).collect();
    let triangles: Vec<[u32; 3]> = mesh.triangles.iter().map(|t| t.map(|v| v + n)).collect();
    mesh.positions.extend(other);
    mesh.triangles.extend(triangles);
    mesh.normals = None;
    let plain = |tree| SimplifyParams { tree, keep_topology: vstree::KeepTopology::Off, ..Default::default() };
    for (tree, name, start) in [
        (TreeParams { max_depth: 1, ..Default::default() }, "max_depth", "1: every triangle collapsed (2 clusters"),
        (
            TreeParams { min_cell_size: 0.99, ..Default::default() },
            "min_cell_size",
            "0.99: every triangle collapsed (1 cluster",
        ),
        (TreeParams { error: 100.0, ..Default::default() }, "error", "100: every triangle collapsed (1 cluster"),
    ] {
        match simplify(&mesh, &plain(tree), &mut Progress::none()) {
            Err(Error::InvalidParameter { name: got, message }) => {
                assert_eq!(got, name, "{message}");
                assert!(message.starts_with(start), "{message}");
            }
            other => panic!("{tree:?}: {other:?}"),
        }
    }
}

/// Each metric's default bound is one it accepts, and a target size ignores the bound.
#[test]
fn every_metric_has_a_valid_default_and_a_size_ignores_the_bound() {
    let sphere = vstree::eval::shapes::icosphere(1.0, 3);
    for metric in [Metric::L2, Metric::L21, Metric::Density] {
        let tree = TreeParams { metric, error: metric.default_error(), ..Default::default() };
        tree.check().unwrap();
        let (out, _) = simplify_with(&sphere, tree).unwrap();
        assert!(!out.triangles.is_empty() && out.triangles.len() <= 1280, "{metric:?}");
        let bad = TreeParams { metric, error: -1.0, ..Default::default() };
        let sized = SimplifyParams { tree: bad, target_faces: 500, ..Default::default() };
        sized.check().unwrap();
        let (out, _) = simplify(&sphere, &sized, &mut Progress::none()).unwrap();
        assert!(out.triangles.len().abs_diff(500) <= 5, "{metric:?}: {}", out.triangles.len());
    }
    assert_eq!(Metric::Density.default_error(), 16.0);
}
