//! The first pass of a large decimation, in parallel: the mesh is cut into chunks (see
//! [`crate::chunks`]), each with its own queue on its own thread, its seams locked. The chunks
//! collapse in rounds under one cost cap: each round the cap rises to the cost below which a
//! share of the collapses still needed lie, over every chunk's queue, and each chunk takes what
//! its queue holds below the cap. So collapses come in about the order of one queue over the
//! whole mesh, and a detailed chunk keeps more of its triangles than a flat one; a chunk's
//! queue and stars (a few MB) stay in the cache, where one queue over millions of edges misses
//! it at every pop.

use super::Decimator;
use crate::chunks::{morton_chunks, submesh, Chunks};
use crate::error::Result;
use crate::mesh::Mesh;
use crate::progress::{Progress, Threads};
use crate::quadric::CellStats;
use glam::DVec3;
use rayon::prelude::*;

/// Triangles per chunk: a chunk's queue fits the cache, and its seams (locked until the serial
/// pass) are a few percent of its vertices.
const CHUNK_TRIANGLES: usize = 50_000;

/// The rounds end when the chunks hold at most this much more than their goal (a ratio of
/// triangles): the last rounds would take a few collapses each, which the serial pass takes as
/// cheaply.
const CLOSE_ENOUGH: f64 = 0.02;

/// Each round's cap lets through this share of the collapses still needed (a ratio): each chunk
/// takes at most twice what its queue held below the cap, so a round never removes more than
/// two thirds of the excess, and the cap rises in small steps, as one queue's costs would.
const ROUND_SHARE: f64 = 1.0 / 3.0;

/// Triangles the chunks leave, beyond the target, per triangle of the seams (a ratio): a
/// locked seam keeps a fan of triangles on each side, which the serial pass, and not the
/// chunks' detail, must pay for; without this room the chunks over-simplify their detail to
/// make up for the seams (a plate bumpy in one corner kept 64% of its triangles there, one
/// queue 99%).
const SEAM_ROOM: usize = 2;

/// A mesh part way through a decimation: the mesh, its positions and quadrics, and the input
/// vertex each of its vertices is.
pub(super) struct Near {
    pub(super) mesh: Mesh,
    pub(super) positions: Vec<DVec3>,
    pub(super) quadrics: Vec<CellStats>,
    pub(super) from: Vec<u32>,
}

