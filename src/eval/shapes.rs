//! Generated shapes whose answers are known (genus, radius, volume), surface sampling and noise.
//!
//! Tests use them to assert on figures, and the command line uses them as default input. Every
//! mesh here is closed, 2-manifold and wound counter-clockwise seen from outside, with unit
//! per-vertex normals; every random process is seeded and gives the same result for any number
//! of threads.

use crate::mesh::Mesh;
use crate::polygonise::{polygonise_grid, Grid};
use crate::rng::{stream_seed, Rng};
use glam::Vec3;
use rayon::prelude::*;
use std::collections::HashMap;

/// The most subdivisions [`icosphere`] and [`bumpy_sphere`] perform (20 * 4^10 = 21M triangles).
pub const MAX_SUBDIVISIONS: u32 = 10;

/// The largest grid resolution [`implicit_mesh`] uses; it needs about 9 bytes per grid point,
/// so 513^3 points take 1.2 GB.
pub const MAX_RESOLUTION: u32 = 512;

/// The unit square [0, 1]² in the plane z = 0 as an `n` x `n` grid of quads, two triangles each
/// (an open, flat mesh with `(n + 1)²` vertices).
pub fn square_grid(n: u32) -> Mesh {
    let positions =
        (0..=n).flat_map(|j| (0..=n).map(move |i| Vec3::new(i as f32 / n as f32, j as f32 / n as f32, 0.0))).collect();
    let v = |i: u32, j: u32| j * (n + 1) + i;
    let triangles = (0..n)
        .flat_map(|j| {
            (0..n).flat_map(move |i| [[v(i, j), v(i + 1, j), v(i + 1, j + 1)], [v(i, j), v(i + 1, j + 1), v(i, j + 1)]])
        })
        .collect();
    Mesh::new(positions, None, triangles)
}

/// A sphere of `|radius|` centred at the origin: a regular icosahedron whose triangles are split
/// 1-to-4 `subdivisions` times (clamped to [`MAX_SUBDIVISIONS`]), with every vertex projected
/// onto the sphere. It has 10 * 4^s + 2 vertices and 20 * 4^s triangles, genus 0, and its normals
/// are the exact sphere normals.
pub fn icosphere(radius: f32, subdivisions: u32) -> Mesh {
    let t = (1.0 + 5.0f32.sqrt()) / 2.0;
    let mut directions: Vec<Vec3> = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| Vec3::new(x, y, z).normalize())
    .collect();
    let mut triangles: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..subdivisions.min(MAX_SUBDIVISIONS) {
        // Each edge's midpoint is created once, keyed by its sorted endpoints, so neighbouring
        // triangles share it and the mesh stays watertight.
        let mut midpoints: HashMap<(u32, u32), u32> = HashMap::with_capacity(triangles.len() * 3);
        let mut midpoint = |a: u32, b: u32, directions: &mut Vec<Vec3>| -> u32 {
            *midpoints.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let m = (directions[a as usize] + directions[b as usize]).normalize();
                directions.push(m);
                directions.len() as u32 - 1
            })
        };
        let mut finer = Vec::with_capacity(triangles.len() * 4);
        for &[a, b, c] in &triangles {
            let ab = midpoint(a, b, &mut directions);
            let bc = midpoint(b, c, &mut directions);
            let ca = midpoint(c, a, &mut directions);
            finer.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        triangles = finer;
    }
    let radius = radius.abs();
    Mesh::new(directions.iter().map(|&d| d * radius).collect(), Some(directions), triangles)
}

