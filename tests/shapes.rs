//! Generated shapes, topology figures and distances, asserted on figures whose answer is known.

mod common;

use glam::Vec3;
use std::path::Path;
use vstree::eval::distance::{chamfer_and_hausdorff, one_sided, point_to_mesh_distances, Target};
use vstree::eval::figures::{signed_volume, surface_area, valence_histogram, valences};
use vstree::eval::shapes::{
    add_noise, bumpy_radius, bumpy_sphere, double_torus, genus_n_pretzel, icosphere, implicit_mesh, sample_surface,
    torus,
};
use vstree::spatial::TriangleBvh;
use vstree::topology::analyze;
use vstree::Mesh;

/// Asserts a closed, oriented, positive-volume surface of the given genus, one component, with
/// one unit normal per vertex.
fn assert_closed_surface(name: &str, mesh: &Mesh, genus: u32) {
    let report = analyze(mesh);
    assert!(report.is_watertight(), "{name}: {report:?}");
    assert_eq!(report.genus(), Some(genus), "{name}: {report:?}");
    assert_eq!(report.components, 1, "{name}");
    assert_eq!(report.unreferenced_vertices, 0, "{name}");
    assert_eq!(report.euler_characteristic, 2 - 2 * i64::from(genus), "{name}");
    assert!(signed_volume(mesh) > 0.0, "{name}: volume {}", signed_volume(mesh));
    let normals = mesh.normals.as_ref().expect("normals");
    assert_eq!(normals.len(), mesh.positions.len(), "{name}");
    assert!(normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-4), "{name}: normals not unit");
    mesh.check().unwrap();
}

/// Fraction of vertex normals that point away from the inside along `outward(p)`.
fn fraction_outward(mesh: &Mesh, outward: impl Fn(Vec3) -> Vec3) -> f32 {
    let normals = mesh.normals.as_ref().unwrap();
    let good = mesh.positions.iter().zip(normals).filter(|(p, n)| n.dot(outward(**p)) > 0.0).count();
    good as f32 / mesh.positions.len() as f32
}

#[test]
fn icosphere_figures() {
    let m = icosphere(1.0, 4);
    assert_eq!(m.positions.len(), 10 * 4usize.pow(4) + 2);
    assert_eq!(m.triangles.len(), 20 * 4usize.pow(4));
    assert_closed_surface("icosphere", &m, 0);
    assert_eq!(analyze(&m).euler_characteristic, 2);
    for p in &m.positions {
        assert!((p.length() - 1.0).abs() <= 1e-6, "{p} has radius {}", p.length());
    }
    // Twelve valence-5 vertices, the rest valence 6.
    assert_eq!(valence_histogram(&m), {
        let mut h = vec![0; 7];
        h[5] = 12;
        h[6] = m.positions.len() as u32 - 12;
        h
    });
    let volume = signed_volume(&icosphere(2.0, 5));
    let exact = 4.0 / 3.0 * std::f64::consts::PI * 8.0;
    assert!((volume - exact).abs() < 2e-3 * exact, "{volume} vs {exact}");
    assert_closed_surface("icosphere 0", &icosphere(3.0, 0), 0);
}

#[test]
fn torus_figures() {
    let m = torus(2.0, 0.5, 48, 16);
    assert_eq!((m.positions.len(), m.triangles.len()), (48 * 16, 2 * 48 * 16));
    assert_closed_surface("torus", &m, 1);
    let exact = 2.0 * std::f64::consts::PI.powi(2) * 2.0 * 0.25;
    let volume = signed_volume(&m);
    assert!((volume - exact).abs() < 0.03 * exact, "{volume} vs {exact}");
    assert!(valences(&m).iter().all(|&v| v == 6));
    // Degenerate segment counts are raised to 3.
    assert_closed_surface("torus 3x3", &torus(1.0, 0.3, 0, 1), 1);
}

