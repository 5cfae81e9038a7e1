//! Malformed input gives an error that names the file, the place and the problem, and no
//! input bytes at all make a reader panic.

use glam::Vec3;
use std::path::Path;
use std::time::{Duration, Instant};
use vstree::io;
use vstree::{Error, Mesh, Result};

/// `(location, message)` of a parse error; fails the test for anything else.
fn parse_error(result: Result<Mesh>, file: &str) -> (String, String) {
    match result {
        Err(Error::Parse { path, location, message }) => {
            assert_eq!(path, Path::new(file));
            (location, message)
        }
        other => panic!("expected a parse error, got {other:?}"),
    }
}

/// Checks an error's location, and that its message contains `needle`.
fn expect_at((location, message): (String, String), expected: &str, needle: &str) {
    assert_eq!(location, expected, "{message}");
    assert!(message.contains(needle), "{needle:?} not in {message:?}");
}

/// An expected error: its location and message.
fn at(location: &str, message: &str) -> (String, String) {
    (location.to_string(), message.to_string())
}

fn ply(src: &[u8]) -> (String, String) {
    parse_error(io::ply::parse(src, Path::new("bad.ply")), "bad.ply")
}

fn off(src: &str) -> (String, String) {
    parse_error(io::off::parse(src.as_bytes(), Path::new("bad.off")), "bad.off")
}

fn xyz(src: &str) -> (String, String) {
    parse_error(io::xyz::parse(src.as_bytes(), Path::new("bad.xyz")), "bad.xyz")
}

const TRIANGLE_HEADER: &str = "ply\nformat binary_little_endian 1.0\nelement vertex 3\n\
    property float x\nproperty float y\nproperty float z\nelement face 2\n\
    property list uchar int vertex_indices\nend_header\n";

