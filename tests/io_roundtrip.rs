//! Writing then reading gives the same mesh: exactly for binary PLY, within a tolerance for
//! text formats. Binary PLY of both byte orders is also read from hand-built byte buffers.

mod common;

use common::scratch::Scratch;
use glam::Vec3;
use std::path::Path;
use vstree::io::{self, WriteOptions};
use vstree::Mesh;

/// A square pyramid whose coordinates need all of f32's digits; every vertex is used and
/// vertices are first used in index order.
fn pyramid(with_normals: bool) -> Mesh {
    let positions = vec![
        Vec3::new(0.1, -2.5e-3, 1234.5677),
        Vec3::new(1.0 / 3.0, 0.0, -7.25),
        Vec3::new(1e-7, 3.0e4, 0.2),
        Vec3::new(-1.0, -1.0, -1.0),
        Vec3::new(0.5, 0.5, std::f32::consts::PI),
    ];
    let normals = positions.iter().map(|p| p.normalize()).collect();
    Mesh::new(
        positions,
        with_normals.then_some(normals),
        vec![[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 1], [1, 4, 3], [1, 3, 2]],
    )
}

fn close(a: &[Vec3], b: &[Vec3]) -> bool {
    a.len() == b.len()
        && a.iter().zip(b).all(|(p, q)| (*p - *q).abs().max_element() <= 1e-5 * (1.0 + p.abs().max_element()))
}

fn assert_close(got: &Mesh, want: &Mesh, what: &str) {
    assert!(close(&got.positions, &want.positions), "{what}: positions");
    match (&got.normals, &want.normals) {
        (Some(a), Some(b)) => assert!(close(a, b), "{what}: normals"),
        (None, None) => {}
        _ => panic!("{what}: normals present in one mesh only"),
    }
    assert_eq!(got.triangles, want.triangles, "{what}: triangles");
}

fn cycle(dir: &Path, name: &str, mesh: &Mesh, options: &WriteOptions) -> Mesh {
    let path = dir.join(name);
    io::write_with(&path, mesh, options).unwrap();
    io::read(&path).unwrap()
}

#[test]
fn binary_ply_is_exact() {
    let dir = Scratch::new("io-rt-binary");
    for normals in [false, true] {
        let mesh = pyramid(normals);
        assert_eq!(cycle(&dir.0, "m.ply", &mesh, &WriteOptions::default()), mesh);
        let cloud = Mesh::from_points(mesh.positions.clone(), mesh.normals.clone());
        assert_eq!(cycle(&dir.0, "c.PLY", &cloud, &WriteOptions::default()), cloud);
    }
}

#[test]
fn ascii_ply_round_trips() {
    let dir = Scratch::new("io-rt-ascii");
    let ascii = WriteOptions { ascii: true };
    for normals in [false, true] {
        let mesh = pyramid(normals);
        assert_close(&cycle(&dir.0, "m.ply", &mesh, &ascii), &mesh, "ascii ply");
        let text = std::fs::read_to_string(dir.0.join("m.ply")).unwrap();
        assert!(text.starts_with("ply\nformat ascii 1.0\n"));
    }
}

#[test]
fn point_clouds_are_written_without_faces() {
    let dir = Scratch::new("io-rt-cloud");
    let cloud = Mesh::from_points(pyramid(true).positions, pyramid(true).normals);
    for (name, ascii) in [("a.ply", true), ("b.ply", false)] {
        let got = cycle(&dir.0, name, &cloud, &WriteOptions { ascii });
        assert_close(&got, &cloud, name);
        let bytes = std::fs::read(dir.0.join(name)).unwrap();
        let header = String::from_utf8_lossy(&bytes[..bytes.len().min(300)]).into_owned();
        assert!(!header.contains("element face"), "{header}");
    }
    for name in ["c.obj", "d.xyz", "e.pwn"] {
        assert_close(&cycle(&dir.0, name, &cloud, &WriteOptions::default()), &cloud, name);
    }
    let off = cycle(&dir.0, "f.off", &cloud, &WriteOptions::default());
    assert!(off.is_point_cloud() && close(&off.positions, &cloud.positions));
}

#[test]
fn obj_round_trips() {
    let dir = Scratch::new("io-rt-obj");
    for normals in [false, true] {
        let mesh = pyramid(normals);
        assert_close(&cycle(&dir.0, "m.obj", &mesh, &WriteOptions::default()), &mesh, "obj");
    }
}

#[test]
fn off_round_trips_without_normals() {
    let dir = Scratch::new("io-rt-off");
    for normals in [false, true] {
        let mesh = pyramid(normals);
        let got = cycle(&dir.0, "m.off", &mesh, &WriteOptions::default());
        // Plain OFF has no normals.
        assert_close(&got, &Mesh { normals: None, ..mesh }, "off");
    }
}