#[test]
fn genus_n_surfaces() {
    assert_closed_surface("double torus", &double_torus(), 2);
    for n in [0, 1, 3, 4] {
        let m = genus_n_pretzel(n);
        assert_closed_surface(&format!("pretzel {n}"), &m, n);
        // Every vertex lies near the zero set: its distance to the nearest torus centre circle
        // is the minor radius 0.35, up to 0.40 at the joints where the smooth union (blend
        // width 0.2) adds material.
        if n > 0 {
            let centres: Vec<f32> = (0..n).map(|i| 2.0 * i as f32 - (n as f32 - 1.0)).collect();
            for p in &m.positions {
                let d = centres
                    .iter()
                    .map(|&cx| {
                        let q = *p - Vec3::X * cx;
                        let ring = (q.x * q.x + q.y * q.y).sqrt() - 1.0;
                        (ring * ring + q.z * q.z).sqrt()
                    })
                    .fold(f32::INFINITY, f32::min);
                assert!((0.33..0.41).contains(&d), "pretzel {n}: {p} at {d}");
            }
        }
    }
}

#[test]
fn bumpy_sphere_lies_on_its_surface() {
    let (radius, amplitude, frequency) = (1.5, 0.2, 6.0);
    let m = bumpy_sphere(radius, amplitude, frequency, 5);
    assert_closed_surface("bumpy sphere", &m, 0);
    for p in &m.positions {
        let r = bumpy_radius(p.normalize(), radius, amplitude, frequency);
        assert!((p.length() - r).abs() < 1e-5);
    }
    let lengths: Vec<f32> = m.positions.iter().map(|p| p.length()).collect();
    let (lo, hi) = lengths.iter().fold((f32::MAX, 0.0f32), |(lo, hi), &r| (lo.min(r), hi.max(r)));
    assert!(hi - lo > 0.25 * radius, "bumps too small: {lo}..{hi}");
    assert!(fraction_outward(&m, |p| p) > 0.95);
}

#[test]
fn implicit_mesh_normals_follow_the_gradient() {
    let m = implicit_mesh(|p| (p / Vec3::new(1.0, 0.6, 0.4)).length() - 1.0, Vec3::splat(-1.2), Vec3::splat(1.2), 40);
    assert_closed_surface("ellipsoid", &m, 0);
    let exact = 4.0 / 3.0 * std::f64::consts::PI * 0.24;
    assert!((signed_volume(&m) - exact).abs() < 0.02 * exact);
    // The ellipsoid's outward normal is along (x/a^2, y/b^2, z/c^2).
    let normals = m.normals.as_ref().unwrap();
    for (p, n) in m.positions.iter().zip(normals) {
        let exact = (*p / Vec3::new(1.0, 0.36, 0.16)).normalize();
        assert!(n.dot(exact) > 0.98, "{p}: {n} vs {exact}");
    }
}

#[test]
fn implicit_mesh_is_deterministic_across_thread_counts() {
    let run =
        |threads| rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(genus_n_pretzel_small);
    assert_eq!(run(1), run(2));
}

fn genus_n_pretzel_small() -> Mesh {
    implicit_mesh(
        |p| (p.length() - 1.0).min((p - Vec3::X * 1.2).length() - 0.5),
        Vec3::splat(-1.5),
        Vec3::splat(2.0),
        30,
    )
}

#[test]
fn sampling_a_sphere() {
    let sphere = icosphere(1.0, 6);
    let count = 100_003;
    let cloud = sample_surface(&sphere, count, 7);
    assert!(cloud.is_point_cloud());
    assert_eq!(cloud.positions.len(), count);
    let normals = cloud.normals.as_ref().unwrap();
    assert_eq!(normals.len(), count);
    for (p, n) in cloud.positions.iter().zip(normals) {
        assert!((p.length() - 1.0).abs() < 1e-3, "{p} at radius {}", p.length());
        assert!(n.dot(p.normalize()) > 0.999);
    }
    // Uniform by area: each octant holds about an eighth of the points.
    let mut octants = [0usize; 8];
    for p in &cloud.positions {
        let o = usize::from(p.x > 0.0) | usize::from(p.y > 0.0) << 1 | usize::from(p.z > 0.0) << 2;
        octants[o] += 1;
    }
    for n in octants {
        let expected = count as f32 / 8.0;
        assert!((n as f32 - expected).abs() < 0.03 * expected, "{octants:?}");
    }
    // Seeds matter; a mesh without area gives nothing.
    assert_ne!(sample_surface(&sphere, 10, 8).positions, cloud.positions[..10]);
    assert_eq!(sample_surface(&sphere, 10, 7).positions, cloud.positions[..10]);
    assert!(sample_surface(&Mesh::default(), 10, 1).positions.is_empty());
    let flat = Mesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::X * 2.0], None, vec![[0, 1, 2], [0, 1, 7]]);
    assert!(sample_surface(&flat, 10, 1).positions.is_empty());
}

