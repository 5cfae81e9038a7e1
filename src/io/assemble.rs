//! Checks every reader applies while turning parsed numbers into mesh parts: face indices in
//! range, faces with at least three corners, finite positions and normals, and allocations
//! bounded by the input's size. Messages are predicates meant to follow a subject such as `face 3: `.

use crate::mesh::{Mesh, MAX_COORDINATE};
use glam::{DVec3, Vec3};

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
pub(crate) fn finite_position(p: DVec3) -> Result<DVec3, String> {
    if !p.is_finite() {
        return Err(format!("has a NaN or infinite coordinate ({}, {}, {})", p.x, p.y, p.z));
    }
    let largest = p.abs().max_element();
    if largest > f64::from(MAX_COORDINATE) {
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

/// Beyond this many times its own extent from the origin, a model is stored relative to an
/// origin of its own (a ratio). f32 resolves 2^-24 of a coordinate's magnitude, so a model
/// this close keeps details of 16 × 2^-24 (1e-6) of its extent, while one 1e6 extents away
/// (a georeferenced scan) would keep none below 6% of it.
const FAR_FROM_ORIGIN: f64 = 16.0;

/// The mesh of positions read in f64. Its `f32` positions are relative to an origin that keeps
/// their detail: zero for a model near the origin (which is then stored exactly as read in
/// f32), else the centre of its box rounded to f32, so that f32 input far away is stored
/// exactly too (the difference of two nearby f32 values is an f32 value).
pub(crate) fn mesh(read: Vec<DVec3>, normals: Option<Vec<Vec3>>, triangles: Vec<[u32; 3]>) -> Mesh {
    let origin = origin_for(&read);
    let positions = read.iter().map(|&p| (p - origin).as_vec3()).collect();
    Mesh { positions, normals, triangles, origin }
}

/// The origin [`mesh`] stores `points` relative to.
fn origin_for(points: &[DVec3]) -> DVec3 {
    let Some(&first) = points.first() else {
        return DVec3::ZERO;
    };
    let (min, max) = points.iter().fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    origin_for_box(min, max)
}

/// The origin [`mesh`] stores points in the box `min..=max` relative to.
pub(crate) fn origin_for_box(min: DVec3, max: DVec3) -> DVec3 {
    let extent = (max - min).max_element();
    let largest = min.abs().max(max.abs()).max_element();
    if largest <= FAR_FROM_ORIGIN * extent {
        DVec3::ZERO
    } else {
        (0.5 * (min + max)).as_vec3().as_dvec3()
    }
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
        assert!(finite_position(DVec3::new(f64::INFINITY, 0.0, 0.0)).unwrap_err().contains("coordinate (inf, 0, 0)"));
    }

    #[test]
    fn caps_capacity_by_available_bytes() {
        assert_eq!(capacity(1 << 31, 200, 12), 16);
        assert_eq!(capacity(3, 200, 12), 3);
        assert_eq!(capacity(3, 200, 0), 3);
    }
}

#[cfg(test)]
mod origin_tests {
    use super::*;

    #[test]
    fn a_model_far_from_the_origin_is_stored_relative_to_its_centre() {
        // Near the origin: stored as read, origin zero.
        let near = mesh(vec![DVec3::new(1.0, 2.0, 3.0), DVec3::new(1.5, 2.5, 3.5)], None, Vec::new());
        assert_eq!(near.origin, DVec3::ZERO);
        assert_eq!(near.positions[0], Vec3::new(1.0, 2.0, 3.0));
        // 1e6 extents away: a millimetre detail of a metre-sized model survives, and f32 input
        // (multiples of 1/16 at 1e6) is stored exactly.
        let far = [DVec3::new(1e6, 1e6, 1e6), DVec3::new(1e6 + 1.0, 1e6 + 0.001, 1e6 + 0.0625)];
        let m = mesh(far.to_vec(), None, Vec::new());
        assert_eq!(m.origin, DVec3::new(1e6 + 0.5, 1e6, 1e6));
        for (stored, read) in m.positions.iter().zip(far) {
            assert!((stored.as_dvec3() + m.origin - read).abs().max_element() < 1e-7, "{stored} {read}");
        }
        assert_eq!(m.positions[1].z.to_bits(), 0.0625f32.to_bits());
    }
}
