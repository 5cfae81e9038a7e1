//! Surface reconstruction: genus, watertightness, distance to the samples, semi-regularity,
//! noise, open scans, determinism and bad input.

mod common;

use glam::Vec3;
use vstree::eval::distance::chamfer_and_hausdorff;
use vstree::reconstruct::{reconstruct, BaseMesh, Closure, ReconstructParams, ReconstructStats, RefinementStop};
use vstree::tree::TreeParams;
use vstree::{eval::shapes, topology, Error, Mesh, Progress};

fn run(cloud: &Mesh, params: &ReconstructParams) -> (Mesh, ReconstructStats) {
    reconstruct(cloud, params, &mut Progress::none()).unwrap()
}

/// Share of vertices with valence 6.
fn regular_share(mesh: &Mesh) -> f64 {
    let v = vstree::eval::figures::valences(mesh);
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

/// Shares of triangles whose smallest angle is under 10 and under 20 degrees.
fn thin_shares(mesh: &Mesh) -> (f64, f64) {
    let smallest: Vec<f32> = mesh
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| mesh.positions[v as usize]);
            let at = |p: Vec3, q: Vec3, r: Vec3| (q - p).angle_between(r - p).to_degrees();
            at(a, b, c).min(at(b, c, a)).min(at(c, a, b))
        })
        .collect();
    let share = |deg: f32| smallest.iter().filter(|&&x| x < deg).count() as f64 / smallest.len().max(1) as f64;
    (share(10.0), share(20.0))
}

