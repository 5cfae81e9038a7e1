//! Coordinates far from the origin (georeferenced scans): positions are read in f64 and stored
//! in f32 relative to an origin of the model's own, so a model 1e6 or 1e8 away gives the same
//! results as at the origin, and what is written reads back exactly.

mod common;

use common::scratch::Scratch;
use glam::{DVec3, Vec3};
use std::fmt::Write as _;
use std::path::Path;
use vstree::reconstruct::{reconstruct, ReconstructParams};
use vstree::{eval::shapes, io, simplify, Mesh, Progress, SimplifyParams};

/// `mesh` moved by `offset`, written as text in f64 the way a georeferencing tool would, and
/// read back: an XYZ file for a cloud, an ASCII PLY for a mesh.
fn read_moved(mesh: &Mesh, offset: f64, dir: &Path) -> Mesh {
    let mut text = String::new();
    let normals = mesh.normals.as_deref().unwrap();
    let path = if mesh.is_point_cloud() {
        for (p, n) in mesh.positions.iter().zip(normals) {
            let q = p.as_dvec3() + offset;
            writeln!(text, "{} {} {} {} {} {}", q.x, q.y, q.z, n.x, n.y, n.z).unwrap();
        }
        dir.join(format!("cloud-{offset:e}.xyz"))
    } else {
        let (v, f) = (mesh.positions.len(), mesh.triangles.len());
        write!(
            text,
            "ply\nformat ascii 1.0\nelement vertex {v}\nproperty double x\nproperty double y\n\
             property double z\nelement face {f}\nproperty list uchar int vertex_indices\nend_header\n"
        )
        .unwrap();
        for p in &mesh.positions {
            let q = p.as_dvec3() + offset;
            writeln!(text, "{} {} {}", q.x, q.y, q.z).unwrap();
        }
        for [a, b, c] in &mesh.triangles {
            writeln!(text, "3 {a} {b} {c}").unwrap();
        }
        dir.join(format!("mesh-{offset:e}.ply"))
    };
    std::fs::write(&path, text).unwrap();
    io::read(&path).unwrap()
}

/// The largest distance between corresponding vertices of two meshes of the same size, the
/// second moved back by `offset`.
fn largest_difference(a: &Mesh, b: &Mesh, offset: f64) -> f64 {
    assert_eq!((a.positions.len(), a.triangles.len()), (b.positions.len(), b.triangles.len()));
    (0..a.positions.len()).map(|i| (b.absolute(i) - offset - a.absolute(i)).length()).fold(0.0, f64::max)
}

#[test]
fn simplification_is_the_same_wherever_the_model_is() {
    let scratch = Scratch::new("far-simplify");
    let sphere = shapes::icosphere(1.0, 4);
    let params = SimplifyParams::default();
    let at_origin = read_moved(&sphere, 0.0, &scratch.0);
    assert_eq!(at_origin.origin, DVec3::ZERO);
    let (reference, _) = simplify(&at_origin, &params, &mut Progress::none()).unwrap();
    for offset in [1e6, 1e8] {
        let moved = read_moved(&sphere, offset, &scratch.0);
        assert_eq!(moved.origin, DVec3::splat(offset), "the centre, which f32 holds exactly");
        let (simplified, _) = simplify(&moved, &params, &mut Progress::none()).unwrap();
        assert_eq!(simplified.origin, moved.origin);
        // Diagonal about 3.5: within 1e-6 of it.
        let d = largest_difference(&reference, &simplified, offset);
        assert!(d < 3.5e-6, "offset {offset:e}: vertices {d:e} apart");
    }
}

#[test]
fn reconstruction_is_the_same_wherever_the_cloud_is() {
    let scratch = Scratch::new("far-reconstruct");
    let cloud = shapes::sample_surface(&shapes::icosphere(1.0, 5), 5000, 11);
    let params = ReconstructParams { max_levels: 2, ..Default::default() };
    let at_origin = read_moved(&cloud, 0.0, &scratch.0);
    let (reference, _) = reconstruct(&at_origin, &params, &mut Progress::none()).unwrap();
    for offset in [1e6, 1e8] {
        let moved = read_moved(&cloud, offset, &scratch.0);
        let (mesh, stats) = reconstruct(&moved, &params, &mut Progress::none()).unwrap();
        assert_eq!(stats.base_genus, Some(0), "offset {offset:e}");
        assert_eq!(mesh.origin, moved.origin);
        let d = largest_difference(&reference, &mesh, offset);
        assert!(d < 3.5e-6, "offset {offset:e}: vertices {d:e} apart");
    }
}