#[test]
fn sampling_is_uniform_across_triangles_of_different_size() {
    // Two triangles, areas 1 and 3: expect a quarter and three quarters of the points.
    let m = Mesh::new(
        vec![
            Vec3::ZERO,
            Vec3::X * 2.0,
            Vec3::Y,
            Vec3::new(10.0, 0.0, 0.0),
            Vec3::new(16.0, 0.0, 0.0),
            Vec3::new(10.0, 1.0, 0.0),
        ],
        None,
        vec![[0, 1, 2], [3, 4, 5]],
    );
    let cloud = sample_surface(&m, 40_000, 3);
    let small = cloud.positions.iter().filter(|p| p.x < 5.0).count();
    assert!((small as f32 / 40_000.0 - 0.25).abs() < 0.01, "{small}");
    assert!(cloud.normals.unwrap().iter().all(|n| *n == Vec3::Z));
}

#[test]
fn sampling_and_noise_are_deterministic_across_thread_counts() {
    let mesh = torus(1.0, 0.3, 64, 24);
    let run = |threads| {
        rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(|| {
            let mut cloud = sample_surface(&mesh, 200_001, 42);
            add_noise(&mut cloud, 0.01, 0.1, 43);
            cloud
        })
    };
    let (one, two) = (run(1), run(2));
    assert_eq!(one, two);
    assert_ne!(one, sample_surface(&mesh, 200_001, 42));
}

#[test]
fn distances_to_an_offset_sphere() {
    let sphere = icosphere(1.0, 5);
    for offset in [0.1f32, -0.2] {
        let points = sample_surface(&icosphere(1.0 + offset, 5), 20_000, 1).positions;
        let d = point_to_mesh_distances(&points, &sphere);
        for x in &d {
            assert!((x - offset.abs()).abs() < 2e-3, "{x} vs {offset}");
        }
        let stats = one_sided(&points, Target::of(&sphere));
        assert_eq!(stats.count, points.len());
        assert!((stats.mean - offset.abs()).abs() < 1e-3);
        assert!(stats.p99 <= stats.max && stats.mean <= stats.rms);
    }
    // The closest point lies on the faceted sphere, near the query's direction (a facet's
    // normal is up to ~0.02 rad off the radial direction, times the distance 1.14).
    let bvh = TriangleBvh::new(&sphere);
    let q = Vec3::new(0.3, -2.0, 0.7);
    let c = bvh.closest_point(q).unwrap();
    assert!((c.point - q.normalize()).length() < 0.03);
    assert!(c.point.length() <= 1.0 + 1e-6 && c.point.length() > 0.999);
    assert!((c.distance - (q.length() - 1.0)).abs() < 1e-3);
    assert!(c.triangle < sphere.triangles.len() as u32);
}

#[test]
fn chamfer_and_hausdorff_of_spheres() {
    let a = icosphere(1.0, 5);
    let b = icosphere(1.05, 5);
    let (chamfer, hausdorff) = chamfer_and_hausdorff(&a, &b, 20_000, 5);
    assert!((chamfer - 0.05).abs() < 1e-3, "{chamfer}");
    assert!((hausdorff - 0.05).abs() < 2e-3, "{hausdorff}");
    // Against a noisy sampled cloud of itself: distances are about the noise.
    let mut cloud = sample_surface(&a, 50_000, 9);
    add_noise(&mut cloud, 0.01, 0.0, 10);
    let (chamfer, _) = chamfer_and_hausdorff(&a, &cloud, 20_000, 5);
    assert!(chamfer > 0.005 && chamfer < 0.02, "{chamfer}");
    // A mesh against itself: zero up to rounding, and the same figures on every call.
    let same = chamfer_and_hausdorff(&a, &a, 1_000, 1);
    assert_eq!(same, chamfer_and_hausdorff(&a, &a, 1_000, 1));
    assert!(same.1 < 1e-5, "{same:?}");
}

