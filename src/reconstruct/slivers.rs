//! Folds that moving vertices cannot undo, collapsed. After the last level's unfolding
//! ([`folds::unfold`]) a few faces stay folded: mostly slivers, where the projection put two or
//! three vertices onto nearly one point of the samples' surface, so that no position of any
//! one vertex opens the fold. Collapsing an edge of a folded face takes the sliver out. Each
//! collapse keeps the topology (the link condition, [`Collapser`]) and is made only where the
//! faces around the merged vertex then fold fewer times than before; the merged vertex goes
//! wherever they fold fewest: at either end, or at the edge's midpoint moved onto the samples'
//! fit. Between rounds of collapses, a vertex still folded moves to its neighbours' mean where
//! that folds fewer faces.
//!
//! The work is local: it runs on the faces within two rings of the folded vertices, and only
//! those vertices move or merge, so every face whose fold a change can make or undo is counted.

use super::folds::{self, FOLD_DEGREES};
use super::mls::SampleSurface;
use super::prepare::keep_unmarked;
use super::refine::Surface;
use crate::collapse::Collapser;
use crate::mesh::Mesh;
use crate::progress::Threads;
use crate::spatial::KdTree;
use glam::Vec3;
use rayon::prelude::*;

/// Rounds of collapses and moves; each takes what the one before left folded.
const ROUNDS: usize = 8;

/// Collapses edges of the folded faces around `folded` (the vertices [`folds::unfold`] left
/// folded) where that leaves fewer folds; returns how many were collapsed. Merged-away vertices
/// leave `s`. A new position moved onto `onto` travels at most
/// `reach`. With `within` (samples and a distance), only vertices that near a sample move or
/// merge: faces with every corner farther stay as they are.
pub(crate) fn collapse_folds(
    s: &mut Surface,
    folded: &[usize],
    onto: &SampleSurface,
    reach: f32,
    within: Option<(&KdTree, f32)>,
    threads: &Threads,
) -> usize {
    let folded: Vec<usize> = match within {
        Some((samples, distance)) => {
            folded.iter().copied().filter(|&v| samples.any_within(s.positions[v], distance)).collect()
        }
        None => folded.to_vec(),
    };
    if folded.is_empty() {
        return 0;
    }
    let mut local = Local::around(s, &folded, threads);
    let (collapsed, moved) = local.collapse(onto, reach, threads);
    if collapsed + moved > 0 {
        local.write_back(s);
    }
    collapsed
}

/// The faces within two rings of the folded vertices, renumbered, under collapses.
struct Local {
    /// Per local vertex: its index in the surface, and whether it may move or merge: it was
    /// folded, so its star and the faces across its star's edges are local, and it is not on a
    /// border.
    global: Vec<u32>,
    movable: Vec<bool>,
    /// The local vertices' positions and normals; its triangles are the collapser's live
    /// faces as of the last fold test.
    s: Surface,
    /// The surface's faces that are local, in order.
    faces: Vec<u32>,
    collapser: Collapser,
}

impl Local {
    fn around(s: &Surface, folded: &[usize], threads: &Threads) -> Local {
        let n = s.positions.len();
        // Ring by ring: the folded vertices, their neighbours (whose stars are kept whole),
        // and the neighbours' neighbours, whose faces hold the faces across the stars' edges.
        let mut ring = vec![0u8; n];
        for &v in folded {
            ring[v] = 1;
        }
        for level in 1..3u8 {
            let touched: Vec<u32> = threads.run(|| {
                s.triangles
                    .par_iter()
                    .filter(|t| t.iter().any(|&v| ring[v as usize] == level))
                    .flat_map_iter(|t| t.iter().copied())
                    .collect()
            });
            for v in touched {
                if ring[v as usize] == 0 {
                    ring[v as usize] = level + 1;
                }
            }
        }
        // Stars of every vertex up to the second ring: the faces that touch them.
        let faces: Vec<u32> = threads.run(|| {
            (0..s.triangles.len() as u32)
                .into_par_iter()
                .filter(|&t| s.triangles[t as usize].iter().any(|&v| (1..=2).contains(&ring[v as usize])))
                .collect()
        });
        let mut index = std::collections::HashMap::new();
        let mut global = Vec::new();
        let triangles: Vec<[u32; 3]> = faces
            .iter()
            .map(|&t| {
                s.triangles[t as usize].map(|v| {
                    *index.entry(v).or_insert_with(|| {
                        global.push(v);
                        global.len() as u32 - 1
                    })
                })
            })
            .collect();
        let positions: Vec<Vec3> = global.iter().map(|&v| s.positions[v as usize]).collect();
        let collapser = Collapser::new(&Mesh::new(positions.clone(), None, triangles));
        let movable =
            (0..global.len()).map(|k| ring[global[k] as usize] == 1 && !collapser.is_border(k as u32)).collect();
        let s = Surface {
            positions,
            normals: global.iter().map(|&v| s.normals[v as usize]).collect(),
            labels: Vec::new(),
            triangles: Vec::new(),
        };
        Local { global, movable, s, faces, collapser }
    }

