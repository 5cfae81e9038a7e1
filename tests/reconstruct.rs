//! Surface reconstruction: genus, watertightness, distance to the samples, semi-regularity,
//! noise, open scans, determinism and bad input.

mod common;

use glam::Vec3;
use vstree::distance::chamfer_and_hausdorff;
use vstree::reconstruct::{reconstruct, ReconstructParams, ReconstructStats, RefinementStop};
use vstree::tree::TreeParams;
use vstree::{shapes, topology, Error, Mesh, Progress};

fn run(cloud: &Mesh, params: &ReconstructParams) -> (Mesh, ReconstructStats) {
    reconstruct(cloud, params, &mut Progress::none()).unwrap()
}

/// Share of vertices with valence 6.
fn regular_share(mesh: &Mesh) -> f64 {
    let v = topology::valences(mesh);
    v.iter().filter(|&&d| d == 6).count() as f64 / v.len() as f64
}

/// Share of triangles facing against the sum of their corners' normals (folds).
fn folded_share(mesh: &Mesh) -> f64 {
    let normals = mesh.normals.as_ref().expect("the reconstruction has normals");
    let folded = mesh
        .triangles
        .iter()
        .filter(|t| {
            let [a, b, c] = t.map(|v| mesh.positions[v as usize]);
            (b - a).cross(c - a).dot(t.iter().map(|&v| normals[v as usize]).sum::<Vec3>()) < 0.0
        })
        .count();
    folded as f64 / mesh.triangles.len().max(1) as f64
}

/// The checks every closed input must pass: M0 and the result watertight with `genus`, mostly
/// valence 6, and close to the samples both ways.
fn assert_closed_reconstruction(name: &str, cloud: &Mesh, genus: u32) {
    let (mesh, stats) = run(cloud, &ReconstructParams::default());
    let report = topology::analyze(&mesh);
    let diagonal = cloud.bounds().unwrap().diagonal();
    let (chamfer, hausdorff) = chamfer_and_hausdorff(&mesh, cloud, 100_000, 1);
    eprintln!(
        "{name}: M0 {} vertices genus {:?}; {} levels; {} triangles; valence 6: {:.1}%; folded {:.2}%; error {:.2e}; chamfer {:.2e}, hausdorff {:.2e} (x diagonal)",
        stats.base_vertices,
        stats.base_genus,
        stats.levels.len(),
        mesh.triangles.len(),
        100.0 * regular_share(&mesh),
        100.0 * folded_share(&mesh),
        stats.final_error,
        chamfer / diagonal,
        hausdorff / diagonal
    );
    assert_eq!(stats.base_genus, Some(genus), "{name}: M0's genus");
    assert!(report.is_watertight(), "{name}: {report:?}");
    assert_eq!(report.genus(), Some(genus), "{name}: the result's genus");
    // Measured at most 0.23% (fertility); 3-5% before M0 and each level were unfolded.
    assert!(folded_share(&mesh) < 0.005, "{name}: {:.2}% folded triangles", 100.0 * folded_share(&mesh));
    assert!(regular_share(&mesh) > 0.9, "{name}: {:.1}% valence 6", 100.0 * regular_share(&mesh));
    // Distances as multiples of the threshold's own length: the tree's L2 bound e keeps every
    // sample's tangent plane within √e × diagonal of its cluster's point (3.2e-3 at 1e-5).
    let bound = ReconstructParams::default().tree.error.sqrt() as f32;
    // Measured at most 1.3e-3 RMS (kitten, whose scan is the noisiest) and a Chamfer of 3.0e-3.
    assert!(
        stats.final_error < 0.94 * f64::from(bound),
        "{name}: RMS sample distance {:.2e} x diagonal",
        stats.final_error
    );
    assert!(chamfer < 1.4 * bound * diagonal, "{name}: chamfer {:.2e} x diagonal", chamfer / diagonal);
    // The worst points are where displacement folds a few triangles (measured up to 2.7e-2 on
    // the double torus); the bound keeps that from getting worse.
    assert!(hausdorff < 12.6 * bound * diagonal, "{name}: hausdorff {:.2e} x diagonal", hausdorff / diagonal);
}

#[test]
fn generated_torus_and_double_torus_keep_their_genus() {
    let torus = shapes::sample_surface(&shapes::torus(1.0, 0.35, 128, 64), 60_000, 1);
    assert_closed_reconstruction("torus", &torus, 1);
    let double = shapes::sample_surface(&shapes::double_torus(), 80_000, 2);
    assert_closed_reconstruction("double torus", &double, 2);
}

#[test]
fn real_shapes_of_known_genus() {
    let Some(kitten) = common::load("kitten.xyz") else { return };
    assert_closed_reconstruction("kitten", &kitten, 1);
    for (name, genus) in [("eight.off", 2), ("knot1.off", 1), ("3holes.off", 3)] {
        let mesh = common::load(name).unwrap();
        assert_closed_reconstruction(name, &shapes::sample_surface(&mesh, 100_000, 1), genus);
    }
}

