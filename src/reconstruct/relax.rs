//! Better-shaped triangles for the base mesh M0. Refinement splits every triangle 1-to-4 into
//! four of the same shape, so the output's angles are M0's; and M0, clustered from a
//! marching-tetrahedra mesh at the T-layer, has slivers. M0 is small, so it is remeshed in
//! place (the paper's suggestion): rounds of Delaunay edge flips where the surface is flat
//! enough for a flip not to cut a ridge, then tangential relaxation, each vertex put back on the
//! samples' local fit ([`super::mls`]). Flips keep a manifold's topology (an edge is never
//! flipped onto one that exists) and border edges and vertices never change. Each refined
//! level's new vertices are relaxed the same way ([`relax_level`]), since displacement skews
//! the split's triangles.

use super::adjacency::Rows;
use super::mls::{project_vertices, SampleSurface};
use super::refine::Surface;
use crate::progress::Threads;
use glam::Vec3;
use rayon::prelude::*;
use std::collections::HashMap;

/// Rounds of flips and relaxation: each round's relaxation changes which flips pay.
const ROUNDS: usize = 3;
/// A flip is made only where the two triangles, before and after, have normals within this
/// cosine of each other (about 25 degrees): a sharper bend is a ridge of the surface, which
/// the flip would cut across.
const FLAT_ENOUGH: f32 = 0.9;
/// A vertex is not relaxed where a neighbour's normal is farther than this cosine from its own
/// (about 45 degrees): see [`relax`].
const BENT: f32 = 0.7;
/// Relaxations of a refinement level's new vertices (see [`relax_level`]).
const LEVEL_ROUNDS: usize = 2;
/// Share of the way to its neighbours' mean that a vertex moves in one relaxation.
const RELAX_STEP: f32 = 0.5;

/// Flips and relaxes `s` (see the module), projecting moved vertices back onto `onto` within
/// `reach`.
pub(crate) fn improve(s: &mut Surface, onto: &SampleSurface, reach: f32, threads: &Threads) {
    let border = crate::topology::border_vertices(&s.triangles, s.positions.len());
    for _ in 0..ROUNDS {
        flip_edges(s);
        let neighbours = Rows::neighbours(&s.triangles, s.positions.len());
        relax(s, &neighbours, &border, threads);
        project_vertices(s, 0, onto, reach, threads);
    }
}

/// After a refinement level: [`LEVEL_ROUNDS`] tangential relaxations of the vertices from
/// `first` on (the level's new ones), before they are projected onto the samples. The 1-to-4
/// split keeps M0's shapes, but displacement moves a new vertex to its leaf's average sample,
/// anywhere in the leaf, which skews the triangles around it. `border`: [`crate::topology::border_vertices`].
pub(crate) fn relax_level(s: &mut Surface, first: usize, border: &[bool], threads: &Threads) {
    let mut fixed = border.to_vec();
    fixed[..first].fill(true);
    // The triangles stay the same while the vertices move: the rings are found once.
    let neighbours = Rows::neighbours(&s.triangles, s.positions.len());
    for _ in 0..LEVEL_ROUNDS {
        relax(s, &neighbours, &fixed, threads);
    }
}

/// The angle at `c` in triangle (a, b, c), in radians.
fn angle_at(c: Vec3, a: Vec3, b: Vec3) -> f32 {
    (a - c).angle_between(b - c)
}

/// Unit normal of triangle (a, b, c), zero when degenerate.
fn normal(a: Vec3, b: Vec3, c: Vec3) -> Vec3 {
    (b - a).cross(c - a).normalize_or_zero()
}