#[test]
fn float_input_far_away_reads_and_writes_back_exactly() {
    let scratch = Scratch::new("far-roundtrip");
    // A binary PLY of float32 coordinates around 1e6, detail down to the float's 1/16 there.
    let sphere = shapes::icosphere(1.0, 3);
    let absolute: Vec<Vec3> = sphere.positions.iter().map(|p| *p * 7.0 + Vec3::new(1e6, -2e6, 5e5)).collect();
    let input = scratch.0.join("far.ply");
    io::write(&input, &Mesh { positions: absolute.clone(), ..sphere.clone() }).unwrap();
    let read = io::read(&input).unwrap();
    assert_ne!(read.origin, DVec3::ZERO);
    for (i, p) in absolute.iter().enumerate() {
        assert_eq!(read.absolute(i), p.as_dvec3(), "vertex {i} read");
    }
    // The relative positions keep what f32 at 1e6 cannot: a millimetre moves a vertex.
    let mut moved = read.clone();
    moved.positions[0].x += 0.001;
    for name in ["out.ply", "out.obj", "out.off", "out.xyz", "out-ascii.ply"] {
        let path = scratch.0.join(name);
        let options = io::WriteOptions { ascii: name.contains("ascii") };
        io::write_with(&path, &moved, &options).unwrap();
        let back = io::read(&path).unwrap();
        // (OBJ vertices come back in the order faces first use them.)
        let sorted = |m: &Mesh| {
            let mut all: Vec<[f64; 3]> = (0..m.positions.len()).map(|i| m.absolute(i).to_array()).collect();
            all.sort_by(|a, b| a.partial_cmp(b).unwrap());
            all
        };
        assert_eq!(sorted(&back), sorted(&moved), "{name}");
        assert_eq!(back.triangles.len(), if name.ends_with("xyz") { 0 } else { moved.triangles.len() }, "{name}");
    }
}

#[test]
fn doubles_given_through_the_c_api_keep_their_detail_far_away() {
    use std::ptr::null;
    use vstree::ffi::{mesh::*, vstree_status};
    // A unit sphere at 1e6 and 1e8, given in doubles as a host with georeferenced data would:
    // float coordinates there are 1/16 and 8 apart; kept as a file's positions are, every
    // radius is within 1e-6 of 1.
    let sphere = shapes::icosphere(1.0, 4);
    for offset in [1e6, 1e8] {
        let moved: Vec<f64> = sphere.positions.iter().flat_map(|p| (p.as_dvec3() + offset).to_array()).collect();
        let triangles: Vec<u32> = sphere.triangles.iter().flatten().copied().collect();
        let (n, t) = (sphere.positions.len(), sphere.triangles.len());
        let mut handle = std::ptr::null_mut();
        let status = unsafe { vstree_mesh_create_f64(moved.as_ptr(), n, null(), triangles.as_ptr(), t, &mut handle) };
        assert_eq!(status, vstree_status::Ok, "offset {offset:e}");
        let mut back = vec![0f64; 3 * n];
        assert_eq!(unsafe { vstree_mesh_copy_positions_f64(handle, back.as_mut_ptr(), back.len()) }, vstree_status::Ok);
        assert_eq!(unsafe { vstree_mesh_triangle_count(handle) }, t);
        unsafe { vstree_mesh_free(handle) };
        let worst =
            back.chunks(3).map(|c| (DVec3::from_slice(c) - offset).length() - 1.0).fold(0.0, |w, e| e.abs().max(w));
        // The sphere's own rounding in f32 is 6e-8 of it.
        assert!(worst < 1e-6, "offset {offset:e}: radius error {worst:e}");
    }
}