#[test]
fn xyz_round_trips_points() {
    let dir = Scratch::new("io-rt-xyz");
    for normals in [false, true] {
        let mesh = pyramid(normals);
        let got = cycle(&dir.0, "m.xyz", &mesh, &WriteOptions::default());
        let points = Mesh::from_points(mesh.positions, mesh.normals);
        assert_close(&got, &points, "xyz");
    }
}

/// Appends values in one byte order.
struct Body {
    bytes: Vec<u8>,
    big: bool,
}

impl Body {
    fn put<const N: usize>(&mut self, le: [u8; N]) -> &mut Body {
        let mut b = le;
        if self.big {
            b.reverse();
        }
        self.bytes.extend_from_slice(&b);
        self
    }
}

/// A PLY with every scalar type, an unknown element with a list, an extra face property,
/// and a quad, in the given byte order.
fn hand_built(big: bool) -> Vec<u8> {
    let format = if big { "binary_big_endian" } else { "binary_little_endian" };
    let header = format!(
        "ply\nformat {format} 1.0\ncomment hand-built\nobj_info test\n\
         element vertex 4\nproperty float x\nproperty float64 y\nproperty short z\n\
         property uchar red\nproperty char c\nproperty ushort u\nproperty int i\nproperty uint ui\n\
         property double nx\nproperty float32 ny\nproperty int8 nz\n\
         element range_grid 2\nproperty list uint16 int32 idx\n\
         element face 2\nproperty int flags\nproperty list uint8 uint vertex_index\n\
         end_header\n"
    );
    let mut body = Body { bytes: header.into_bytes(), big };
    let vertices: [(f32, f64, i16); 4] = [(0.5, -1.25, 3), (1.0, 0.0, -2), (-0.25, 2.0, 0), (7.0, 1e-3, 100)];
    for (k, (x, y, z)) in vertices.into_iter().enumerate() {
        body.put(x.to_le_bytes()).put(y.to_le_bytes()).put(z.to_le_bytes());
        body.put([200u8]).put([(-3i8) as u8]).put(60000u16.to_le_bytes());
        body.put((-70000i32).to_le_bytes()).put(4_000_000_000u32.to_le_bytes());
        body.put(0.0f64.to_le_bytes()).put(0.0f32.to_le_bytes()).put([k as u8]);
    }
    body.put(2u16.to_le_bytes()).put(7i32.to_le_bytes()).put(8i32.to_le_bytes());
    body.put(0u16.to_le_bytes());
    body.put((-1i32).to_le_bytes()).put([3u8]);
    for i in [0u32, 1, 2] {
        body.put(i.to_le_bytes());
    }
    body.put(5i32.to_le_bytes()).put([4u8]);
    for i in [0u32, 2, 3, 1] {
        body.put(i.to_le_bytes());
    }
    body.bytes
}

#[test]
fn hand_built_binary_ply_reads_in_both_byte_orders() {
    for big in [false, true] {
        let mesh = io::ply::parse(&hand_built(big), Path::new("hand.ply")).unwrap();
        assert_eq!(mesh.positions[0], Vec3::new(0.5, -1.25, 3.0));
        assert_eq!(mesh.positions[3], Vec3::new(7.0, 1e-3, 100.0));
        let normals = mesh.normals.as_ref().unwrap();
        assert_eq!(normals[2], Vec3::new(0.0, 0.0, 2.0));
        assert_eq!(mesh.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 3, 1]]);
    }
}

#[test]
fn ascii_ply_with_crlf_lists_and_extra_elements() {
    let src = "ply\r\nformat ascii 1.0\r\ncomment x\r\nelement vertex 4\r\nproperty float x\r\n\
               property float y\r\nproperty float z\r\nproperty float nx\r\nproperty float confidence\r\n\
               element range_grid 3\r\nproperty list uchar int vertex_indices\r\n\
               element face 1\r\nproperty list uchar int vertex_indices\r\nend_header\r\n\
               0 0 0 1 0.5\r\n1 0 0 1 0.5\r\n1 1 0 1 0.5\r\n0 1 0 1 0.5\r\n\
               1 0\r\n0\r\n2 1 2\r\n4 0 1 2 3\r\n";
    let mesh = io::ply::parse(src.as_bytes(), Path::new("crlf.ply")).unwrap();
    assert_eq!(mesh.positions.len(), 4);
    assert!(mesh.normals.is_none(), "nx alone is not a normal");
    assert_eq!(mesh.triangles, vec![[0, 1, 2], [0, 2, 3]]);
}

#[test]
fn extensions_are_case_insensitive() {
    for name in ["a.PLY", "a.Obj", "a.OFF", "a.XyZ", "a.pwn"] {
        assert!(io::Format::from_path(Path::new(name)).is_some(), "{name}");
    }
    assert!(io::Format::from_path(Path::new("a.stl")).is_none());
    assert!(io::Format::from_path(Path::new("ply")).is_none());
}