/// Decimates the chunks of `near` in parallel until they hold about `target` triangles beyond
/// the room their seams need, the seams locked; `shift` places the chunks' grid (see
/// [`morton_chunks`]). The input vertex of each vertex is followed. `None` when the mesh is too
/// small for more than one chunk, or its seams leave the chunks nothing to do.
pub(super) fn decimate_in_chunks(
    near: &Near,
    target: usize,
    shift: f32,
    threads: &Threads,
    progress: &mut Progress,
) -> Result<Option<Near>> {
    let Near { mesh, positions, quadrics, from } = near;
    let count = mesh.triangles.len() / CHUNK_TRIANGLES;
    if count < 2 {
        return Ok(None);
    }
    let chunk_of = threads.run(|| morton_chunks(&mesh.positions, count, shift));
    let chunks = threads.run(|| Chunks::new(mesh, count, |v| chunk_of[v as usize]));
    let seams = chunks.triangles(count).len();
    let goal = (target + SEAM_ROOM * seams) as f64;
    if goal >= (mesh.triangles.len() - seams) as f64 {
        return Ok(None);
    }
    let mut parts: Vec<(Vec<u32>, Decimator)> = threads.run(|| {
        chunks
            .runs()
            .par_iter()
            .map(|run| {
                let (vertices, sub) = submesh(mesh, run);
                let locked = vertices.iter().map(|&v| chunks.seam[v as usize]).collect();
                let sub_positions = vertices.iter().map(|&v| positions[v as usize]).collect();
                let sub_quadrics = vertices.iter().map(|&v| quadrics[v as usize]).collect();
                let mut d = Decimator::new(&sub, sub_positions, sub_quadrics, Some(locked));
                d.seed();
                (vertices, d)
            })
            .collect()
    });
    let start = parts.iter().map(|(_, d)| d.faces).sum::<usize>() as f64 - goal;
    loop {
        let faces: usize = parts.iter().map(|(_, d)| d.faces).sum();
        let excess = faces as f64 - goal;
        if excess <= CLOSE_ENOUGH * goal {
            break;
        }
        progress.report((1.0 - excess / start) as f32, "collapsing edges to the size")?;
        // Two triangles go per collapse.
        let wanted = (excess / 2.0 * ROUND_SHARE).ceil() as usize;
        let mut costs: Vec<f64> = threads.run(|| {
            parts
                .par_iter()
                .flat_map_iter(|(_, d)| d.heap.items().iter().filter(|c| c.is_current(&d.versions)).map(|c| c.cost))
                .collect()
        });
        if costs.is_empty() {
            break;
        }
        let k = wanted.min(costs.len() - 1);
        let (_, &mut cap, _) = costs.select_nth_unstable_by(k, f64::total_cmp);
        let taken: usize = threads.run(|| {
            parts
                .par_iter_mut()
                .map(|(_, d)| {
                    let below = d.heap.items().iter().filter(|c| c.cost <= cap && c.is_current(&d.versions)).count();
                    d.take_below(cap, 2 * below)
                })
                .sum()
        });
        if taken == 0 {
            break;
        }
    }
    // The seams' triangles as they were, the chunks' survivors where they went.
    let mut positions = positions.to_vec();
    let mut quadrics = quadrics.to_vec();
    let mut triangles: Vec<[u32; 3]> = chunks.triangles(count).iter().map(|&t| mesh.triangles[t as usize]).collect();
    for (vertices, d) in parts {
        let identity: Vec<u32> = (0..vertices.len() as u32).collect();
        let (left, kept) = d.collapser.finish(&identity);
        for &v in &kept {
            positions[vertices[v as usize] as usize] = d.positions[v as usize];
            quadrics[vertices[v as usize] as usize] = d.quadrics[v as usize];
        }
        triangles.extend(left.triangles.iter().map(|t| t.map(|v| vertices[kept[v as usize] as usize])));
    }
    let kept = crate::reconstruct::renumber_used_vertices(&mut triangles, positions.len());
    Ok(Some(Near {
        mesh: Mesh::new(kept.iter().map(|&v| mesh.positions[v]).collect(), None, triangles),
        positions: kept.iter().map(|&v| positions[v]).collect(),
        quadrics: kept.iter().map(|&v| quadrics[v]).collect(),
        from: kept.iter().map(|&v| from[v]).collect(),
    }))
}

impl Decimator {
    /// Takes the cheapest allowed collapses while they cost at most `cap`, at most `most` of
    /// them; how many it took.
    fn take_below(&mut self, cap: f64, most: usize) -> usize {
        let mut taken = 0;
        while taken < most {
            self.drop_stale(self.faces);
            if self.heap.peek().is_none_or(|c| c.cost > cap) {
                break;
            }
            let Some(c) = self.heap.pop() else { break };
            taken += usize::from(self.take(c));
        }
        taken
    }
}

#[cfg(test)]
mod tests {
    use super::super::{decimate, tests::face_quadrics};
    use super::*;
    use crate::eval::shapes;
    use crate::progress::{Progress, Threads};
    use crate::topology::analyze;

    /// The largest distance of `mesh`'s vertices from the torus of radii 1 and 0.3 about z.
    fn off_the_torus(mesh: &Mesh) -> f32 {
        let off = |p: &glam::Vec3| ((p.truncate().length() - 1.0).hypot(p.z) - 0.3).abs();
        mesh.positions.iter().map(off).fold(0.0, f32::max)
    }

    fn positions(mesh: &Mesh) -> Vec<DVec3> {
        mesh.positions.iter().map(|p| p.as_dvec3()).collect()
    }

    /// `mesh` before any collapse.
    fn whole(mesh: &Mesh, quadrics: &[CellStats]) -> Near {
        let from = (0..mesh.positions.len() as u32).collect();
        Near { mesh: mesh.clone(), positions: positions(mesh), quadrics: quadrics.to_vec(), from }
    }

