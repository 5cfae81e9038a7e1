//! Generated meshes written to a file as they are made, never held: inputs larger than memory
//! for the streaming simplification's tests and benchmarks.

use glam::Vec3;
use std::io::{self, Write};

/// Writes a binary little-endian PLY of a bumpy torus around the z axis (tube radius `minor`
/// around the circle of radius `major`, the tube's radius varied by `bump` of itself in a
/// 5 x 3 pattern around it): `rings` x `segments` vertices and twice as many triangles, genus 1,
/// closed, written ring by ring (memory: one ring). Returns the triangle count.
pub fn write_bumpy_torus_ply(
    out: &mut impl Write,
    rings: u32,
    segments: u32,
    major: f32,
    minor: f32,
    bump: f32,
) -> io::Result<u64> {
    let (m, n) = (u64::from(rings.max(3)), u64::from(segments.max(3)));
    if m * n > u64::from(u32::MAX) {
        return Err(io::Error::other("more vertices than 32-bit indices address"));
    }
    let triangles = 2 * m * n;
    write!(
        out,
        "ply\nformat binary_little_endian 1.0\ncomment vstree: generated bumpy torus\nelement vertex {}\n\
         property float x\nproperty float y\nproperty float z\nelement face {triangles}\n\
         property list uchar int vertex_indices\nend_header\n",
        m * n
    )?;
    let tau = std::f32::consts::TAU;
    let mut row = Vec::with_capacity(n as usize * 13);
    for i in 0..m {
        row.clear();
        let u = tau * i as f32 / m as f32;
        for j in 0..n {
            let v = tau * j as f32 / n as f32;
            let r = minor * (1.0 + bump * (5.0 * u).sin() * (3.0 * v).sin());
            let p =
                Vec3::new(u.cos(), u.sin(), 0.0) * major + Vec3::new(v.cos() * u.cos(), v.cos() * u.sin(), v.sin()) * r;
            for c in p.to_array() {
                row.extend_from_slice(&c.to_le_bytes());
            }
        }
        out.write_all(&row)?;
    }
    let index = |i: u64, j: u64| ((i % m) * n + (j % n)) as u32;
    for i in 0..m {
        row.clear();
        for j in 0..n {
            // d/du x d/dv points outward: (i, j) -> (i+1, j) -> (i+1, j+1) is counter-clockwise.
            let (a, b, c, d) = (index(i, j), index(i + 1, j), index(i + 1, j + 1), index(i, j + 1));
            for tri in [[a, b, c], [a, c, d]] {
                row.push(3);
                for v in tri {
                    row.extend_from_slice(&v.to_le_bytes());
                }
            }
        }
        out.write_all(&row)?;
    }
    Ok(triangles)
}

/// The distance from `p` to the surface [`write_bumpy_torus_ply`] samples (same `major`,
/// `minor` and `bump`), measured along the tube's radius at `p`'s angles: within a few percent
/// of the true distance for the gentle bumps it is used with.
pub fn bumpy_torus_distance(p: Vec3, major: f32, minor: f32, bump: f32) -> f32 {
    let u = p.y.atan2(p.x);
    let outward = Vec3::new(u.cos(), u.sin(), 0.0);
    let d = p - outward * major;
    let v = d.z.atan2(d.dot(outward));
    let r = minor * (1.0 + bump * (5.0 * u).sin() * (3.0 * v).sin());
    (d.length() - r).abs()
}