#[test]
fn topology_detects_defects() {
    let base = icosphere(1.0, 2);
    assert!(analyze(&base).is_watertight());

    // A removed triangle leaves a triangular hole.
    let mut holed = base.clone();
    holed.triangles.remove(17);
    let r = analyze(&holed);
    assert_eq!(r.boundary_edges, 3);
    assert!(!r.is_watertight());
    assert_eq!(r.genus(), None);
    assert_eq!(r.euler_characteristic, 1);

    // A flipped triangle disagrees with its three neighbours.
    let mut flipped = base.clone();
    flipped.triangles[5].swap(0, 1);
    let r = analyze(&flipped);
    assert_eq!(r.inconsistently_oriented_edges, 3);
    assert_eq!(r.boundary_edges, 0);
    assert!(!r.is_watertight());

    // A fin: a third face on an existing edge.
    let mut fin = base.clone();
    let [a, b, _] = fin.triangles[0];
    fin.positions.push(Vec3::new(3.0, 3.0, 3.0));
    let apex = fin.positions.len() as u32 - 1;
    fin.triangles.push([b, a, apex]);
    let r = analyze(&fin);
    assert_eq!(r.non_manifold_edges, 1);
    assert_eq!(r.boundary_edges, 2);
    assert!(r.non_manifold_vertices >= 2);
    assert!(!r.is_watertight());

    // Two spheres: two components, each genus 0.
    let mut two = base.clone();
    let shift = base.positions.len() as u32;
    two.positions.extend(base.positions.iter().map(|p| *p + Vec3::X * 5.0));
    two.triangles.extend(base.triangles.iter().map(|t| t.map(|v| v + shift)));
    two.normals = None;
    let r = analyze(&two);
    assert_eq!((r.components, r.genus()), (2, Some(0)));
    assert_eq!(r.euler_characteristic, 4);

    // A sphere and a torus: genus adds up.
    let mut mixed = torus(1.0, 0.3, 24, 12);
    let shift = mixed.positions.len() as u32;
    mixed.positions.extend(&base.positions);
    mixed.triangles.extend(base.triangles.iter().map(|t| t.map(|v| v + shift)));
    assert_eq!(analyze(&mixed).genus(), Some(1));

    let area = surface_area(&icosphere(1.0, 6));
    assert!((area - 4.0 * std::f64::consts::PI).abs() < 1e-3 * 4.0 * std::f64::consts::PI);
}

/// Reads the vertices and triangles of an OFF file (enough for the shared test data; the
/// project's own reader lives on another branch).
fn read_off(path: &Path) -> Mesh {
    let text = std::fs::read_to_string(path).unwrap();
    let mut tokens = text.lines().map(|l| l.split('#').next().unwrap_or("")).flat_map(str::split_whitespace);
    assert_eq!(tokens.next(), Some("OFF"));
    let mut number = || tokens.next().unwrap().parse::<f64>().unwrap();
    let (nv, nf) = (number() as usize, number() as usize);
    number();
    let positions = (0..nv).map(|_| Vec3::new(number() as f32, number() as f32, number() as f32)).collect();
    let mut triangles = Vec::new();
    for _ in 0..nf {
        let k = number() as usize;
        let ids: Vec<u32> = (0..k).map(|_| number() as u32).collect();
        for i in 1..k.saturating_sub(1) {
            triangles.push([ids[0], ids[i], ids[i + 1]]);
        }
    }
    Mesh::new(positions, None, triangles)
}

#[test]
fn real_meshes_have_their_documented_genus() {
    let Some(data) = common::data_dir() else { return };
    for (file, genus) in [("3holes.off", 3), ("fertility_20k.off", 4), ("eight.off", 2), ("knot1.off", 1)] {
        let path = data.join(file);
        assert!(path.is_file(), "{} not found", path.display());
        let mesh = read_off(&path);
        let report = analyze(&mesh);
        assert!(report.is_watertight(), "{file}: {report:?}");
        assert_eq!(report.genus(), Some(genus), "{file}: {report:?}");
        // A mesh's own vertices are on its surface; samples of it too.
        let samples = sample_surface(&mesh, 2_000, 1).positions;
        let d = point_to_mesh_distances(&samples, &mesh);
        let diagonal = mesh.bounds().unwrap().diagonal();
        assert!(d.iter().all(|&x| x <= 1e-5 * diagonal), "{file}");
    }
}
