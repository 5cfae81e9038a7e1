//! Timings of the measurement tools at scale. Ignored by default; run with
//! `cargo test --release --test shapes_perf -- --ignored --nocapture --test-threads 1`.

use glam::Vec3;
use std::time::Instant;
use vstree::eval::distance::{point_to_mesh_distances, point_to_points_distances};
use vstree::eval::shapes::{add_noise, genus_n_pretzel, icosphere, sample_surface, torus};
use vstree::rng::Rng;
use vstree::spatial::{KdTree, TriangleBvh};
use vstree::topology::analyze;

fn timed<T>(label: &str, f: impl FnOnce() -> T) -> T {
    let start = Instant::now();
    let out = f();
    println!("{label}: {:.3} s", start.elapsed().as_secs_f64());
    out
}

#[test]
#[ignore = "timing; run in release"]
fn timings() {
    println!("rayon threads: {}", rayon::current_num_threads());
    // 2 * 500 * 100 = 100,000 triangles.
    let mesh = torus(1.0, 0.3, 500, 100);
    assert_eq!(mesh.triangles.len(), 100_000);

    let cloud = timed("sample_surface 5M points (100k triangles)", || sample_surface(&mesh, 5_000_000, 1));
    assert_eq!(cloud.positions.len(), 5_000_000);
    let mut noisy = timed("sample_surface 1M points", || sample_surface(&mesh, 1_000_000, 2));
    timed("add_noise 1M points", || add_noise(&mut noisy, 0.005, 0.05, 3));

    let bvh = timed("TriangleBvh::new 100k triangles", || TriangleBvh::new(&mesh));
    assert_eq!(bvh.len(), 100_000);
    let d = timed("point_to_mesh_distances 1M queries vs 100k triangles", || {
        point_to_mesh_distances(&noisy.positions, &mesh)
    });
    assert!(d.iter().all(|x| x.is_finite()));
    // Queries spread through the bounding box (up to ~1 unit from the surface) prune less.
    let mut rng = Rng::new(4);
    let far: Vec<Vec3> =
        (0..1_000_000).map(|_| Vec3::new(rng.f32() * 3.0 - 1.5, rng.f32() * 3.0 - 1.5, rng.f32() - 0.5)).collect();
    let d = timed("point_to_mesh_distances 1M box-uniform queries vs 100k triangles", || {
        point_to_mesh_distances(&far, &mesh)
    });
    assert!(d.iter().all(|x| x.is_finite()));

    let points = timed("KdTree::new 1M points", || KdTree::new(&cloud.positions[..1_000_000]).unwrap());
    assert_eq!(points.len(), 1_000_000);
    let d = timed("point_to_points_distances 1M queries vs 1M points", || {
        point_to_points_distances(&noisy.positions, &cloud.positions[..1_000_000])
    });
    assert!(d.iter().all(|x| x.is_finite()));

    let big = timed("icosphere(1, 8): 1.3M triangles", || icosphere(1.0, 8));
    let report = timed("analyze 1.3M triangles", || analyze(&big));
    assert_eq!(report.genus(), Some(0));

    let pretzel = timed("genus_n_pretzel(4)", || genus_n_pretzel(4));
    println!("  {} triangles", pretzel.triangles.len());
}