/// A torus around the z axis, centred at the origin: the tube of radius `minor` around the
/// circle of radius `major` in the xy plane. `major_segments` (around z) and `minor_segments`
/// (around the tube) are clamped to 3..=32768. Genus 1, exact torus normals.
///
/// With `minor >= major` the tube self-intersects; the mesh is still combinatorially a torus.
pub fn torus(major: f32, minor: f32, major_segments: u32, minor_segments: u32) -> Mesh {
    // The clamp keeps m * n (the vertex count) within u32.
    let (m, n) = (major_segments.clamp(3, 1 << 15), minor_segments.clamp(3, 1 << 15));
    let mut positions = Vec::with_capacity((m * n) as usize);
    let mut normals = Vec::with_capacity((m * n) as usize);
    for i in 0..m {
        let u = std::f32::consts::TAU * i as f32 / m as f32;
        for j in 0..n {
            let v = std::f32::consts::TAU * j as f32 / n as f32;
            let normal = Vec3::new(v.cos() * u.cos(), v.cos() * u.sin(), v.sin());
            let ring = Vec3::new(u.cos(), u.sin(), 0.0) * major;
            positions.push(ring + normal * minor);
            normals.push(normal);
        }
    }
    let index = |i: u32, j: u32| (i % m) * n + (j % n);
    let mut triangles = Vec::with_capacity((2 * m * n) as usize);
    for i in 0..m {
        for j in 0..n {
            // d/du x d/dv points outward, so (i, j) -> (i+1, j) -> (i+1, j+1) is counter-clockwise.
            let (a, b, c, d) = (index(i, j), index(i + 1, j), index(i + 1, j + 1), index(i, j + 1));
            triangles.extend([[a, b, c], [a, c, d]]);
        }
    }
    Mesh::new(positions, Some(normals), triangles)
}

/// The radius of [`bumpy_sphere`] in the unit direction `direction`:
/// `radius * (1 + amplitude * sin(frequency x) sin(frequency y) sin(frequency z))`, with
/// `amplitude` clamped to [0, 0.9] so the surface stays star-shaped around the origin.
pub fn bumpy_radius(direction: Vec3, radius: f32, amplitude: f32, frequency: f32) -> f32 {
    let d = direction * frequency;
    let amplitude = amplitude.clamp(0.0, 0.9);
    radius * (1.0 + amplitude * d.x.sin() * d.y.sin() * d.z.sin())
}

/// The triangles of `mesh` with every vertex at z >= 0, on all its vertices: the upper half
/// of a torus around the z axis is an open band with two border loops.
pub fn upper_half(mesh: &Mesh) -> Mesh {
    let upper = mesh.triangles.iter().copied().filter(|t| t.iter().all(|&v| mesh.positions[v as usize].z >= 0.0));
    Mesh::new(mesh.positions.clone(), None, upper.collect())
}

/// A sphere with sinusoidal bumps (see [`bumpy_radius`] for the exact surface): an
/// [`icosphere`] whose vertices are moved radially onto the bumpy surface. Its curvature varies
/// smoothly over the surface, which is what adaptivity tests need. Genus 0; normals are
/// area-weighted face normals.
pub fn bumpy_sphere(radius: f32, amplitude: f32, frequency: f32, subdivisions: u32) -> Mesh {
    let mut mesh = icosphere(1.0, subdivisions);
    let radius = radius.abs();
    for p in &mut mesh.positions {
        *p *= bumpy_radius(*p, radius, amplitude, frequency);
    }
    mesh.normals = Some(mesh.area_weighted_normals());
    mesh
}

/// Signed distance to a torus around the z axis through `center` (exact).
fn torus_distance(p: Vec3, center: Vec3, major: f32, minor: f32) -> f32 {
    let q = p - center;
    let ring = (q.x * q.x + q.y * q.y).sqrt() - major;
    (ring * ring + q.z * q.z).sqrt() - minor
}

/// The polynomial smooth minimum: equal to `min(a, b)` when they differ by more than `k`,
/// blended (and slightly lower) otherwise, which rounds the crease where two shapes are united.
fn smooth_min(a: f32, b: f32, k: f32) -> f32 {
    let h = (k - (a - b).abs()).max(0.0) / k;
    a.min(b) - h * h * k * 0.25
}