/// Passes of Delaunay flips: an interior edge a-b, with c opposite in one triangle and d in the
/// other, becomes c-d where the angles at c and d add up to more than π (the flip then raises
/// the smallest angle of the pair), unless c-d is already an edge, a or b would keep fewer than
/// three neighbours, or the quad is bent (see [`FLAT_ENOUGH`]).
fn flip_edges(s: &mut Surface) {
    // Directed edge -> its triangle; edges that more than one triangle runs the same way
    // (a non-manifold or inconsistently oriented spot) are left alone.
    let mut face_of: HashMap<(u32, u32), u32> = HashMap::new();
    let mut tangled: Vec<(u32, u32)> = Vec::new();
    for (f, t) in s.triangles.iter().enumerate() {
        for k in 0..3 {
            if face_of.insert((t[k], t[(k + 1) % 3]), f as u32).is_some() {
                tangled.push((t[k], t[(k + 1) % 3]));
            }
        }
    }
    for e in tangled {
        face_of.remove(&e);
        face_of.remove(&(e.1, e.0));
    }
    // Edges leaving each vertex: its valence inside the mesh (one less on a border).
    let mut valence = vec![0u32; s.positions.len()];
    for &(a, _) in face_of.keys() {
        valence[a as usize] += 1;
    }
    let opposite = |t: &[u32; 3], a: u32, b: u32| t.iter().copied().find(|&v| v != a && v != b);
    let mut edges: Vec<(u32, u32)> = face_of.keys().copied().filter(|&(a, b)| a < b).collect();
    edges.sort_unstable();
    for (a, b) in edges {
        let (Some(&f1), Some(&f2)) = (face_of.get(&(a, b)), face_of.get(&(b, a))) else { continue };
        let (t1, t2) = (s.triangles[f1 as usize], s.triangles[f2 as usize]);
        let (Some(c), Some(d)) = (opposite(&t1, a, b), opposite(&t2, a, b)) else { continue };
        if c == d || face_of.contains_key(&(c, d)) || face_of.contains_key(&(d, c)) {
            continue;
        }
        if valence[a as usize] <= 3 || valence[b as usize] <= 3 {
            continue;
        }
        let [pa, pb, pc, pd] = [a, b, c, d].map(|v| s.positions[v as usize]);
        if angle_at(pc, pa, pb) + angle_at(pd, pa, pb) <= std::f32::consts::PI + 1e-3 {
            continue;
        }
        let (old1, old2) = (normal(pa, pb, pc), normal(pb, pa, pd));
        let (new1, new2) = (normal(pa, pd, pc), normal(pd, pb, pc));
        let corners: Vec3 = [a, b, c, d].iter().map(|&v| s.normals[v as usize]).sum();
        if old1.dot(old2) < FLAT_ENOUGH
            || new1.dot(new2) < FLAT_ENOUGH
            || new1.dot(corners) <= 0.0
            || new2.dot(corners) <= 0.0
        {
            continue;
        }
        // (a, b, c) and (b, a, d) become (a, d, c) and (d, b, c).
        s.triangles[f1 as usize] = [a, d, c];
        s.triangles[f2 as usize] = [d, b, c];
        face_of.remove(&(a, b));
        face_of.remove(&(b, a));
        face_of.insert((a, d), f1);
        face_of.insert((d, c), f1);
        face_of.insert((b, c), f2);
        face_of.insert((c, d), f2);
        valence[a as usize] -= 1;
        valence[b as usize] -= 1;
        valence[c as usize] += 1;
        valence[d as usize] += 1;
    }
}

