//! Malformed input gives an error that names the file, the place and the problem, and no
//! input bytes at all make a reader panic.

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
    let (location, message) = ply(&good[..good.len() - 2]);
    assert_eq!(location, "face 1");
    assert!(message.contains("file ends in face 1 of 2"), "{message}");
    let (location, message) = ply(&good[..TRIANGLE_HEADER.len() + 13]);
    assert_eq!(location, "vertex 1");
    assert!(message.contains("file ends in vertex 1 of 3"), "{message}");
}

#[test]
fn bad_magic_and_header_errors_name_the_line() {
    let (location, message) = ply(b"PLY\nformat ascii 1.0\nend_header\n");
    assert_eq!(location, "line 1");
    assert!(message.contains("not a PLY file"), "{message}");
    let (location, message) = ply(b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\nend_header\n");
    assert_eq!(location, "line 4");
    assert!(message.contains("unknown property type `float128`"), "{message}");
    let (location, message) = ply(b"ply\nformat binary_middle_endian 1.0\nend_header\n");
    assert_eq!(location, "line 2");
    assert!(message.contains("unknown format"), "{message}");
    let (location, message) = ply(b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n0\n");
    assert_eq!(location, "line 3");
    assert!(message.contains("`y`"), "{message}");
}

#[test]
fn out_of_range_face_index_names_the_face() {
    let (location, message) = ply(&binary_triangles([[0, 1, 2], [0, 1, 99]], 0.0));
    assert_eq!(location, "face 1");
    assert!(message.contains("vertex 99") && message.contains("only 3 vertices"), "{message}");
    let (location, message) = ply(&binary_triangles([[0, -1, 2], [0, 1, 2]], 0.0));
    assert_eq!(location, "face 0");
    assert!(message.contains("-1"), "{message}");
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
    let (location, message) = off("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 q\n3 0 1 2\n");
    assert_eq!(location, "line 5");
    assert!(message.contains("`q`"), "{message}");
    let (location, message) = off("OFF\nthree 1 0\n");
    assert_eq!(location, "line 2");
    assert!(message.contains("`three`"), "{message}");
    let (location, message) = xyz("0 0 0\n1 1 1\n2 2 two\n");
    assert_eq!(location, "line 3");
    assert!(message.contains("`two`"), "{message}");
}

#[test]
fn inconsistent_xyz_columns_name_the_line() {
    let (location, message) = xyz("# points\n0 0 0 0 0 1\n1 1 1 0 0 1\n2 2 2\n");
    assert_eq!(location, "line 4");
    assert!(message.contains("expected 6 numbers like line 2, found 3"), "{message}");
}

#[test]
fn absurd_counts_in_tiny_files_fail_fast() {
    let start = Instant::now();
    let mut huge = b"ply\nformat binary_little_endian 1.0\nelement vertex 2147483648\n\
        property float x\nproperty float y\nproperty float z\nend_header\n"
        .to_vec();
    huge.extend_from_slice(&[0; 100]);
    let (location, message) = ply(&huge);
    assert_eq!(location, "vertex 8");
    assert!(message.contains("of 2147483648"), "{message}");
    let ascii = b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
        property float z\nelement face 18446744073709551615\nproperty list uint uint vertex_indices\n\
        end_header\n0 0 0\n0 0 0\n0 0 0\n4294967295 0 1 2\n";
    let (location, message) = ply(ascii);
    assert_eq!(location, "line 13");
    assert!(message.contains("file ends in face 0"), "{message}");
    let (_, message) = off("OFF\n4000000000 4000000000 0\n0 0 0\n");
    assert!(message.contains("file ends in vertex 1 of 4000000000"), "{message}");
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
    let (location, message) = ply(&binary_triangles([[0, 1, 2], [2, 1, 0]], f32::NAN));
    assert_eq!(location, "vertex 0");
    assert!(message.contains("NaN"), "{message}");
    let (location, message) = ply(&ascii_ply("0 0 0\n1 0 inf\n0 1 0\n3 0 1 2\n"));
    assert_eq!(location, "line 11");
    assert!(message.contains("vertex 1"), "{message}");
    let (location, message) = off("OFF\n3 1 0\n0 0 0\n1 0 0\nnan 1 0\n3 0 1 2\n");
    assert_eq!(location, "line 5");
    assert!(message.contains("vertex 2"), "{message}");
    let (location, message) = xyz("0 0 0\nNaN 0 0\n");
    assert_eq!(location, "line 2");
    assert!(message.contains("point 1"), "{message}");
    let obj = io::obj::parse(b"v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", Path::new("bad.obj"));
    parse_error(obj, "bad.obj");
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