/// Major and minor radius of the tori in [`double_torus`] and [`genus_n_pretzel`].
const PRETZEL_MAJOR: f32 = 1.0;
const PRETZEL_MINOR: f32 = 0.35;
/// Grid cells per unit length for the tori: about 17 cells across a tube.
const PRETZEL_CELLS_PER_UNIT: f32 = 24.0;
/// The most holes [`genus_n_pretzel`] makes; beyond it the grid would exceed [`MAX_RESOLUTION`].
pub const MAX_PRETZEL_HOLES: u32 = 10;

/// A genus-2 surface: two tori in the xy plane whose centre circles touch, united with a smooth
/// minimum (see [`genus_n_pretzel`], of which this is the case n = 2).
pub fn double_torus() -> Mesh {
    genus_n_pretzel(2)
}

/// A flat closed surface of genus `n` (clamped to [`MAX_PRETZEL_HOLES`]): `n` tori of major radius
/// 1 and minor radius 0.35 in the xy plane, centred along the x axis two units apart (so
/// neighbouring centre circles touch), united with a smooth minimum and polygonised by
/// [`implicit_mesh`] at 24 cells per unit. For n = 0 it is an oblate ellipsoid (genus 0) of the
/// same footprint as one torus.
pub fn genus_n_pretzel(n: u32) -> Mesh {
    let n = n.min(MAX_PRETZEL_HOLES);
    let (big, small) = (PRETZEL_MAJOR, PRETZEL_MINOR);
    let half_width = n.max(1) as f32 * big + small + 0.15;
    let half_depth = big + small + 0.15;
    let half_height = small + 0.15;
    let max = Vec3::new(half_width, half_depth, half_height);
    let resolution = (2.0 * half_width * PRETZEL_CELLS_PER_UNIT).ceil() as u32;
    let centers: Vec<Vec3> = (0..n).map(|i| Vec3::X * big * (2.0 * i as f32 - (n as f32 - 1.0))).collect();
    let f = |p: Vec3| {
        if centers.is_empty() {
            // An ellipsoid with semi-axes (R + r, R + r, r); not a distance, but a fine implicit.
            let s = Vec3::new(big + small, big + small, small);
            return ((p / s).length() - 1.0) * small;
        }
        centers
            .iter()
            .map(|&c| torus_distance(p, c, big, small))
            .reduce(|a, b| smooth_min(a, b, 0.2))
            .unwrap_or(f32::MAX)
    };
    implicit_mesh(f, -max, max, resolution)
}

/// Polygonises the zero set of `f` (negative inside, positive outside) in the box
/// `[min, max]` by marching tetrahedra.
///
/// The grid's cells are cubes of side `(longest box side) / resolution` (resolution clamped to
/// 1..=[`MAX_RESOLUTION`]) starting at `min`, extended to a whole number of cells; each cube is
/// split into 6 tetrahedra along its main diagonal the same way everywhere. One vertex sits on
/// each grid edge whose ends differ in sign (f == 0 counts as outside), at the linear
/// interpolation of the two values, and is shared by all tetrahedra around that edge, so the
/// result is a watertight, 2-manifold, outward (counter-clockwise) mesh as long as the surface
/// does not leave the box (where it leaves, it has a boundary). Normals are the normalised
/// central-difference gradient of `f`. NaN values count as outside.
///
/// Evaluation and triangulation run in parallel over z-slabs; the output is identical for any
/// number of threads. A box with a non-finite corner or zero extent gives an empty mesh.
pub fn implicit_mesh(f: impl Fn(Vec3) -> f32 + Sync, min: Vec3, max: Vec3, resolution: u32) -> Mesh {
    let (lo, hi) = (min.min(max), min.max(max));
    let extent = hi - lo;
    let longest = extent.max_element();
    if !lo.is_finite() || !hi.is_finite() || longest <= 0.0 {
        return Mesh::default();
    }
    let resolution = resolution.clamp(1, MAX_RESOLUTION);
    let cell = longest / resolution as f32;
    let cells_along = |e: f32| ((e / cell).ceil() as u32).clamp(1, resolution);
    let dims = [cells_along(extent.x) + 1, cells_along(extent.y) + 1, cells_along(extent.z) + 1];
    let grid = Grid { origin: lo, cell, dims };
    let mut mesh = polygonise_grid(&f, &grid);

    // Normals from the gradient; where it vanishes, from the faces.
    let step = cell * 0.1;
    let mut normals: Vec<Vec3> = mesh
        .positions
        .par_iter()
        .map(|&p| {
            let g = Vec3::new(
                f(p + Vec3::X * step) - f(p - Vec3::X * step),
                f(p + Vec3::Y * step) - f(p - Vec3::Y * step),
                f(p + Vec3::Z * step) - f(p - Vec3::Z * step),
            );
            g.normalize_or_zero()
        })
        .collect();
    if normals.contains(&Vec3::ZERO) {
        let fallback = mesh.area_weighted_normals();
        for (n, alt) in normals.iter_mut().zip(fallback) {
            if *n == Vec3::ZERO {
                *n = alt;
            }
        }
    }
    mesh.normals = Some(normals);
    mesh
}