#[test]
fn fertility_has_genus_four() {
    let Some(mesh) = common::load("fertility_20k.off") else { return };
    assert_closed_reconstruction("fertility", &shapes::sample_surface(&mesh, 100_000, 1), 4);
}

/// Ten overlapping raw scans, misaligned by about a grid cell, with scanner noise and no
/// normals: a closed bunny without handles (before the thickening of thin parts its ears came
/// out perforated, genus 24), close to the zippered bunny made from the same scans.
#[test]
fn merged_bunny_scans_give_a_clean_bunny() {
    let (Some(scans), Some(zipper)) = (common::load("bunny_scans_merged.ply"), common::load("bunny_zipper.ply")) else {
        return;
    };
    let (mesh, stats) = run(&Mesh::from_points(scans.positions.clone(), None), &ReconstructParams::default());
    let report = topology::analyze(&mesh);
    let diagonal = zipper.bounds().unwrap().diagonal();
    let (chamfer, hausdorff) = chamfer_and_hausdorff(&mesh, &zipper, 100_000, 1);
    eprintln!(
        "bunny scans: M0 genus {:?} (thickened: {}); {} triangles; valence 6 {:.1}%; folded {:.2}%; to bun_zipper: chamfer {:.2e}, hausdorff {:.2e} (x diagonal)",
        stats.base_genus,
        stats.thickened,
        mesh.triangles.len(),
        100.0 * regular_share(&mesh),
        100.0 * folded_share(&mesh),
        chamfer / diagonal,
        hausdorff / diagonal
    );
    assert!(report.is_watertight(), "{report:?}");
    assert_eq!(report.genus(), Some(0), "handles in the bunny");
    assert!(regular_share(&mesh) > 0.9);
    // Measured 0.86% (2.0% before folds that the leaves kept re-folding were moved along the
    // normal only, 3.2% before thin parts were thickened): the leaves of misaligned
    // overlapping scans disagree by more than the vertices' spacing.
    assert!(folded_share(&mesh) < 0.015, "{:.2}% folded", 100.0 * folded_share(&mesh));
    // Measured 6.9e-4 (the zippered bunny is open underneath, where this one is closed).
    assert!(chamfer < 1e-3 * diagonal, "chamfer to bun_zipper {:.2e} x diagonal", chamfer / diagonal);
}

#[test]
fn a_noisy_sphere_lands_on_the_true_sphere() {
    let mut cloud = shapes::sample_surface(&shapes::icosphere(1.0, 6), 100_000, 3);
    for (p, n) in cloud.positions.iter_mut().zip(cloud.normals.as_mut().unwrap()) {
        *p = p.normalize();
        *n = *p;
    }
    shapes::add_noise(&mut cloud, 0.003, 0.1, 4);
    let (mesh, _) = run(&cloud, &ReconstructParams::default());
    let report = topology::analyze(&mesh);
    assert!(report.is_watertight() && report.genus() == Some(0), "{report:?}");
    let off: Vec<f32> = mesh.positions.iter().map(|p| (p.length() - 1.0).abs()).collect();
    let mean = off.iter().sum::<f32>() / off.len() as f32;
    let max = off.iter().copied().fold(0.0, f32::max);
    eprintln!("noisy sphere: mean {mean:.4}, max {max:.4} from the true sphere");
    assert!(mean < 0.006, "mean distance to the true sphere {mean}");
    // A few vertices fold out where displacement pulls them onto a noisy leaf (measured 0.033).
    assert!(max < 0.045, "max distance to the true sphere {max}");
}

#[test]
fn a_cloud_without_normals_gets_them_estimated() {
    let mut cloud = shapes::sample_surface(&shapes::torus(1.0, 0.35, 96, 48), 40_000, 5);
    cloud.normals = None;
    let (mesh, stats) = run(&cloud, &ReconstructParams::default());
    assert_eq!(stats.normals.estimated, 40_000);
    let report = topology::analyze(&mesh);
    assert!(report.is_watertight() && report.genus() == Some(1), "{report:?}");
    assert!(topology::signed_volume(&mesh) > 0.0, "facing inward");
}

#[test]
fn same_mesh_with_one_or_two_threads() {
    let cloud = shapes::sample_surface(&shapes::double_torus(), 40_000, 6);
    let one = run(&cloud, &ReconstructParams { threads: 1, ..Default::default() }).0;
    let two = run(&cloud, &ReconstructParams { threads: 2, ..Default::default() }).0;
    assert!(one == two, "the result depends on the thread count");
}