/// The checks every closed input must pass: M0 and the result watertight with `genus`, mostly
/// valence 6, and close to the samples both ways.
fn assert_closed_reconstruction(name: &str, cloud: &Mesh, genus: u32) {
    let (mesh, stats) = run(cloud, &ReconstructParams::default());
    let report = topology::analyze(&mesh);
    let diagonal = cloud.bounds().unwrap().diagonal();
    let (chamfer, hausdorff) = chamfer_and_hausdorff(&mesh, cloud, 100_000, 1);
    let thin = thin_shares(&mesh);
    eprintln!(
        "{name}: M0 {} vertices genus {:?}; {} levels; {} triangles; valence 6: {:.1}%; folded {:.2}%; under 10 and 20 degrees {:.2}% {:.2}%; error {:.2e}; chamfer {:.2e}, hausdorff {:.2e} (x diagonal)",
        stats.base_vertices,
        stats.base_genus,
        stats.levels.len(),
        mesh.triangles.len(),
        100.0 * regular_share(&mesh),
        100.0 * folded_share(&mesh),
        100.0 * thin.0,
        100.0 * thin.1,
        stats.final_error,
        chamfer / diagonal,
        hausdorff / diagonal
    );
    assert_eq!(stats.base_genus, Some(genus), "{name}: M0's genus");
    assert!(report.is_watertight(), "{name}: {report:?}");
    assert_eq!(report.genus(), Some(genus), "{name}: the result's genus");
    // Measured 0 on every one: each refined level is unfolded onto the samples' fit.
    assert!(folded_share(&mesh) < 1e-4, "{name}: {:.3}% folded triangles", 100.0 * folded_share(&mesh));
    // Nor any pair of triangles folded onto each other (the benchmark's folds, 150 degrees).
    let pairs = topology::adjacent_face_pairs(&mesh.triangles);
    let folds = topology::folded_face_pairs(&mesh.positions, &mesh.triangles, &pairs, 150.0).len();
    assert_eq!(folds, 0, "{name}: {folds} folds");
    // Remeshing-grade triangles (issue 13's targets): measured at most 0.32% under 10 degrees
    // and 1.73% under 20 (fertility).
    assert!(thin.0 < 0.01 && thin.1 < 0.05, "{name}: {thin:?} under 10 and 20 degrees");
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
fn the_winding_base_mesh_keeps_a_thin_ring_that_the_planes_flatten() {
    // A ring 0.06 thick on a 2-wide torus: its T-nodes are several times larger than its
    // section, so their blended planes flatten it, where the winding number and the distance
    // to the samples follow it. Measured Chamfer 1.50e-4 (winding) and 2.19e-4 (paper).
    let truth = shapes::torus(1.0, 0.03, 256, 32);
    let cloud = shapes::sample_surface(&truth, 60_000, 1);
    let mut chamfers = Vec::new();
    // Closed asked for: the flattened ring's faces face away from its samples, which `Auto`
    // would take for the back of an open scan.
    for base_mesh in [BaseMesh::Winding, BaseMesh::Paper] {
        let params = ReconstructParams { base_mesh, closure: Closure::Closed, ..Default::default() };
        let (mesh, stats) = run(&cloud, &params);
        assert_eq!(stats.base_genus, Some(1), "{base_mesh:?}: M0's genus");
        assert_eq!(topology::analyze(&mesh).genus(), Some(1), "{base_mesh:?}: the result's genus");
        chamfers.push(chamfer_and_hausdorff(&mesh, &truth, 100_000, 1).0);
    }
    assert!(chamfers[0] < 0.8 * chamfers[1], "Chamfer: winding {:.3e}, paper {:.3e}", chamfers[0], chamfers[1]);
}

#[test]
fn a_plate_thinner_than_the_grid_keeps_its_four_holes() {
    // A 2 x 2 plate 0.024 thick with four holes 0.4 across: the grid (64 cells across the
    // root cube, as coarse as the flat plate's large T-nodes allow) is wider than the plate,
    // so its points see one side only and perforate it; thickened by THICKEN_CELLS, the plate
    // is whole and its real holes, wider than twice the offset, stay open.
    let half_thickness = 0.012;
    let plate = |p: Vec3| {
        let slab = (p.x.abs() - 1.0).max(p.y.abs() - 1.0).max(p.z.abs() - half_thickness);
        let hole = [(0.5, 0.5), (-0.5, 0.5), (0.5, -0.5), (-0.5, -0.5)]
            .iter()
            .map(|&(x, y)| ((p.x - x).powi(2) + (p.y - y).powi(2)).sqrt() - 0.2)
            .fold(f32::MAX, f32::min);
        slab.max(-hole)
    };
    let truth = shapes::implicit_mesh(plate, Vec3::splat(-1.2), Vec3::splat(1.2), 300);
    assert_eq!(topology::analyze(&truth).genus(), Some(4));
    let cloud = shapes::sample_surface(&truth, 100_000, 1);
    let (mesh, stats) = run(&cloud, &ReconstructParams::default());
    let report = topology::analyze(&mesh);
    assert!(stats.thickened, "the plate was not thickened (grid {} cells)", stats.grid_cells);
    assert!(report.is_watertight() && report.components == 1 && report.genus() == Some(4), "{report:?}");
}

#[test]
fn a_sparse_torus_keeps_its_handle() {
    // 1,152 points on a 48 x 24 grid of a bumpy torus, no normals: the tree's leaves hold one
    // or two samples in cells smaller than the surface those stand for, and counted by their
    // cells alone the winding number stayed below one half inside the tube (genus 0, 6 parts).
    let pi = std::f32::consts::PI;
    let mut points = Vec::new();
    for i in 0..48 {
        let u = 2.0 * pi * i as f32 / 48.0;
        for j in 0..24 {
            let v = 2.0 * pi * j as f32 / 24.0;
            let r = 0.3 * (1.0 + 0.2 * (5.0 * u).sin() * (3.0 * v).sin());
            points.push(Vec3::new((1.0 + r * v.cos()) * u.cos(), (1.0 + r * v.cos()) * u.sin(), r * v.sin()));
        }
    }
    let cloud = Mesh::from_points(points, None);
    let (mesh, stats) = run(&cloud, &ReconstructParams { max_levels: 2, max_grid_depth: 6, ..Default::default() });
    let report = topology::analyze(&mesh);
    assert_eq!(stats.base_genus, Some(1));
    assert!(report.is_watertight() && report.components == 1 && report.genus() == Some(1), "{report:?}");
    assert!(stats.final_error < 2e-3, "RMS {}", stats.final_error);
}

#[test]
fn normals_that_all_point_inward_are_turned_out_for_a_closed_surface() {
    let outward = sphere_points(20_000, |_| true);
    let inward =
        Mesh::from_points(outward.positions.clone(), outward.normals.as_ref().map(|n| n.iter().map(|&v| -v).collect()));
    let (mesh, stats) = run(&inward, &ReconstructParams::default());
    assert_eq!(stats.normals.orient.map(|o| o.flipped), Some(20_000));
    let report = topology::analyze(&mesh);
    assert!(report.is_watertight() && report.genus() == Some(0) && report.components == 1, "{report:?}");
    let off = mesh.positions.iter().map(|p| (p.length() - 1.0).abs()).fold(0.0f32, f32::max);
    assert!(off < 0.02, "a vertex {off} off the sphere");
    // Given outward normals are kept; so are those of an open output, where they face the
    // scanner whatever their flux: the inside of a bowl, scanned from within.
    assert_eq!(run(&outward, &ReconstructParams::default()).1.normals.orient, None);
    let dome = sphere_points(10_000, |p| p.z > 0.0);
    let bowl =
        Mesh::from_points(dome.positions.clone(), dome.normals.as_ref().map(|n| n.iter().map(|&v| -v).collect()));
    let (mesh, stats) = run(&bowl, &ReconstructParams { closure: Closure::Open, ..Default::default() });
    assert_eq!(stats.normals.orient, None);
    assert!(topology::analyze(&mesh).boundary_edges > 0);
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
    // Measured 0.86%: the leaves of misaligned overlapping scans disagree by more than the
    // vertices' spacing.
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

/// Gaussian noise of 0.5% of the diagonal on a torus (200k points, its tube a sixth of its
/// size): the noise is measured and allowed for, so the base mesh makes no handle of it and
/// the surface lands well inside the noise of the true torus.
#[test]
fn heavy_noise_is_measured_and_makes_no_handles() {
    let (major, minor) = (1.0f32, 0.35f32);
    let mut cloud = shapes::sample_surface(&shapes::torus(major, minor, 256, 96), 200_000, 8);
    let diagonal = vstree::mesh::Aabb::of(&cloud.positions).unwrap().diagonal();
    let sigma = 0.005 * diagonal;
    shapes::add_noise(&mut cloud, sigma, 0.0, 9);
    let (mesh, stats) = run(&cloud, &ReconstructParams::default());
    let report = topology::analyze(&mesh);
    assert!(report.is_watertight() && report.genus() == Some(1), "{report:?}");
    let found = stats.noise / 0.005;
    assert!((found - 1.0).abs() < 0.15, "noise found {:.4}% of the diagonal", 100.0 * stats.noise);
    let off = |p: &Vec3| ((Vec3::new(p.x, p.y, 0.0).length() - major).hypot(p.z) - minor).abs();
    let mean = mesh.positions.iter().map(off).sum::<f32>() / mesh.positions.len() as f32;
    eprintln!("torus with noise {sigma:.4}: found {:.4}, mean distance {mean:.5}", stats.noise * f64::from(diagonal));
    assert!(mean < 0.25 * sigma, "mean distance to the true torus {mean}, noise {sigma}");
}

/// A ball with a rod four noise levels thick sticking out, under 0.5% noise: the rod's V-nodes
/// fit within the noise allowance of their error, and left as leaves they had no T-node of
/// their own; the base mesh merged them into the ball's, and the rod was lost.
#[test]
fn a_thin_rod_under_heavy_noise_is_kept() {
    let rod_tip = 0.95f32;
    let ball_and_rod = |p: Vec3| {
        let rod = (p.y.hypot(p.z) - 0.03).max(p.x - rod_tip).max(-p.x);
        (p.length() - 0.45).min(rod)
    };
    let solid = shapes::implicit_mesh(ball_and_rod, Vec3::splat(-1.0), Vec3::splat(1.0), 200);
    let mut cloud = shapes::sample_surface(&solid, 100_000, 12);
    let diagonal = vstree::mesh::Aabb::of(&cloud.positions).unwrap().diagonal();
    shapes::add_noise(&mut cloud, 0.005 * diagonal, 0.0, 13);
    let (mesh, _) = run(&cloud, &ReconstructParams::default());
    let report = topology::analyze(&mesh);
    assert!(report.is_watertight() && report.genus() == Some(0), "{report:?}");
    let reach = mesh.positions.iter().map(|p| p.x).fold(f32::MIN, f32::max);
    assert!(reach > rod_tip - 0.1, "the surface reaches x = {reach}, the rod {rod_tip}");
}

#[test]
fn a_cloud_without_normals_gets_them_estimated() {
    let mut cloud = shapes::sample_surface(&shapes::torus(1.0, 0.35, 96, 48), 40_000, 5);
    cloud.normals = None;
    let (mesh, stats) = run(&cloud, &ReconstructParams::default());
    assert_eq!(stats.normals.estimated, 40_000);
    let report = topology::analyze(&mesh);
    assert!(report.is_watertight() && report.genus() == Some(1), "{report:?}");
    assert!(vstree::eval::figures::signed_volume(&mesh) > 0.0, "facing inward");
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
    // Found to be open, and made open, by default.
    let (mesh, stats) = run(&scan, &ReconstructParams::default());
    let report = topology::analyze(&mesh);
    eprintln!(
        "bun000: {:.0}% of the closed surface unsupported; {} triangles, {} boundary edges",
        100.0 * stats.unsupported_share,
        mesh.triangles.len(),
        report.boundary_edges
    );
    assert!(stats.open && stats.unsupported_share > 0.3, "{}", stats.unsupported_share);
    assert!(report.boundary_edges > 0 && report.non_manifold_edges == 0, "{report:?}");
    // No hole inside the scan: the border is short (a closing sheet clustered into M0, or
    // specks of it, would leave thousands of border edges).
    assert!(report.boundary_edges < mesh.triangles.len() / 20, "{report:?}");
    // What is left is near the samples.
    let far =
        vstree::eval::distance::one_sided(&mesh.positions, vstree::eval::distance::Target::Points(&scan.positions));
    assert!(far.p99 < 0.01 * scan.bounds().unwrap().diagonal(), "p99 {}", far.p99);
    // Asked for, the same scan gives a closed surface.
    let (mesh, stats) = run(&scan, &ReconstructParams { closure: Closure::Closed, ..Default::default() });
    assert!(!stats.open && topology::analyze(&mesh).is_watertight());
}

/// `count` points on the unit sphere where `keep` holds, with their exact normals.
fn sphere_points(count: usize, keep: impl Fn(Vec3) -> bool) -> Mesh {
    let sphere = shapes::icosphere(1.0, 5);
    let kept =
        sphere.triangles.iter().copied().filter(|t| t.iter().all(|&v| keep(sphere.positions[v as usize]))).collect();
    let cloud = shapes::sample_surface(&Mesh::new(sphere.positions.clone(), None, kept), count, 11);
    let on_sphere: Vec<Vec3> = cloud.positions.iter().map(|p| p.normalize()).collect();
    Mesh::from_points(on_sphere.clone(), Some(on_sphere))
}

/// The upper half of the unit icosphere that [`sphere_points`] samples for a hemisphere.
fn hemisphere_mesh() -> Mesh {
    let sphere = shapes::icosphere(1.0, 5);
    let kept = sphere.triangles.iter().copied().filter(|t| t.iter().all(|&v| sphere.positions[v as usize].z > -1e-6));
    Mesh::new(sphere.positions.clone(), None, kept.collect())
}

/// The median distance from a point to its nearest other point.
fn spacing(points: &[Vec3]) -> f32 {
    let bvh = vstree::spatial::KdTree::new(points).unwrap();
    let mut gaps: Vec<f32> = (0..points.len())
        .step_by(7)
        .filter_map(|i| bvh.nearest_among(points[i], |j| j as usize != i).map(|(d, _)| d))
        .collect();
    gaps.sort_by(f32::total_cmp);
    gaps[gaps.len() / 2]
}

#[test]
fn a_hemisphere_gives_an_open_dome_up_to_its_rim() {
    for count in [10_000, 100_000] {
        let cloud = sphere_points(count, |p| p.z > -1e-6);
        let (mesh, stats) = run(&cloud, &ReconstructParams::default());
        let report = topology::analyze(&mesh);
        assert!(stats.open, "{count}: {:.2} unsupported", stats.unsupported_share);
        assert!(report.boundary_edges > 0 && report.non_manifold_edges == 0 && report.components == 1, "{report:?}");
        // On the sphere, and reaching the rim all round: every border vertex near z = 0. (The
        // refinement's bumps of a few hundredths, at the pole and the rim, are a known defect:
        // 0.061 at 10k points.)
        let off = mesh.positions.iter().map(|p| (p.length() - 1.0).abs()).fold(0.0f32, f32::max);
        assert!(off < 0.07, "{count}: a vertex {off} off the sphere");
        assert!(stats.final_error < 1e-3, "{count}: RMS {}", stats.final_error);
        // Close to the true dome both ways (measured 1.9e-4 and 1.0e-4, the border cut back to
        // the samples).
        let dome = hemisphere_mesh();
        let (chamfer, _) = chamfer_and_hausdorff(&mesh, &dome, 100_000, 1);
        assert!(chamfer < 4e-4, "{count}: Chamfer {chamfer:.2e} to the dome");
        // The border follows the scan's: the sampled triangles' rim, jagged by an icosphere
        // edge around z = 0. Both ways within a few sample spacings, or (the rim's zigzag
        // cut short by straight edges) three quarters of the output's border edges where those are longer. Measured:
        // 2.6 and 3.5 spacings at 10k points, 3.1 and 5.6 at 100k (border edges 11 spacings).
        let h = spacing(&cloud.positions);
        let rim = border_edges(&dome);
        let border: Vec<Vec3> = border_vertices(&mesh).iter().map(|&v| mesh.positions[v]).collect();
        let output_rim: Vec<[Vec3; 2]> =
            border_edges(&mesh).iter().map(|&[a, b]| [a, b].map(|v| mesh.positions[v as usize])).collect();
        let rim: Vec<[Vec3; 2]> = rim.iter().map(|&[a, b]| [a, b].map(|v| dome.positions[v as usize])).collect();
        let beyond = border.iter().map(|&p| distance_to_segments(p, &rim)).fold(0.0f32, f32::max);
        let short = rim
            .iter()
            .flat_map(|&[a, b]| (0..4).map(move |k| a.lerp(b, k as f32 / 4.0)))
            .map(|p| distance_to_segments(p, &output_rim))
            .fold(0.0f32, f32::max);
        let mut lengths: Vec<f32> = output_rim.iter().map(|[a, b]| a.distance(*b)).collect();
        lengths.sort_by(f32::total_cmp);
        let edge = lengths[lengths.len() / 2];
        assert!(
            beyond < 4.0 * h && short < (4.0 * h).max(0.75 * edge),
            "{count}: border {beyond} off the rim, rim {short} off the border, spacing {h}, border edges {edge}"
        );
    }
}

#[test]
fn a_scan_from_one_side_leaves_no_sheet_behind_it() {
    // The upper half of a torus, as a scanner above it sees it: an annulus with two borders.
    // Behind it the winding number stays under one half, so inside-above-one-half would close
    // it with a sheet right behind the samples, too close for the border trim to remove.
    let (major, minor) = (1.0, 0.4);
    let torus = shapes::torus(major, minor, 256, 96);
    let top = torus.triangles.iter().copied().filter(|t| t.iter().all(|&v| torus.positions[v as usize].z > -1e-6));
    let sampled = shapes::sample_surface(&Mesh::new(torus.positions.clone(), None, top.collect()), 60_000, 5);
    let on_torus = |p: Vec3| {
        let ring = Vec3::new(p.x, p.y, 0.0).normalize() * major;
        let normal = (p - ring).normalize();
        (ring + normal * minor, normal)
    };
    let (points, normals): (Vec<Vec3>, Vec<Vec3>) = sampled.positions.iter().map(|&p| on_torus(p)).unzip();
    let cloud = Mesh::from_points(points, Some(normals));
    let (mesh, stats) = run(&cloud, &ReconstructParams::default());
    let report = topology::analyze(&mesh);
    assert!(stats.open && report.non_manifold_edges == 0 && report.components == 1, "{report:?}");
    // No sheet behind the scan: no face below the torus's equator by more than the border trim
    // (2 sample spacings), and no face turned away from the scanner.
    let h = spacing(&cloud.positions);
    let lowest = mesh.positions.iter().map(|p| p.z).fold(f32::MAX, f32::min);
    // Faces facing down (their corners' normals): a sheet behind the scan faces away from it.
    let normals = mesh.normals.as_ref().unwrap();
    let away = mesh.triangles.iter().filter(|t| t.iter().map(|&v| normals[v as usize].z).sum::<f32>() < -0.5).count();
    eprintln!(
        "torus top: lowest vertex {lowest:.4} ({:.1} spacings), {away} faces facing down, {:.3}% folded, {report:?}",
        -lowest / h,
        100.0 * folded_share(&mesh)
    );
    assert!(lowest > -3.0 * h, "a vertex {:.1} spacings below the scan", -lowest / h);
    assert!(away == 0, "{away} faces facing down, away from the scanner");
    // What is left of a sheet folds against the scan: measured 0.011% of the faces folded, 1.3%
    // (and 24% more vertices) with inside above one half.
    assert!(folded_share(&mesh) < 1e-3, "{:.3}% folded", 100.0 * folded_share(&mesh));
    // An annulus: Euler characteristic 0, two border loops.
    assert_eq!(report.vertices as i64 - report.edges as i64 + report.faces as i64, 0, "{report:?}");
}

/// The edges that only one face has.
fn border_edges(mesh: &Mesh) -> Vec<[u32; 2]> {
    let mut edges: Vec<(u32, u32)> = mesh
        .triangles
        .iter()
        .flat_map(|t| (0..3).map(move |k| (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3]))))
        .collect();
    edges.sort_unstable();
    edges.chunk_by(|a, b| a == b).filter(|run| run.len() == 1).map(|run| [run[0].0, run[0].1]).collect()
}