/// Points per independently seeded chunk in [`sample_surface`] and [`add_noise`]. Fixed, so the
/// random streams do not depend on the thread count.
const CHUNK: usize = 1 << 14;

/// Walker's alias table (built by Vose's method) over the triangles with positive area: a draw
/// costs one random slot and one comparison, whatever the number of triangles.
struct AliasTable {
    slots: Vec<AliasSlot>,
}

/// One slot: keep `own` with probability `keep`, else take `alias`.
#[derive(Clone, Copy)]
struct AliasSlot {
    keep: f64,
    own: u32,
    alias: u32,
}

impl AliasTable {
    /// The table for choosing `items[i]` with probability `weights[i] / sum`. All weights must
    /// be positive and finite, and there must be fewer than 2^32 of them.
    fn new(items: &[u32], weights: &[f64]) -> AliasTable {
        let n = items.len();
        let total: f64 = weights.iter().sum();
        // Scaled so the mean is 1; slots below 1 are topped up from slots above 1.
        let mut scaled: Vec<f64> = weights.iter().map(|w| w * n as f64 / total).collect();
        let mut slots: Vec<AliasSlot> = items.iter().map(|&own| AliasSlot { keep: 1.0, own, alias: own }).collect();
        let (mut small, mut large): (Vec<usize>, Vec<usize>) = (0..n).partition(|&i| scaled[i] < 1.0);
        while let (Some(s), Some(&l)) = (small.pop(), large.last()) {
            slots[s].keep = scaled[s];
            slots[s].alias = items[l];
            scaled[l] -= 1.0 - scaled[s];
            if scaled[l] < 1.0 {
                large.pop();
                small.push(l);
            }
        }
        // Whatever is left (only through rounding) keeps itself: keep = 1 already. Every item
        // has positive weight, so no zero-area triangle can be drawn this way.
        AliasTable { slots }
    }

    /// An item drawn from 64 random bits: the high half picks the slot (multiply-shift), the low
    /// half is the coin.
    fn draw(&self, bits: u64) -> u32 {
        let slot = &self.slots[(((bits >> 32) * self.slots.len() as u64) >> 32) as usize];
        let coin = (bits & 0xFFFF_FFFF) as f64 * (1.0 / 4_294_967_296.0);
        if coin < slot.keep {
            slot.own
        } else {
            slot.alias
        }
    }
}