/// Moves every vertex not on the border [`RELAX_STEP`] of the way to the mean of its
/// neighbours, within its tangent plane.
fn relax(s: &mut Surface, neighbours: &Rows, fixed: &[bool], threads: &Threads) {
    let moved: Vec<Vec3> = threads.run(|| {
        (0..s.positions.len())
            .into_par_iter()
            .map(|v| {
                let ring = neighbours.of(v as u32);
                let p = s.positions[v];
                if fixed[v] || ring.is_empty() {
                    return p;
                }
                let n = s.normals[v];
                // Where the surface bends sharply over one ring (a tip, a ridge), the ring's
                // mean lies on the blunter side: moving there would cut the tip short.
                if ring.iter().any(|&w| s.normals[w as usize].dot(n) < BENT) {
                    return p;
                }
                let mean = ring.iter().map(|&w| s.positions[w as usize]).sum::<Vec3>() / ring.len() as f32;
                let delta = mean - p;
                p + RELAX_STEP * (delta - n * n.dot(delta))
            })
            .collect()
    });
    s.positions = moved;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Mesh;
    use crate::reconstruct::mls::tests::sphere_samples;
    use crate::{eval::shapes, rng::Rng, topology};

    /// Share of triangles with an angle under `degrees`.
    fn thin_share(s: &Surface, degrees: f32) -> f32 {
        let thin = s
            .triangles
            .iter()
            .filter(|t| {
                let [a, b, c] = t.map(|v| s.positions[v as usize]);
                angle_at(a, b, c).min(angle_at(b, c, a)).min(angle_at(c, a, b)) < degrees.to_radians()
            })
            .count();
        thin as f32 / s.triangles.len() as f32
    }

    #[test]
    fn slivers_on_a_sphere_become_well_shaped_and_stay_on_it() {
        // An icosphere whose vertices slid along the surface by up to 40% of an edge (10% of
        // its triangles under 20 degrees), on the same sphere, genus 0. Measured: none after.
        let sphere = shapes::icosphere(1.0, 3);
        let mut rng = Rng::new(3);
        let positions: Vec<Vec3> = sphere
            .positions
            .iter()
            .map(|&p| {
                let (u, v) = p.any_orthonormal_pair();
                let edge = 0.16;
                let shift = u * (rng.f32() - 0.5) + v * (rng.f32() - 0.5);
                (p + 0.8 * edge * shift).normalize()
            })
            .collect();
        let mut s = Surface {
            normals: positions.clone(),
            labels: vec![0; positions.len()],
            positions,
            triangles: sphere.triangles.clone(),
        };
        let samples = sphere_samples(20_000, 1.0);
        let threads = Threads::new(1).unwrap();
        let onto = SampleSurface::new(&samples, &threads).unwrap();
        let before = thin_share(&s, 20.0);
        improve(&mut s, &onto, 0.1, &threads);
        let after = thin_share(&s, 20.0);
        assert!(before > 0.08 && after < 0.02, "under 20 degrees: {before} -> {after}");
        let off = s.positions.iter().map(|p| (p.length() - 1.0).abs()).fold(0.0f32, f32::max);
        assert!(off < 1e-3, "a vertex {off} off the sphere");
        let report = topology::analyze(&Mesh::new(s.positions.clone(), None, s.triangles.clone()));
        assert!(report.is_watertight() && report.genus() == Some(0), "{report:?}");
    }

    #[test]
    fn a_refined_levels_new_vertices_are_relaxed_and_the_old_ones_stay() {
        // An icosphere split once more; the new (mid-edge) vertices slid along the sphere by
        // up to 60% of an edge, as displacement to a leaf's sample does. Relaxing the level
        // makes its triangles well shaped again and leaves the old vertices where they were.
        let coarse = shapes::icosphere(1.0, 2);
        let fine = shapes::icosphere(1.0, 3);
        let first = coarse.positions.len();
        let mut rng = Rng::new(5);
        let edge = 0.16;
        let positions: Vec<Vec3> = fine
            .positions
            .iter()
            .enumerate()
            .map(|(v, &p)| {
                if v < first {
                    return p;
                }
                let (u, w) = p.any_orthonormal_pair();
                (p + 1.2 * edge * (u * (rng.f32() - 0.5) + w * (rng.f32() - 0.5))).normalize()
            })
            .collect();
        let mut s = Surface {
            normals: positions.clone(),
            labels: vec![0; positions.len()],
            positions,
            triangles: fine.triangles.clone(),
        };
        let before = thin_share(&s, 20.0);
        let border = crate::topology::border_vertices(&s.triangles, s.positions.len());
        relax_level(&mut s, first, &border, &Threads::new(1).unwrap());
        let after = thin_share(&s, 20.0);
        assert!(before > 0.08 && after < 0.03, "under 20 degrees: {before} -> {after}");
        assert!(s.positions[..first] == fine.positions[..first], "an old vertex moved");
    }
}