#[test]
fn a_single_range_scan_gives_an_open_mesh() {
    let Some(scan) = common::load("bunny_raw_bun000.ply") else { return };
    let (mesh, stats) = run(&scan, &ReconstructParams { trim: 3.0, ..Default::default() });
    let report = topology::analyze(&mesh);
    eprintln!(
        "bun000: {} triangles after trimming {}; {} boundary edges",
        mesh.triangles.len(),
        stats.trimmed_triangles,
        report.boundary_edges
    );
    assert!(report.boundary_edges > 0, "a single scan must stay open");
    // The scan closed by a sheet well behind it: one blob without handles, whose back goes.
    assert_eq!(stats.base_genus, Some(0), "M0 of a single scan");
    assert!(stats.trimmed_triangles > 500, "{} trimmed", stats.trimmed_triangles);
    // What is left is near the samples.
    let far = vstree::distance::one_sided(&mesh.positions, vstree::distance::Target::Points(&scan.positions));
    assert!(far.p99 < 0.02 * scan.bounds().unwrap().diagonal(), "p99 {}", far.p99);
}

#[test]
fn a_stricter_indicator_gives_a_denser_base_mesh() {
    let cloud = shapes::sample_surface(&shapes::bumpy_sphere(1.0, 0.12, 6.0, 6), 60_000, 7);
    let loose = run(&cloud, &ReconstructParams::default()).1;
    let strict = ReconstructParams {
        tree: TreeParams { d_a: 0.7, d_d: 0.08, error: 1e-5, ..Default::default() },
        ..Default::default()
    };
    let strict = run(&cloud, &strict).1;
    eprintln!("M0: {} vertices (defaults), {} (d_a 0.7, d_d 0.08)", loose.base_vertices, strict.base_vertices);
    assert!(strict.base_vertices as f64 > 1.3 * loose.base_vertices as f64);
}

/// A target no triangle budget can reach: refinement stops at the budget and says so, and the
/// output stays within it (nothing is allocated for the level that would exceed it).
#[test]
fn an_unreachable_target_stops_at_the_triangle_budget() {
    let cloud = shapes::sample_surface(&shapes::icosphere(1.0, 5), 20_000, 8);
    let params = ReconstructParams {
        tree: TreeParams { error: 1e-14, ..Default::default() },
        target_distance: 1e-9,
        max_levels: 12,
        max_triangles: 200_000,
        ..Default::default()
    };
    let (mesh, stats) = run(&cloud, &params);
    assert_eq!(stats.stopped, RefinementStop::TriangleBudget, "{stats:?}");
    assert!(
        mesh.triangles.len() <= 200_000 && 4 * mesh.triangles.len() > 200_000,
        "{} triangles",
        mesh.triangles.len()
    );
    assert!(topology::analyze(&mesh).is_watertight());
    let (_, stats) = run(&cloud, &ReconstructParams { target_distance: 0.5, ..Default::default() });
    assert_eq!(stats.stopped, RefinementStop::Target);
    assert!(stats.levels.is_empty(), "M0 is already within half the diagonal");
}

#[test]
fn bad_input_is_refused_clearly() {
    let few = Mesh::from_points(vec![Vec3::ZERO; 5], Some(vec![Vec3::Z; 5]));
    assert!(reconstruct(&few, &Default::default(), &mut Progress::none())
        .unwrap_err()
        .to_string()
        .contains("at least"));
    let line: Vec<Vec3> = (0..100).map(|i| Vec3::new(i as f32, 0.0, 0.0)).collect();
    assert!(reconstruct(&Mesh::from_points(line, None), &Default::default(), &mut Progress::none()).is_err());
    let mut nan = shapes::sample_surface(&shapes::icosphere(1.0, 2), 100, 1);
    nan.positions[7].x = f32::NAN;
    assert!(reconstruct(&nan, &Default::default(), &mut Progress::none()).unwrap_err().to_string().contains('7'));
    let sphere = shapes::sample_surface(&shapes::icosphere(1.0, 3), 2_000, 1);
    for (params, name) in [
        (ReconstructParams { max_levels: 99, ..Default::default() }, "max_levels"),
        (ReconstructParams { trim: -1.0, ..Default::default() }, "trim"),
        (ReconstructParams { max_grid_depth: 50, ..Default::default() }, "max_grid_depth"),
        (ReconstructParams { target_distance: f64::NAN, ..Default::default() }, "target_distance"),
        (ReconstructParams { max_triangles: 0, ..Default::default() }, "max_triangles"),
    ] {
        match reconstruct(&sphere, &params, &mut Progress::none()) {
            Err(Error::InvalidParameter { name: got, .. }) => assert_eq!(got, name),
            other => panic!("expected an error naming {name}, got {:?}", other.map(|r| r.1)),
        }
    }
    // Duplicated points are fine.
    let mut twice = sphere.clone();
    twice.positions.extend(sphere.positions.clone());
    twice.normals.as_mut().unwrap().extend(sphere.normals.clone().unwrap());
    reconstruct(&twice, &Default::default(), &mut Progress::none()).unwrap();
    // Cancelling stops with Cancelled.
    let mut stop = |f: f32, _: &str| f < 0.5;
    assert!(matches!(reconstruct(&sphere, &Default::default(), &mut Progress::new(&mut stop)), Err(Error::Cancelled)));
}