/// `count` points distributed uniformly by area on the triangles of `mesh`, as a point cloud
/// (no triangles) with normals.
///
/// Each point picks a triangle with probability proportional to its area (an alias table, so
/// the cost per point does not grow with the mesh), then a uniform point in it (square-root
/// barycentric mapping). Its normal is the barycentric interpolation of the vertex normals when
/// the mesh has normals (one per vertex), which for a tessellated smooth surface is closer to
/// the true normal; otherwise, or where the interpolation vanishes, the triangle's unit normal.
///
/// Deterministic for a given `seed` whatever the thread count: the points are generated in
/// fixed-size chunks, each with its own random stream derived from (seed, chunk index).
/// Triangles with out-of-range indices or zero area are never chosen; a mesh without area (or
/// `count == 0`) gives an empty cloud.
pub fn sample_surface(mesh: &Mesh, count: usize, seed: u64) -> Mesh {
    let p = &mesh.positions;
    let (items, weights): (Vec<u32>, Vec<f64>) = mesh
        .triangles
        .iter()
        .enumerate()
        .filter(|(_, tri)| tri.iter().all(|&v| (v as usize) < p.len()))
        .map(|(t, tri)| {
            let [a, b, c] = tri.map(|v| p[v as usize].as_dvec3());
            (t as u32, (b - a).cross(c - a).length())
        })
        .filter(|&(_, double_area)| double_area > 0.0 && double_area.is_finite())
        .unzip();
    if count == 0 || items.is_empty() {
        return Mesh::from_points(Vec::new(), Some(Vec::new()));
    }
    let table = AliasTable::new(&items, &weights);
    let vertex_normals = mesh.normals.as_deref().filter(|n| n.len() == p.len());

    let mut positions = vec![Vec3::ZERO; count];
    let mut normals = vec![Vec3::ZERO; count];
    positions.par_chunks_mut(CHUNK).zip(normals.par_chunks_mut(CHUNK)).enumerate().for_each(
        |(chunk, (positions, normals))| {
            let mut rng = Rng::new(stream_seed(seed, chunk as u64));
            for (position, normal) in positions.iter_mut().zip(normals) {
                let tri = mesh.triangles[table.draw(rng.next_u64()) as usize];
                let [a, b, c] = tri.map(|v| p[v as usize]);
                let r1 = rng.f32().sqrt();
                let r2 = rng.f32();
                let w = [1.0 - r1, r1 * (1.0 - r2), r1 * r2];
                *position = a * w[0] + b * w[1] + c * w[2];
                let face = (b - a).cross(c - a).normalize_or(Vec3::Z);
                *normal = match vertex_normals {
                    Some(n) => (n[tri[0] as usize] * w[0] + n[tri[1] as usize] * w[1] + n[tri[2] as usize] * w[2])
                        .normalize_or(face),
                    None => face,
                };
            }
        },
    );
    Mesh::from_points(positions, Some(normals))
}