    /// In rounds while any is made: the collapses, shortest candidate edge first, then the moves
    /// of the vertices still folded.
    /// Returns the collapses and the moves made.
    fn collapse(&mut self, onto: &SampleSurface, reach: f32, threads: &Threads) -> (usize, usize) {
        let (mut collapsed, mut moves) = (0, 0);
        for _ in 0..ROUNDS {
            let folded = self.folded_triangles(threads);
            let mut edges: Vec<(f32, u32, u32)> = folded
                .iter()
                .flat_map(|t| (0..3).map(move |k| (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3]))))
                .filter(|&(a, b)| self.movable[a as usize] && self.movable[b as usize])
                .map(|(a, b)| (self.s.positions[a as usize].distance(self.s.positions[b as usize]), a, b))
                .collect();
            edges.sort_unstable_by(|x, y| x.0.total_cmp(&y.0).then((x.1, x.2).cmp(&(y.1, y.2))));
            edges.dedup_by_key(|e| (e.1, e.2));
            let before = collapsed;
            for (_, a, b) in edges {
                collapsed += usize::from(self.try_collapse(a, b, onto, reach));
            }
            let mut moved = 0;
            let mut corners: Vec<u32> = self.folded_triangles(threads).into_iter().flatten().collect();
            corners.sort_unstable();
            corners.dedup();
            for v in corners {
                moved += usize::from(self.movable[v as usize] && self.try_move(v, onto, reach));
            }
            moves += moved;
            if collapsed == before && moved == 0 {
                break;
            }
        }
        (collapsed, moves)
    }

    /// The local faces whose corners are all on folds now (faces facing against their corners'
    /// normals, or turned against a neighbour across an edge by more than [`FOLD_DEGREES`]).
    fn folded_triangles(&mut self, threads: &Threads) -> Vec<[u32; 3]> {
        let s = &mut self.s;
        s.triangles = self.collapser.live_triangles();
        let pairs = threads.run(|| crate::topology::adjacent_face_pairs(&s.triangles));
        let folded = threads.run(|| folds::folded_or_creased_vertices(s, &pairs));
        let mut is_folded = vec![false; s.positions.len()];
        for v in folded {
            is_folded[v] = true;
        }
        s.triangles.iter().copied().filter(|t| t.iter().all(|&v| is_folded[v as usize])).collect()
    }

    /// Moves `v` to the mean of its neighbours, onto the samples' fit or not, where the faces
    /// around it then fold fewer times.
    fn try_move(&mut self, v: u32, onto: &SampleSurface, reach: f32) -> bool {
        let star: Vec<[u32; 3]> = self.collapser.faces_around(v).collect();
        let mut ring: Vec<u32> = star.iter().flatten().copied().filter(|&w| w != v).collect();
        ring.sort_unstable();
        ring.dedup();
        if ring.is_empty() {
            return false;
        }
        let across = self.faces_across(&star, &[v]);
        let at = |w: u32| (self.s.positions[w as usize], self.s.normals[w as usize]);
        let before = count_folds(&star, &across, at);
        let mean = ring.iter().map(|&w| self.s.positions[w as usize]).sum::<Vec3>() / ring.len() as f32;
        let normal = ring.iter().map(|&w| self.s.normals[w as usize]).sum::<Vec3>().normalize_or_zero();
        let normal = if normal == Vec3::ZERO { self.s.normals[v as usize] } else { normal };
        let projected = onto.project(mean, normal).filter(|(p, _)| p.distance(mean) <= reach);
        let best = projected
            .into_iter()
            .chain([(mean, normal)])
            .map(|(p, n)| (count_folds(&star, &across, |w| if w == v { (p, n) } else { at(w) }), p, n))
            .min_by_key(|option| option.0);
        let Some((_, p, n)) = best.filter(|best| best.0 < before) else { return false };
        self.s.positions[v as usize] = p;
        self.s.normals[v as usize] = n;
        true
    }

    /// Merges `a` and `b` if the link condition allows it and the faces around the merged vertex
    /// then fold fewer times, at the position where they fold fewest.
    fn try_collapse(&mut self, a: u32, b: u32, onto: &SampleSurface, reach: f32) -> bool {
        let c = &mut self.collapser;
        if !c.is_alive(a) || !c.is_alive(b) || !c.can_collapse(a, b) {
            return false;
        }
        let mut star: Vec<[u32; 3]> = c.faces_around(a).chain(c.faces_around(b)).collect();
        star.sort_unstable();
        star.dedup();
        let across = self.faces_across(&star, &[a, b]);
        let at = |v: u32| (self.s.positions[v as usize], self.s.normals[v as usize]);
        let before = count_folds(&star, &across, at);
        let merged: Vec<[u32; 3]> = star
            .iter()
            .filter(|t| !(t.contains(&a) && t.contains(&b)))
            .map(|t| t.map(|v| if v == a { b } else { v }))
            .collect();
        let (pa, pb) = (at(a), at(b));
        let middle = (pa.0 + pb.0) / 2.0;
        let normal = (pa.1 + pb.1).normalize_or_zero();
        let projected = onto.project(middle, if normal == Vec3::ZERO { pb.1 } else { normal });
        let options = projected.filter(|(p, _)| p.distance(middle) <= reach).into_iter().chain([pa, pb]);
        let best = options
            .map(|(p, n)| (count_folds(&merged, &across, |v| if v == b { (p, n) } else { at(v) }), p, n))
            .min_by_key(|option| option.0);
        let Some((after, p, n)) = best else { return false };
        if after >= before {
            return false;
        }
        self.collapser.merge(a, b);
        self.s.positions[b as usize] = p;
        self.s.normals[b as usize] = n;
        true
    }

    /// The faces across the outer edges of `star` (the faces around the vertices `inner`):
    /// those that share an edge with it without touching `inner`.
    fn faces_across(&self, star: &[[u32; 3]], inner: &[u32]) -> Vec<[u32; 3]> {
        let outside = |f: &[u32; 3]| !f.iter().any(|v| inner.contains(v));
        let mut across: Vec<[u32; 3]> = Vec::new();
        for t in star {
            for k in 0..3 {
                let (x, y) = (t[k], t[(k + 1) % 3]);
                if inner.contains(&x) || inner.contains(&y) {
                    continue;
                }
                across.extend(self.collapser.faces_around(x).filter(|f| f.contains(&y) && outside(f)));
            }
        }
        across.sort_unstable();
        across.dedup();
        across
    }

    /// The collapsed faces back into `s`, and the merged-away vertices out of it.
    fn write_back(self, s: &mut Surface) {
        for (k, &v) in self.global.iter().enumerate() {
            s.positions[v as usize] = self.s.positions[k];
            s.normals[v as usize] = self.s.normals[k];
        }
        let mut local = vec![false; s.triangles.len()];
        for &t in &self.faces {
            local[t as usize] = true;
        }
        keep_unmarked(&mut s.triangles, &local);
        let live = self.collapser.live_triangles();
        s.triangles.extend(live.iter().map(|t| t.map(|v| self.global[v as usize])));
        s.drop_unused_vertices();
    }
}