/// A binary triangle file with two faces; `faces` are their indices.
fn binary_triangles(faces: [[i32; 3]; 2], x0: f32) -> Vec<u8> {
    let mut bytes = TRIANGLE_HEADER.as_bytes().to_vec();
    for p in [[x0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
        for c in p {
            bytes.extend_from_slice(&c.to_le_bytes());
        }
    }
    for face in faces {
        bytes.push(3);
        for i in face {
            bytes.extend_from_slice(&i.to_le_bytes());
        }
    }
    bytes
}

fn ascii_ply(body: &str) -> Vec<u8> {
    format!(
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
         property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n{body}"
    )
    .into_bytes()
}

#[test]
fn truncated_binary_ply_names_the_item() {
    let good = binary_triangles([[0, 1, 2], [2, 1, 0]], 0.0);
    io::ply::parse(&good, Path::new("bad.ply")).unwrap();
    expect_at(ply(&good[..good.len() - 2]), "face 1", "file ends after 1 of the 2 `face` elements");
    expect_at(ply(&good[..TRIANGLE_HEADER.len() + 13]), "vertex 1", "file ends after 1 of the 3 `vertex` elements");
}

#[test]
fn bad_magic_and_header_errors_name_the_line() {
    expect_at(ply(b"PLY\nformat ascii 1.0\nend_header\n"), "line 1", "not a PLY file");
    expect_at(
        ply(b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\nend_header\n"),
        "line 4",
        "unknown property type `float128`",
    );
    expect_at(ply(b"ply\nformat binary_middle_endian 1.0\nend_header\n"), "line 2", "unknown format");
    expect_at(ply(b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n0\n"), "line 3", "`y`");
}

#[test]
fn out_of_range_face_index_names_the_face() {
    let (location, message) = ply(&binary_triangles([[0, 1, 2], [0, 1, 99]], 0.0));
    assert_eq!(location, "face 1");
    assert!(message.contains("vertex 99") && message.contains("only 3 vertices"), "{message}");
    expect_at(ply(&binary_triangles([[0, -1, 2], [0, 1, 2]], 0.0)), "face 0", "-1");
    let (location, message) = ply(&ascii_ply("0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n"));
    assert_eq!(location, "line 13");
    assert!(message.contains("face 0") && message.contains("vertex 3"), "{message}");
    let (location, message) = off("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 50\n");
    assert_eq!(location, "line 6");
    assert!(message.contains("face 0") && message.contains("vertex 50"), "{message}");
    let obj = io::obj::parse(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n", Path::new("bad.obj"));
    parse_error(obj, "bad.obj");
}

#[test]
fn two_vertex_face_names_the_face() {
    let (location, message) = ply(&ascii_ply("0 0 0\n1 0 0\n0 1 0\n2 0 1\n"));
    assert_eq!(location, "line 13");
    assert!(message.contains("face 0") && message.contains("2 vertices"), "{message}");
    let (_, message) = off("OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n2 0 1\n");
    assert!(message.contains("face 1") && message.contains("2 vertices"), "{message}");
}

#[test]
fn non_numeric_tokens_name_the_line() {
    let (location, message) = ply(&ascii_ply("0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n"));
    assert_eq!(location, "line 11");
    assert!(message.contains("vertex 1") && message.contains("`zero`"), "{message}");
    expect_at(off("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 q\n3 0 1 2\n"), "line 5", "`q`");
    expect_at(off("OFF\nthree 1 0\n"), "line 2", "`three`");
    expect_at(xyz("0 0 0\n1 1 1\n2 2 two\n"), "line 3", "`two`");
}

#[test]
fn inconsistent_xyz_columns_name_the_line() {
    expect_at(xyz("# points\n0 0 0 0 0 1\n1 1 1 0 0 1\n2 2 2\n"), "line 4", "expected 6 numbers like line 2, found 3");
}

#[test]
fn absurd_counts_in_tiny_files_fail_fast() {
    let start = Instant::now();
    let mut huge = b"ply\nformat binary_little_endian 1.0\nelement vertex 2147483648\n\
        property float x\nproperty float y\nproperty float z\nend_header\n"
        .to_vec();
    huge.extend_from_slice(&[0; 100]);
    expect_at(ply(&huge), "vertex 8", "of the 2147483648 `vertex` elements");
    let ascii = b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
        property float z\nelement face 18446744073709551615\nproperty list uint uint vertex_indices\n\
        end_header\n0 0 0\n0 0 0\n0 0 0\n4294967295 0 1 2\n";
    expect_at(ply(ascii), "line 13", "face 0: expected 4294967296 values, found 4");
    let (_, message) = off("OFF\n4000000000 4000000000 0\n0 0 0\n");
    assert!(message.contains("file ends after 1 of the 4000000000 vertices"), "{message}");
    // Elements without properties occupy no bytes, whatever their count.
    let empty = b"ply\nformat binary_big_endian 1.0\nelement vertex 0\nproperty float x\n\
        property float y\nproperty float z\nelement nothing 1000000000000000000\nend_header\n";
    io::ply::parse(empty, Path::new("bad.ply")).unwrap();
    let too_many = b"ply\nformat ascii 1.0\nelement vertex 5000000000\nproperty float x\n\
        property float y\nproperty float z\nend_header\n";
    assert!(matches!(io::ply::parse(too_many, Path::new("bad.ply")), Err(Error::TooLarge(_))));
    assert!(start.elapsed() < Duration::from_secs(1));
}

#[test]
fn empty_files_are_errors() {
    for name in ["e.ply", "e.obj", "e.off", "e.xyz", "e.pwn"] {
        let format = io::Format::from_path(Path::new(name)).unwrap();
        for bytes in [&b""[..], b"  \n\r\n"] {
            let (location, message) = parse_error(format.parse(bytes, Path::new(name)), name);
            assert_eq!(location, "line 1", "{name}");
            assert!(message.contains("empty") || message.contains("not a PLY"), "{name}: {message}");
        }
    }
}

#[test]
fn nan_coordinates_name_the_vertex() {
    expect_at(ply(&binary_triangles([[0, 1, 2], [2, 1, 0]], f32::NAN)), "vertex 0", "NaN");
    expect_at(ply(&ascii_ply("0 0 0\n1 0 inf\n0 1 0\n3 0 1 2\n")), "line 11", "vertex 1");
    expect_at(off("OFF\n3 1 0\n0 0 0\n1 0 0\nnan 1 0\n3 0 1 2\n"), "line 5", "vertex 2");
    expect_at(xyz("0 0 0\nNaN 0 0\n"), "line 2", "point 1");
    let obj = io::obj::parse(b"v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", Path::new("bad.obj"));
    parse_error(obj, "bad.obj");
}

/// An ASCII PLY of `count` vertices with normals and no faces; the body starts on line 11.
fn ascii_ply_with_normals(count: usize, body: &str) -> Vec<u8> {
    format!(
        "ply\nformat ascii 1.0\nelement vertex {count}\nproperty float x\nproperty float y\n\
         property float z\nproperty float nx\nproperty float ny\nproperty float nz\nend_header\n{body}"
    )
    .into_bytes()
}

/// A binary PLY of three vertices with normals, all `+z` but vertex `bad`'s, which is `normal`.
fn binary_ply_with_normals(bad: usize, normal: [f32; 3]) -> Vec<u8> {
    let mut bytes = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n\
        property float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\n\
        end_header\n"
        .to_vec();
    for i in 0..3 {
        let n = if i == bad { normal } else { [0.0, 0.0, 1.0] };
        for c in [i as f32, 0.0, 0.0].into_iter().chain(n) {
            bytes.extend_from_slice(&c.to_le_bytes());
        }
    }
    bytes
}

fn obj(src: &str) -> (String, String) {
    parse_error(io::obj::parse(src.as_bytes(), Path::new("bad.obj")), "bad.obj")
}

#[test]
fn non_finite_normals_name_the_line_or_element() {
    expect_at(
        ply(&binary_ply_with_normals(2, [0.0, f32::NAN, 1.0])),
        "vertex 2",
        "NaN or infinite normal component (0, NaN, 1)",
    );
    expect_at(
        ply(&binary_ply_with_normals(0, [f32::NEG_INFINITY, 0.0, 0.0])),
        "vertex 0",
        "normal component (-inf, 0, 0)",
    );
    expect_at(
        ply(&ascii_ply_with_normals(3, "0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 nan 0 1\n")),
        "line 13",
        "vertex 2: has a NaN or infinite normal component",
    );
    expect_at(
        xyz("# n\n0 0 0 0 0 1\n1 1 1 0 inf 1\n"),
        "line 3",
        "point 1: has a NaN or infinite normal component (0, inf, 1)",
    );
    expect_at(
        off("NOFF\n3 1 0\n0 0 0 0 0 1\n1 0 0 0 0 NaN\n0 1 0 0 0 1\n3 0 1 2\n"),
        "line 4",
        "vertex 1: has a NaN or infinite normal component",
    );
    // OBJ per-vertex normals (kept) name their `vn` line, though tobj renumbers vertices.
    let src = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvn 0 0 1\nvn nan 0 1\nf 3//3 2//2 1//1\n";
    expect_at(obj(src), "line 6", "normal 2 has a NaN or infinite normal component");
    expect_at(obj("v 0 0 0\nv 1 0 0\nvn 0 0 1\nvn 0 inf 0\n"), "line 4", "normal 1 has a NaN");
}

#[test]
fn dropped_or_zero_normals_are_not_reader_errors() {
    // One `vn` shared by all corners is not per-vertex, so it is dropped, NaN or not.
    let mesh = io::obj::parse(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvn nan 0 1\nf 1//1 2//1 3//1\n", Path::new("a.obj"));
    assert!(mesh.unwrap().normals.is_none());
    let mesh = io::obj::parse(b"v 0 0 0\nv 1 0 0\nvn nan 0 0\n", Path::new("a.obj")).unwrap();
    assert!(mesh.normals.is_none());
    let mesh = io::ply::parse(&binary_ply_with_normals(1, [0.0; 3]), Path::new("a.ply")).unwrap();
    assert_eq!(mesh.normals.unwrap()[1], glam::Vec3::ZERO);
    let mesh = io::xyz::parse(b"0 0 0 0 0 0\n", Path::new("a.xyz")).unwrap();
    assert_eq!(mesh.normals.unwrap()[0], glam::Vec3::ZERO);
}

#[test]
fn ascii_ply_items_end_at_their_line() {
    assert_eq!(
        ply(&ascii_ply("0 0 0\n1 0 0 7\n0 1 0\n3 0 1 2\n")),
        at("line 11", "vertex 1: expected 3 values, found 4")
    );
    assert_eq!(ply(&ascii_ply("0 0 0\n1 0\n0 1 0\n3 0 1 2\n")), at("line 11", "vertex 1: expected 3 values, found 2"));
    assert_eq!(ply(&ascii_ply("0 0 0\n1 0 0\n0 1 0\n3 0 1\n")), at("line 13", "face 0: expected 4 values, found 3"));
    assert_eq!(
        ply(&ascii_ply("0 0 0\n1 0 0\n0 1 0\n3 0 1 2 1\n")),
        at("line 13", "face 0: expected 4 values, found 5")
    );
    let body = "0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n1 1 0 0 0 1 5\n";
    assert_eq!(ply(&ascii_ply_with_normals(4, body)), at("line 14", "vertex 3: expected 6 values, found 7"));
    // A list not read yet counts only its length: the expected count is a lower bound.
    let two_lists = b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
        property float z\nelement face 1\nproperty list uchar int vertex_indices\n\
        property list uchar float texcoord\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1\n";
    assert_eq!(ply(two_lists), at("line 14", "face 0: expected at least 5 values, found 3"));
    // A vertex line missing from the middle is reported where the items stop matching.
    assert_eq!(ply(&ascii_ply("0 0 0\n1 0 0\n3 0 1 2\n")), at("line 12", "vertex 2: expected 3 values, found 4"));
}

#[test]
fn ascii_ply_tolerates_blank_lines_trailing_spaces_and_crlf() {
    let body = "\r\n0 0 0 \r\n\n  1 0 0\t\r\n0 1 0\r\n   \n3 0 1 2  \r\n\n";
    let mesh = io::ply::parse(&ascii_ply(body), Path::new("ok.ply")).unwrap();
    assert_eq!((mesh.positions.len(), mesh.triangles.len()), (3, 1));
    let mesh = io::ply::parse(&ascii_ply("0 0 0\n1 0 0\n0 1 0\n3 0 1 2"), Path::new("ok.ply")).unwrap();
    assert_eq!(mesh.triangles, vec![[0, 1, 2]]);
    // Skipped blank lines still count for the line numbers.
    assert_eq!(
        ply(&ascii_ply("0 0 0\n\n\r\n1 0 0 5\n0 1 0\n3 0 1 2\n")),
        at("line 13", "vertex 1: expected 3 values, found 4")
    );
    assert_eq!(
        ply(&ascii_ply("0 0 0\n1 0 0\n0 1 0\n\n\n")),
        at("line 12", "file ends after 0 of the 1 `face` elements")
    );
}

#[test]
fn obj_errors_name_the_line() {
    let tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    expect_at(
        obj(&format!("{tri}f 1 2 3\nf 1 2 9\n")),
        "line 5",
        "vertex index 9 is out of range: the file has 3 `v` lines",
    );
    expect_at(obj(&format!("{tri}f 0 1 2\n")), "line 4", "vertex index 0 is invalid");
    let (location, message) = obj("# relative\nv 0 0 0\nv 1 0 0\nf -1 -2 -3\nv 0 1 0\n");
    assert_eq!(location, "line 4");
    assert!(message.contains("relative vertex index -3") && message.contains("only 2 `v` lines"), "{message}");
    expect_at(obj("v 0 0 0\nv 1 0 0\nv 0 1 zero\nf 1 2 3\n"), "line 3", "`zero`");
    expect_at(obj(&format!("{tri}vn 0 0 1\nf 1//1 2//1 3//2\n")), "line 5", "normal index 2 is out of range");
    expect_at(obj(&format!("{tri}f 1 2/x 3\n")), "line 4", "`2/x`");
    // Makes tobj index out of bounds (a panic it does not guard against): still located.
    expect_at(
        obj(&format!("{tri}vn 0 0 1\nf 1//1 2//1 3//6148914691236517206\n")),
        "line 5",
        "normal index 6148914691236517206 is out of range",
    );
    // Points and lines are ignored, whatever their indices; a two-corner face is refused, as in
    // PLY and OFF.
    io::obj::parse(format!("{tri}p 99\nl 5 6\nf 1 2 3\n").as_bytes(), Path::new("ok.obj")).unwrap();
    expect_at(obj(&format!("{tri}f 1 2 3\nf 1 2\n")), "line 5", "a face with 2 corners: a face needs at least 3");
    expect_at(obj(&format!("{tri}f 1 # two\n")), "line 4", "a face with 1 corner: ");
    // A reference to a `v` line after the end of the face's object, which tobj refuses.
    expect_at(
        obj("o a\nv 0 0 0\nv 1 0 0\nf 1 2 3\no b\nv 0 1 0\n"),
        "line 4",
        "vertex index 3 is out of range: its object ends at line 5 after 2 `v` lines, and a face may only use those",
    );
    expect_at(
        obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1//1 2//1 3//2\nvn 0 0 1\ng b\nvn 0 0 1\n"),
        "line 4",
        "normal index 2 is out of range: its object ends at line 6 after 1 `vn` lines",
    );
}

#[test]
fn obj_colours_on_some_vertices_are_ignored() {
    // tobj looks colours up by vertex and failed here with "face vertex color index out of bounds".
    let src = "v 0 0 0 1 0 0\nv 1 0 0\nv 0 1 0 0 0 1\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
    let mesh = io::obj::parse(src.as_bytes(), Path::new("c.obj")).unwrap();
    assert_eq!(mesh.positions, [Vec3::ZERO, Vec3::Y, Vec3::X, Vec3::Z]);
    assert_eq!(mesh.triangles, [[0, 1, 2], [0, 2, 3], [0, 3, 1], [2, 1, 3]]);
    // Malformed colours are still errors at their line.
    expect_at(obj("v 0 0 0 1 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"), "line 1", "expected x y z, x y z w or x y z r g b");
}

#[test]
fn obj_non_finite_vertices_name_their_line() {
    assert_eq!(
        obj("v 0 0 0\nv 1 0 0\nv 0 nan 0\nv 0 1 0\nf 1 2 4\nf 4 3 1\n"),
        at("line 3", "vertex 2 has a NaN or infinite coordinate (0, NaN, 0)")
    );
    // A vertex no face uses is dropped by tobj, so it is no error.
    let mesh = io::obj::parse(b"v inf 0 0\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 2 3 4\n", Path::new("ok.obj"));
    assert_eq!(mesh.unwrap().positions.len(), 3);
}

/// The errors of files read from disk name the file and the line.
#[test]
fn errors_from_files_name_path_and_line() {
    let dir = std::env::temp_dir().join(format!("vstree-io-errors-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let cases: [(&str, &[u8], &str); 4] = [
        ("normal.ply", &ascii_ply_with_normals(2, "0 0 0 0 0 1\n1 0 0 0 inf 1\n"), "line 12: vertex 1: has a NaN"),
        ("short.ply", &ascii_ply("0 0 0\n1 0\n0 1 0\n3 0 1 2\n"), "line 11: vertex 1: expected 3 values, found 2"),
        ("index.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n", "line 4: relative vertex index -4"),
        ("normal.pwn", b"0 0 0 0 0 1\n1 1 1 nan 0 0\n", "line 2: point 1: has a NaN or infinite normal"),
    ];
    for (name, bytes, expected) in cases {
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        let err = io::read(&path).unwrap_err();
        assert!(matches!(&err, Error::Parse { path: p, .. } if *p == path), "{err:?}");
        let shown = err.to_string();
        assert!(shown.starts_with(&format!("{}: {expected}", path.display())), "{shown}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn unknown_extension_and_missing_file() {
    let err = io::read(Path::new("model.stl")).unwrap_err();
    assert!(matches!(err, Error::UnsupportedFormat { .. }));
    let missing = std::env::temp_dir().join("vstree-io-definitely-missing.ply");
    assert!(matches!(io::read(&missing), Err(Error::Io { .. })));
}

/// A small deterministic generator for corruption positions.
fn xorshift(state: &mut u64) -> u64 {
    *state ^= *state << 13;
    *state ^= *state >> 7;
    *state ^= *state << 17;
    *state
}

#[test]
fn no_input_bytes_make_a_reader_panic() {
    let samples: Vec<(&str, Vec<u8>)> = vec![
        ("t.ply", binary_triangles([[0, 1, 2], [2, 1, 0]], 0.5)),
        ("t.ply", ascii_ply("0 0 0\n1 0 0\n0 1 0\n4 0 1 2 0\n")),
        ("t.off", b"NOFF 3 1 0\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2 9 9 9\n".to_vec()),
        ("t.xyz", b"0 0 0 0 0 1\n1 1 1 0 0 1\n".to_vec()),
        ("t.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\n".to_vec()),
    ];
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    for (name, good) in &samples {
        let format = io::Format::from_path(Path::new(name)).unwrap();
        let path = Path::new(name);
        for cut in 0..=good.len() {
            let _ = format.parse(&good[..cut], path);
        }
        for _ in 0..2000 {
            let mut bad = good.clone();
            for _ in 0..1 + xorshift(&mut state) % 4 {
                let at = (xorshift(&mut state) % bad.len() as u64) as usize;
                bad[at] = match xorshift(&mut state) % 4 {
                    0 => b'-',
                    1 => b'9',
                    2 => 0xff,
                    _ => xorshift(&mut state) as u8,
                };
            }
            let _ = format.parse(&bad, path);
        }
    }
}