    #[test]
    fn a_large_mesh_goes_in_chunks_as_well_as_in_one_queue() {
        // 262k triangles: five chunks, which stop at their share of the target.
        let torus = shapes::torus(1.0, 0.3, 512, 256);
        let quadrics = face_quadrics(&torus);
        let target = 20_000;
        let near = decimate_in_chunks(
            &whole(&torus, &quadrics),
            target,
            0.0,
            &Threads::new(2).unwrap(),
            &mut Progress::none(),
        )
        .unwrap()
        .expect("chunks");
        let left = near.mesh.triangles.len();
        assert!(left > target && left < target * 2, "{left} left for {target}");
        assert_eq!(near.from.len(), near.mesh.positions.len());
        let r = analyze(&near.mesh);
        assert!(r.is_watertight() && r.genus() == Some(1), "{r:?}");

        let (chunked, _) =
            decimate(&torus, quadrics.clone(), DVec3::ZERO, target, &Threads::new(2).unwrap(), &mut Progress::none())
                .unwrap();
        let r = analyze(&chunked);
        assert!(r.is_watertight() && r.genus() == Some(1), "{r:?}");
        assert!(chunked.triangles.len().abs_diff(target) <= 1);
        let mut one = Decimator::new(&torus, positions(&torus), quadrics, None);
        one.run(target);
        let (mut queued, kept) = one.collapser.finish(&(0..torus.positions.len() as u32).collect::<Vec<_>>());
        for (p, &v) in queued.positions.iter_mut().zip(&kept) {
            *p = one.positions[v as usize].as_vec3();
        }
        let (a, b) = (off_the_torus(&chunked), off_the_torus(&queued));
        assert!(a < 1.25 * b, "in chunks {a}, in one queue {b}");
    }

    #[test]
    fn a_detailed_chunk_keeps_more_than_a_flat_one() {
        // A plate of 320k triangles (six chunks), bumpy in one corner, a tenth of its area: the
        // shared cost cap spends nearly all of the target there (one queue: 99%), where
        // shares by triangle count would give the corner a tenth.
        let mut plate = shapes::square_grid(400);
        let corner = |p: glam::Vec3| p.x < 0.316 && p.y < 0.316;
        for p in &mut plate.positions {
            if corner(*p) {
                p.z = 0.01 * (60.0 * p.x).sin() * (60.0 * p.y).sin();
            }
        }
        let quadrics = face_quadrics(&plate);
        assert!(decimate_in_chunks(
            &whole(&plate, &quadrics),
            10_000,
            0.0,
            &Threads::new(2).unwrap(),
            &mut Progress::none()
        )
        .unwrap()
        .is_some());
        let (out, _) =
            decimate(&plate, quadrics, DVec3::ZERO, 10_000, &Threads::new(2).unwrap(), &mut Progress::none()).unwrap();
        let in_corner = |t: &&[u32; 3]| corner(t.iter().map(|&v| out.positions[v as usize]).sum::<glam::Vec3>() / 3.0);
        let there = out.triangles.iter().filter(in_corner).count();
        assert!(there > out.triangles.len() * 3 / 4, "{there} of {} in the corner", out.triangles.len());
    }

    #[test]
    fn the_rounds_report_progress_and_stop_when_cancelled() {
        let torus = shapes::torus(1.0, 0.3, 512, 256);
        let quadrics = face_quadrics(&torus);
        let threads = Threads::new(2).unwrap();
        let mut seen = Vec::new();
        let mut record = |fraction: f32, _: &str| {
            seen.push(fraction);
            true
        };
        decimate(&torus, quadrics.clone(), DVec3::ZERO, 20_000, &threads, &mut Progress::new(&mut record)).unwrap();
        assert!(seen.len() > 4 && seen.windows(2).all(|w| w[0] <= w[1]), "{seen:?}");
        let mut calls = 0;
        let mut cancel = |_: f32, _: &str| {
            calls += 1;
            calls < 3
        };
        let cancelled = decimate(&torus, quadrics, DVec3::ZERO, 20_000, &threads, &mut Progress::new(&mut cancel));
        assert!(cancelled.is_err());
    }
}