/// The distance from `p` to the nearest of `segments`.
fn distance_to_segments(p: Vec3, segments: &[[Vec3; 2]]) -> f32 {
    segments
        .iter()
        .map(|&[a, b]| {
            let t = ((p - a).dot(b - a) / (b - a).length_squared().max(f32::MIN_POSITIVE)).clamp(0.0, 1.0);
            p.distance(a.lerp(b, t))
        })
        .fold(f32::INFINITY, f32::min)
}

/// The vertices on an edge that only one face has.
fn border_vertices(mesh: &Mesh) -> Vec<usize> {
    let mut out: Vec<usize> = border_edges(mesh).iter().flatten().map(|&v| v as usize).collect();
    out.sort_unstable();
    out.dedup();
    out
}

#[test]
fn closed_solids_with_sharp_creases_stay_closed() {
    // A thick ring (a rotor), a box and a cross of three bars: over the octree, a face joins
    // the vertices of neighbouring T-nodes, and where those lie on two sides of a crease its
    // chord cuts the corner, away from the samples (counted supported when its corners' T-nodes
    // face its way), and non-manifold leaves at the finest level are split further rather than
    // left to the grid. 0.7.0 opened five of these six clouds (unsupported shares 0.35 to
    // 0.80, measured on the grid it fell back to).
    let ring = |p: Vec3| ((p.x * p.x + p.y * p.y).sqrt() - 0.6).abs().max(p.z.abs()) - 0.2;
    let slab = |p: Vec3| (p.abs() - Vec3::new(0.8, 0.5, 0.3)).max_element();
    let cross = |p: Vec3| {
        let a = p.abs();
        let bar = |u: f32, v: f32, along: f32| (u.max(v) - 0.2).max(along - 0.8);
        bar(a.x, a.y, a.z).min(bar(a.x, a.z, a.y)).min(bar(a.y, a.z, a.x))
    };
    type Field<'a> = &'a (dyn Fn(Vec3) -> f32 + Sync);
    let shapes: [(&str, Field, usize, u32); 4] = [
        ("ring", &ring, 100_000, 1),
        ("box", &slab, 20_000, 0),
        ("box", &slab, 100_000, 0),
        ("cross", &cross, 100_000, 0),
    ];
    for (name, f, count, genus) in shapes {
        let solid = shapes::implicit_mesh(f, Vec3::splat(-1.0), Vec3::splat(1.0), 160);
        let cloud = shapes::sample_surface(&solid, count, 3);
        let (mesh, stats) = run(&cloud, &ReconstructParams::default());
        let report = topology::analyze(&mesh);
        assert!(
            !stats.open && report.is_watertight() && report.genus() == Some(genus),
            "{name} {count}: {:.3} unsupported, {report:?}",
            stats.unsupported_share
        );
    }
}