/// Adds Gaussian noise to a point cloud (or a mesh's vertices), in place.
///
/// Every position moves by an isotropic Gaussian offset whose per-axis standard deviation is
/// `position_sigma` (absolute units). Every normal, when there are normals, is tilted by adding a
/// Gaussian tangent vector with per-axis standard deviation `normal_sigma_radians` and then
/// re-normalised, so for small sigma the tilt angle has a Rayleigh distribution with scale
/// sigma (mean sigma * sqrt(pi/2)); zero normals stay zero. A sigma that is not positive and
/// finite leaves that attribute unchanged. Deterministic for a given `seed` whatever the
/// thread count; positions and normals use separate random streams.
pub fn add_noise(cloud: &mut Mesh, position_sigma: f32, normal_sigma_radians: f32, seed: u64) {
    let usable = |s: f32| s.is_finite() && s > 0.0;
    if usable(position_sigma) {
        cloud.positions.par_chunks_mut(CHUNK).enumerate().for_each(|(chunk, positions)| {
            let mut rng = Rng::new(stream_seed(seed, 2 * chunk as u64));
            for p in positions {
                *p += Vec3::new(rng.normal(), rng.normal(), rng.normal()) * position_sigma;
            }
        });
    }
    if let (Some(normals), true) = (cloud.normals.as_mut(), usable(normal_sigma_radians)) {
        normals.par_chunks_mut(CHUNK).enumerate().for_each(|(chunk, normals)| {
            let mut rng = Rng::new(stream_seed(seed, 2 * chunk as u64 + 1));
            for n in normals {
                // Draw even for skipped normals so each normal's noise depends on its index only.
                let (g1, g2) = (rng.normal(), rng.normal());
                let Some(unit) = n.try_normalize() else {
                    continue;
                };
                let (t1, t2) = unit.any_orthonormal_pair();
                *n = (unit + (t1 * g1 + t2 * g2) * normal_sigma_radians).normalize_or(unit);
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::figures::signed_volume;
    use crate::topology::analyze;

    #[test]
    fn implicit_sphere_is_watertight_and_outward() {
        let m = implicit_mesh(|p| p.length() - 1.0, Vec3::splat(-1.3), Vec3::splat(1.3), 20);
        let r = analyze(&m);
        assert!(r.is_watertight(), "{r:?}");
        assert_eq!(r.genus(), Some(0));
        let volume = signed_volume(&m);
        let exact = 4.0 / 3.0 * std::f64::consts::PI;
        assert!((volume - exact).abs() < 0.05 * exact, "volume {volume}");
        for (p, n) in m.positions.iter().zip(m.normals.as_ref().unwrap()) {
            assert!((p.length() - 1.0).abs() < 0.02);
            assert!(n.dot(p.normalize()) > 0.99);
        }
    }

    #[test]
    fn implicit_degenerate_inputs() {
        assert!(implicit_mesh(|p| p.length() - 1.0, Vec3::ONE, Vec3::ONE, 10).positions.is_empty());
        assert!(implicit_mesh(|_| f32::NAN, Vec3::ZERO, Vec3::ONE, 4).triangles.is_empty());
        // Zero exactly at grid points (the plane z = 0 through a grid layer) still gives a
        // manifold surface with no coincident vertices.
        let m = implicit_mesh(|p| (p.length() - 1.0).max(-p.z), Vec3::splat(-1.5), Vec3::splat(1.5), 12);
        let r = analyze(&m);
        assert!(r.is_watertight(), "{r:?}");
    }

    #[test]
    fn alias_table_reproduces_the_weights() {
        let weights = [1.0, 0.0001, 5.0, 2.5, 0.3, 1.2];
        let items: Vec<u32> = (10..16).collect();
        let table = AliasTable::new(&items, &weights);
        let total: f64 = weights.iter().sum();
        let mut rng = Rng::new(1);
        let n = 1_000_000;
        let mut counts = [0usize; 6];
        for _ in 0..n {
            counts[(table.draw(rng.next_u64()) - 10) as usize] += 1;
        }
        for (c, w) in counts.iter().zip(weights) {
            let expected = w / total * n as f64;
            let sd = expected.sqrt().max(1.0);
            assert!((*c as f64 - expected).abs() < 5.0 * sd, "{counts:?}");
        }
    }

    #[test]
    fn noise_statistics() {
        let n = 100_000;
        let mut cloud = Mesh::from_points(vec![Vec3::ZERO; n], Some(vec![Vec3::Z; n]));
        add_noise(&mut cloud, 0.01, 0.05, 3);
        let var = cloud.positions.iter().map(|p| p.length_squared()).sum::<f32>() / (3 * n) as f32;
        assert!((var.sqrt() - 0.01).abs() < 2e-4, "sigma {}", var.sqrt());
        let normals = cloud.normals.unwrap();
        let mean_angle = normals.iter().map(|v| v.z.clamp(-1.0, 1.0).acos()).sum::<f32>() / n as f32;
        let expected = 0.05 * (std::f32::consts::PI / 2.0).sqrt();
        assert!((mean_angle - expected).abs() < 0.02 * expected, "{mean_angle} vs {expected}");
        assert!(normals.iter().all(|v| (v.length() - 1.0).abs() < 1e-5));
    }
}
