//! Checks every reader applies while turning parsed numbers into mesh parts: face indices in
//! range, faces with at least three corners, finite positions and normals, and allocations
//! bounded by the input's size. Messages are predicates meant to follow a subject such as `face 3: `.

use crate::mesh::MAX_COORDINATE;
use glam::Vec3;

/// Converts a raw vertex index from a face to `u32`, checking it against `vertex_count`.
pub(crate) fn vertex_index(value: i64, vertex_count: usize) -> Result<u32, String> {
    if value < 0 {
        return Err(format!("uses negative vertex index {value}"));
    }
    match usize::try_from(value) {
        Ok(i) if i < vertex_count => {
            u32::try_from(i).map_err(|_| format!("uses vertex {i}, beyond the 32-bit index range"))
        }
        _ => Err(format!("uses vertex {value}, but there are only {vertex_count} vertices")),
    }
}

/// Appends the fan triangulation `(p0, pi, pi+1)` of a polygon whose indices are already
/// checked. Polygons with fewer than three corners are an error.
pub(crate) fn push_fan(polygon: &[u32], triangles: &mut Vec<[u32; 3]>) -> Result<(), String> {
    match polygon {
        [first, rest @ ..] if rest.len() >= 2 => {
            triangles.extend(rest.windows(2).map(|pair| [*first, pair[0], pair[1]]));
            Ok(())
        }
        _ => Err(format!("has {} vertices, but a face needs at least 3", polygon.len())),
    }
}

/// Returns `p` if all its coordinates are finite and within [`MAX_COORDINATE`].
pub(crate) fn finite_position(p: Vec3) -> Result<Vec3, String> {
    let p = finite(p, "coordinate")?;
    let largest = p.abs().max_element();
    if largest > MAX_COORDINATE {
        return Err(format!(
            "has a coordinate of {largest:e}: at most {MAX_COORDINATE:e} in magnitude is supported (32-bit \
             geometry); rescale the input"
        ));
    }
    Ok(p)
}

/// Returns `n` if all its components are finite. Zero-length normals pass: they are valid
/// input, and the stages that use normals decide what to do with them.
pub(crate) fn finite_normal(n: Vec3) -> Result<Vec3, String> {
    finite(n, "normal component")
}

fn finite(v: Vec3, what: &str) -> Result<Vec3, String> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(format!("has a NaN or infinite {what} ({}, {}, {})", v.x, v.y, v.z))
    }
}

/// How many items to reserve room for: `count`, but no more than `available_bytes` could hold
/// at `min_item_bytes` each, so a header that lies about its counts cannot make us allocate.
pub(crate) fn capacity(count: usize, available_bytes: usize, min_item_bytes: usize) -> usize {
    count.min(available_bytes / min_item_bytes.max(1))
}

/// Checks that `count` vertices can be addressed by `u32` triangle indices.
pub(crate) fn vertex_count_fits(count: usize) -> Result<(), String> {
    if u32::try_from(count).is_ok() {
        Ok(())
    } else {
        Err(format!("{count} vertices; at most {} are supported", u32::MAX))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fans_polygons_and_rejects_short_faces() {
        let mut tris = Vec::new();
        push_fan(&[0, 1, 2, 3, 4], &mut tris).unwrap();
        assert_eq!(tris, vec![[0, 1, 2], [0, 2, 3], [0, 3, 4]]);
        assert!(push_fan(&[0, 1], &mut tris).unwrap_err().contains("2 vertices"));
        assert!(push_fan(&[], &mut tris).is_err());
    }

    #[test]
    fn checks_index_range() {
        assert_eq!(vertex_index(4, 5), Ok(4));
        assert!(vertex_index(5, 5).unwrap_err().contains("only 5 vertices"));
        assert!(vertex_index(-1, 5).unwrap_err().contains("negative"));
        assert!(vertex_index(i64::MAX, usize::MAX).is_err());
    }

    #[test]
    fn rejects_non_finite_but_not_zero_normals() {
        assert_eq!(finite_normal(Vec3::ZERO), Ok(Vec3::ZERO));
        assert!(finite_normal(Vec3::new(0.0, f32::NAN, 1.0)).unwrap_err().contains("normal component (0, NaN, 1)"));
        assert!(finite_position(Vec3::new(f32::INFINITY, 0.0, 0.0)).unwrap_err().contains("coordinate (inf, 0, 0)"));
    }

    #[test]
    fn caps_capacity_by_available_bytes() {
        assert_eq!(capacity(1 << 31, 200, 12), 16);
        assert_eq!(capacity(3, 200, 12), 3);
        assert_eq!(capacity(3, 200, 0), 3);
    }
}