#[test]
fn a_sphere_with_a_small_hole_stays_closed_unless_asked() {
    // A cap of 5% of the area unsampled: closed over by default, kept open with `Open`.
    let cloud = sphere_points(40_000, |p| p.z < 0.9);
    let (mesh, stats) = run(&cloud, &ReconstructParams::default());
    assert!(!stats.open, "{:.3} unsupported", stats.unsupported_share);
    let report = topology::analyze(&mesh);
    assert!(report.is_watertight() && report.genus() == Some(0), "{report:?}");
    let (mesh, stats) = run(&cloud, &ReconstructParams { closure: Closure::Open, ..Default::default() });
    let report = topology::analyze(&mesh);
    assert!(stats.open && report.boundary_edges > 0 && report.non_manifold_edges == 0, "{report:?}");
    // The hole shrinks by the reach of the samples around it (the T-nodes' sag): measured
    // open above z = 0.986 where the samples stop at 0.9.
    let top = mesh.positions.iter().map(|p| p.z).fold(f32::MIN, f32::max);
    assert!(top < 0.99, "the hole was covered up to z = {top}");
    // A hemisphere is closed when asked.
    let dome = sphere_points(10_000, |p| p.z > -1e-6);
    let (mesh, stats) = run(&dome, &ReconstructParams { closure: Closure::Closed, ..Default::default() });
    assert!(!stats.open && topology::analyze(&mesh).is_watertight());
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
    let tree = ReconstructParams::default().tree;
    for (params, name) in [
        (ReconstructParams { max_levels: 99, ..Default::default() }, "max_levels"),
        (ReconstructParams { trim: -1.0, ..Default::default() }, "trim"),
        (ReconstructParams { max_grid_depth: 50, ..Default::default() }, "max_grid_depth"),
        (ReconstructParams { target_distance: f64::NAN, ..Default::default() }, "target_distance"),
        (ReconstructParams { max_triangles: 0, ..Default::default() }, "max_triangles"),
        // The height-field test can never hold at these ends: no T-layer, no base mesh.
        (ReconstructParams { tree: TreeParams { d_a: 1.0, ..tree }, ..Default::default() }, "d_a"),
        (ReconstructParams { tree: TreeParams { d_d: 0.0, ..tree }, ..Default::default() }, "d_d"),
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

/// `cloud` with every position multiplied by `scale`.
fn scaled(cloud: &Mesh, scale: f32) -> Mesh {
    Mesh::from_points(cloud.positions.iter().map(|&p| p * scale).collect(), cloud.normals.clone())
}

#[test]
fn a_cloud_reconstructs_alike_at_any_scale() {
    // Within the documented coordinate range (1e18), a cloud's units must not matter: at
    // powers of two the work is the same to the bit, at other scales the same shape.
    let cloud = sphere_points(3_000, |_| true);
    let (unit, unit_stats) = run(&cloud, &ReconstructParams::default());
    for exponent in [-50, -20, 20, 47, 56] {
        let scale = 2f32.powi(exponent);
        let (mesh, stats) = run(&scaled(&cloud, scale), &ReconstructParams::default());
        assert_eq!(stats.output_triangles, unit_stats.output_triangles, "2^{exponent}");
        let back: Vec<Vec3> = mesh.positions.iter().map(|&p| p / scale).collect();
        assert_eq!(back, unit.positions, "2^{exponent}: the same vertices, scaled");
    }
    for scale in [1e-15f32, 1e14, 1e15, 1e16, 1e17] {
        let (mesh, stats) = run(&scaled(&cloud, scale), &ReconstructParams::default());
        let report = topology::analyze(&mesh);
        assert!(report.is_watertight() && report.genus() == Some(0), "{scale:e}: {report:?}");
        let worst = mesh.positions.iter().map(|p| (p.length() / scale - 1.0).abs()).fold(0.0, f32::max);
        assert!(worst < 0.01, "{scale:e}: a vertex {worst} off the sphere's radius");
        assert_eq!(stats.isolated_points, 0);
    }
}

#[test]
fn isolated_points_far_away_are_left_out() {
    // One stray point 1000 diameters away once stretched the grid until the sphere was
    // smaller than a cell; it and a clump of three are left out, and the sphere comes out as
    // it does alone.
    let cloud = sphere_points(3_000, |_| true);
    let (alone, _) = run(&cloud, &ReconstructParams::default());
    let mut stray = cloud.clone();
    let far = [
        Vec3::new(2000.0, 0.0, 0.0),
        Vec3::new(0.0, -40.0, 0.0),
        Vec3::new(0.0, -40.01, 0.0),
        Vec3::new(0.01, -40.0, 0.0),
    ];
    stray.positions.extend(far);
    stray.normals.as_mut().unwrap().extend([Vec3::X; 4]);
    let (mesh, stats) = run(&stray, &ReconstructParams::default());
    assert_eq!(stats.isolated_points, 4);
    assert_eq!(stats.tree.samples, cloud.positions.len());
    assert_eq!(mesh.triangles.len(), alone.triangles.len());
    let moved = mesh.positions.iter().zip(&alone.positions).map(|(a, b)| a.distance(*b)).fold(0.0, f32::max);
    assert!(moved < 1e-4, "a vertex moved {moved}");
}

#[test]
fn a_cloud_that_samples_no_surface_says_so() {
    // Ten points scattered in a cube: no orientation of theirs encloses a volume. The message
    // names the likely causes, not the paper's blended planes, which the default does not use.
    let mut rng = vstree::rng::Rng::new(3);
    let mut failures = 0;
    for _ in 0..8 {
        let points: Vec<Vec3> = (0..10).map(|_| Vec3::new(rng.f32(), rng.f32(), rng.f32())).collect();
        if let Err(e) = reconstruct(&Mesh::from_points(points, None), &Default::default(), &mut Progress::none()) {
            let message = e.to_string();
            assert!(
                message.contains("10 points, normals estimated: too few or too scattered to sample a surface"),
                "{message}"
            );
            assert!(!message.contains("blended"), "{message}");
            failures += 1;
        }
    }
    assert!(failures >= 4, "only {failures} of 8 scattered clouds failed");
}

#[test]
fn the_adaptive_base_mesh_keeps_the_genus_with_a_fraction_of_the_evaluations() {
    // Polygonised over the tree's octree, the field is evaluated at the T-layer's corners
    // instead of along a grid as fine as the deepest T-node: measured 3-14x fewer points
    // here (a surface with handles is polygonised a second time, thickened, on both paths:
    // the pretzel's 6,924 against 21,317), with M0 a closed 2-manifold of the true genus and
    // the same Chamfer within 10%.
    let shapes = [
        ("torus", shapes::torus(1.0, 0.35, 128, 64), 1),
        ("double torus", shapes::double_torus(), 2),
        ("pretzel", shapes::genus_n_pretzel(3), 3),
    ];
    for (name, truth, genus) in shapes {
        let cloud = shapes::sample_surface(&truth, 60_000, 1);
        let (on_grid, grid) = run(&cloud, &ReconstructParams { base_mesh: BaseMesh::Winding, ..Default::default() });
        let (mesh, adaptive) = run(&cloud, &ReconstructParams::default());
        assert!(grid.on_grid && !adaptive.on_grid, "{name}: the adaptive polygonisation fell back to the grid");
        assert_eq!(adaptive.base_genus, Some(genus), "{name}: M0's genus");
        let report = topology::analyze(&mesh);
        assert!(report.is_watertight() && report.genus() == Some(genus), "{name}: {report:?}");
        assert!(
            adaptive.field_evaluations * 5 / 2 < grid.field_evaluations,
            "{name}: {} evaluations, {} on the grid",
            adaptive.field_evaluations,
            grid.field_evaluations
        );
        let chamfer = |m: &Mesh| chamfer_and_hausdorff(m, &truth, 100_000, 1).0;
        let (a, g) = (chamfer(&mesh), chamfer(&on_grid));
        assert!(a < 1.25 * g, "{name}: Chamfer {a:.3e} adaptive, {g:.3e} on the grid");
    }
}

#[test]
fn the_adaptive_base_mesh_keeps_a_ring_thinner_than_its_cells() {
    // A ring 0.06 thick on a 2-wide torus: the corners of many T-nodes along it lie outside
    // it, so the leaves whose corners all agree are split until theirs see it.
    let truth = shapes::torus(1.0, 0.03, 256, 32);
    let cloud = shapes::sample_surface(&truth, 60_000, 1);
    let params = ReconstructParams { base_mesh: BaseMesh::Adaptive, closure: Closure::Closed, ..Default::default() };
    let (mesh, stats) = run(&cloud, &params);
    let report = topology::analyze(&mesh);
    assert!(!stats.on_grid, "fell back to the grid");
    assert_eq!(stats.base_genus, Some(1), "M0's genus");
    assert!(report.is_watertight() && report.components == 1 && report.genus() == Some(1), "{report:?}");
    let (_, hausdorff) = chamfer_and_hausdorff(&mesh, &truth, 100_000, 1);
    assert!(hausdorff < 0.01, "Hausdorff {hausdorff:.3e}");
}

#[test]
fn a_small_dense_part_beside_a_sparse_one_comes_out_whole() {
    // A very uneven T-layer: a torus 0.05 across sampled 100 times as densely as a sphere 2
    // across beside it. Its T-nodes are hundreds of times smaller than the sphere's; both come
    // out closed with their own genus, on their surfaces.
    let sphere = sphere_points(5_000, |_| true);
    let (major, minor, centre) = (0.02, 0.006, Vec3::new(1.5, 0.0, 0.0));
    let mut torus = shapes::sample_surface(&shapes::torus(major, minor, 64, 32), 500_000, 3);
    torus.positions.iter_mut().for_each(|p| *p += centre);
    let mut cloud = sphere.clone();
    cloud.positions.extend(&torus.positions);
    cloud.normals.as_mut().unwrap().extend(torus.normals.as_ref().unwrap());
    let (mesh, _) = run(&cloud, &ReconstructParams::default());
    let report = topology::analyze(&mesh);
    let mut parts = report.component_euler_characteristics.clone();
    parts.sort_unstable();
    assert!(report.is_watertight() && parts == [0, 2], "{report:?}");
    let off_surface = |p: Vec3| {
        let q = p - centre;
        if q.length() < 0.1 {
            ((Vec3::new(q.x, q.y, 0.0).length() - major).hypot(q.z) - minor).abs() / minor
        } else {
            (p.length() - 1.0).abs()
        }
    };
    let worst = mesh.positions.iter().map(|&p| off_surface(p)).fold(0.0, f32::max);
    assert!(worst < 0.1, "a vertex {worst} off its surface (in the torus's tube radii or the sphere's radius)");
}

#[test]
fn a_target_distance_spends_the_triangles_where_the_detail_is() {
    // A unit sphere with bumps 0.02 high on its upper cap only (z > 0.4). Without a target every
    // level splits every triangle (M0 is already denser on the cap, where its T-nodes are
    // smaller). With one, a level splits only the regions whose samples are farther than the
    // target (in RMS) from their triangles: the smooth lower part stops early, the bumpy cap
    // goes on, and the red-green transitions keep one closed surface of genus 0.
    let mut truth = shapes::icosphere(1.0, 7);
    for p in &mut truth.positions {
        let rise = ((p.z - 0.4) / 0.6).clamp(0.0, 1.0);
        *p *= 1.0 + 0.02 * rise * (40.0 * p.x).sin() * (40.0 * p.y).sin();
    }
    truth.normals = None;
    let cloud = shapes::sample_surface(&truth, 150_000, 5);
    let diagonal = cloud.bounds().unwrap().diagonal();
    // Triangles per unit area over the bumpy cap (z > 0.5) over those of the lower half.
    let contrast = |mesh: &Mesh| {
        let density = |keep: &dyn Fn(f32) -> bool| {
            let (mut count, mut area) = (0usize, 0.0f32);
            for t in &mesh.triangles {
                let [a, b, c] = t.map(|v| mesh.positions[v as usize]);
                if keep((a.z + b.z + c.z) / 3.0) {
                    count += 1;
                    area += (b - a).cross(c - a).length() / 2.0;
                }
            }
            count as f32 / area
        };
        density(&|z| z > 0.5) / density(&|z| z < -0.1)
    };
    let (uniform, _) = run(&cloud, &ReconstructParams::default());
    let target = ReconstructParams { target_distance: TARGET, ..Default::default() };
    let (adaptive, stats) = run(&cloud, &target);
    let report = topology::analyze(&adaptive);
    let (chamfer, _) = chamfer_and_hausdorff(&adaptive, &truth, 100_000, 3);
    eprintln!(
        "contrast: uniform {:.2}, adaptive {:.2}; triangles {} and {}; adaptive levels {:?}, error {:.2e}, chamfer {:.2e}",
        contrast(&uniform),
        contrast(&adaptive),
        uniform.triangles.len(),
        adaptive.triangles.len(),
        stats.levels,
        stats.final_error,
        chamfer / diagonal
    );
    // Measured: contrast 2.77 without a target, 4.03 with; 141k triangles where splitting all
    // of M0's 158 five times makes 162k (the lower part stopped at the fourth level).
    assert!(contrast(&adaptive) > 1.3 * contrast(&uniform));
    let everywhere = stats.base_triangles * 4usize.pow(stats.levels.len() as u32);
    assert!(10 * adaptive.triangles.len() < 9 * everywhere, "{} of {everywhere}", adaptive.triangles.len());
    assert!(report.is_watertight() && report.components == 1 && report.genus() == Some(0), "{report:?}");
    assert_eq!(stats.stopped, RefinementStop::Target, "{stats:?}");
    assert!(stats.final_error <= TARGET);
    assert!(chamfer < 2.0 * TARGET as f32 * diagonal, "{chamfer}");
}

/// The target of [`a_target_distance_spends_the_triangles_where_the_detail_is`], over the
/// diagonal.
const TARGET: f64 = 1e-4;