/// The folds among `star` and between it and `across` (a pair of faces sharing an edge turned
/// by more than [`FOLD_DEGREES`]), plus each face of `star` that faces against its corners'
/// normals or has no normal (no area), with the vertices where `at` says.
fn count_folds(star: &[[u32; 3]], across: &[[u32; 3]], at: impl Fn(u32) -> (Vec3, Vec3)) -> usize {
    let normal = |t: &[u32; 3]| {
        let [p, q, r] = t.map(|v| at(v).0);
        let cross = (q - p).cross(r - p);
        let longest = (q - p).length_squared().max((r - q).length_squared()).max((p - r).length_squared());
        // No normal where twice the area is under a millionth of the longest edge squared
        // (an angle of about 0.0001 degrees).
        (cross.length() > 1e-6 * longest).then(|| cross.normalize())
    };
    let limit = FOLD_DEGREES.to_radians().cos();
    let star_normals: Vec<Option<Vec3>> = star.iter().map(normal).collect();
    let across_normals: Vec<Option<Vec3>> = across.iter().map(normal).collect();
    let mut folds = 0;
    for (i, (t, m)) in star.iter().zip(&star_normals).enumerate() {
        let Some(m) = m else {
            folds += 1;
            continue;
        };
        let corners: Vec3 = t.iter().map(|&v| at(v).1).sum();
        folds += usize::from(m.dot(corners) < 0.0);
        let later = star[i + 1..].iter().zip(&star_normals[i + 1..]);
        for (u, n) in later.chain(across.iter().zip(&across_normals)) {
            let shared = t.iter().filter(|v| u.contains(v)).count();
            folds += usize::from(shared == 2 && n.is_some_and(|n| m.dot(n) < limit));
        }
    }
    folds
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reconstruct::mls::tests::sphere_samples;

    /// An icosphere of radius 1 with radial normals.
    fn icosphere() -> Surface {
        let sphere = crate::eval::shapes::icosphere(1.0, 3);
        Surface {
            normals: sphere.positions.clone(),
            labels: vec![0; sphere.positions.len()],
            positions: sphere.positions,
            triangles: sphere.triangles,
        }
    }

    /// The neighbours of vertex `v` of `s`.
    fn ring(s: &Surface, v: u32) -> Vec<u32> {
        let mut ring: Vec<u32> =
            s.triangles.iter().filter(|t| t.contains(&v)).flatten().copied().filter(|&w| w != v).collect();
        ring.sort_unstable();
        ring.dedup();
        ring
    }

    /// Runs [`collapse_folds`] on `s` against samples of the unit sphere, and checks that no fold
    /// is left, that the surface is still a closed sphere and on the samples; returns the
    /// collapses.
    fn collapse_on_the_sphere(s: &mut Surface) -> usize {
        let threads = Threads::new(1).unwrap();
        let folded = folds::folded_or_creased_vertices(s, &crate::topology::adjacent_face_pairs(&s.triangles));
        assert!(!folded.is_empty(), "the surface is folded to begin with");
        let samples = sphere_samples(20_000, 1.0);
        let onto = SampleSurface::new(&samples, &threads).unwrap();
        let (vertices, faces) = (s.positions.len(), s.triangles.len());
        let collapsed = collapse_folds(s, &folded, &onto, 0.2, None, &threads);
        assert_eq!(s.positions.len(), vertices - collapsed, "merged vertices leave");
        assert_eq!(s.triangles.len(), faces - 2 * collapsed);
        let left = folds::folded_or_creased_vertices(s, &crate::topology::adjacent_face_pairs(&s.triangles));
        assert!(left.is_empty(), "still folded: {left:?}");
        let report = crate::topology::analyze(&Mesh::new(s.positions.clone(), None, s.triangles.clone()));
        assert!(report.is_watertight());
        assert_eq!(report.genus(), Some(0));
        let off = s.positions.iter().map(|p| (p.length() - 1.0).abs()).fold(0.0f32, f32::max);
        assert!(off < 1e-2, "a vertex {off} off the sphere");
        collapsed
    }

    /// The icosphere with vertex 0 moved onto a neighbour's place and 2% of their edge past
    /// it: the faces between them are slivers folded over.
    fn pushed_sliver() -> Surface {
        let mut s = icosphere();
        let neighbour = ring(&s, 0)[0] as usize;
        let (p, q) = (s.positions[0], s.positions[neighbour]);
        s.positions[0] = (q + 0.02 * (q - p)).normalize();
        s
    }

    #[test]
    fn a_sliver_folded_over_is_collapsed_and_the_sphere_stays_closed() {
        let mut s = pushed_sliver();
        assert!(collapse_on_the_sphere(&mut s) >= 1);
    }

    #[test]
    fn only_vertices_near_the_given_samples_change() {
        // The folded sliver of the test above, with samples only at the far pole: an open
        // output's part beyond its samples is left as the trim will find it.
        let mut s = pushed_sliver();
        let far_pole = KdTree::new(&[-s.positions[0]]).unwrap();
        let threads = Threads::new(1).unwrap();
        let folded = folds::folded_or_creased_vertices(&s, &crate::topology::adjacent_face_pairs(&s.triangles));
        let samples = sphere_samples(20_000, 1.0);
        let onto = SampleSurface::new(&samples, &threads).unwrap();
        let before = s.clone();
        assert_eq!(collapse_folds(&mut s, &folded, &onto, 0.2, Some((&far_pole, 0.5)), &threads), 0);
        assert_eq!((s.positions, s.triangles), (before.positions, before.triangles));
    }

    #[test]
    fn a_crumpled_patch_of_nearly_one_point_is_collapsed() {
        // A vertex's whole ring pulled to within a thousandth of an edge of it, each neighbour
        // on the far side of where it was: tiny faces folded every way, which no single move
        // opens.
        let mut s = icosphere();
        let centre = s.positions[0];
        for w in ring(&s, 0) {
            let p = s.positions[w as usize];
            s.positions[w as usize] = (centre - 1e-3 * (p - centre)).normalize();
        }
        let collapsed = collapse_on_the_sphere(&mut s);
        assert!(collapsed >= 3, "{collapsed} collapses");
    }
}
