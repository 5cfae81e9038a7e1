//! Realistic PLY headers for the body fuzzers, so that the fuzzer spends its time on the body:
//! the input's first byte picks a layout (and, for binary, the byte order), the next two the
//! vertex and face counts, and the rest is the body. fuzz/make_seeds.py writes the same layouts.

/// The vertex and face properties of each layout.
const LAYOUTS: [(&str, &str); 5] = [
    // Positions, triangles as most writers store them.
    ("property float x\nproperty float y\nproperty float z\n", "property list uchar int vertex_indices\n"),
    // With normals.
    (
        "property float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\n",
        "property list uchar int vertex_indices\n",
    ),
    // Double coordinates, an int-counted list.
    ("property double x\nproperty double y\nproperty double z\n", "property list int int vertex_indices\n"),
    // A point cloud: no face element.
    ("property float x\nproperty float y\nproperty float z\n", ""),
    // Colours and a face flag, which the reader skips; unsigned indices.
    (
        "property float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n",
        "property list uchar uint vertex_indices\nproperty uchar flags\n",
    ),
];

/// The whole file for `data`: a header of `format` (`ascii` or `binary`) and `data`'s body.
pub fn file(data: &[u8], format: &str) -> Option<Vec<u8>> {
    let [choice, vertices, faces, body @ ..] = data else {
        return None;
    };
    let (vertex, face) = LAYOUTS[usize::from(*choice) % LAYOUTS.len()];
    let format = match (format, usize::from(*choice) / LAYOUTS.len() % 2) {
        ("ascii", _) => "ascii",
        (_, 0) => "binary_little_endian",
        _ => "binary_big_endian",
    };
    let mut file = format!("ply\nformat {format} 1.0\nelement vertex {vertices}\n{vertex}");
    if !face.is_empty() {
        file += &format!("element face {faces}\n{face}");
    }
    file += "end_header\n";
    let mut file = file.into_bytes();
    file.extend_from_slice(body);
    Some(file)
}
