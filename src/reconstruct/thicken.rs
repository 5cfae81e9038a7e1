//! Thin parts made whole: where a polygonisation of the base mesh's implicit function has
//! handles or several parts, it is made again a little outside the zero set, and kept if that
//! has fewer parts, or as many and fewer handles, its vertices moved back onto the samples.

use super::{adjacency, support};
use crate::mesh::Mesh;
use crate::progress::Threads;
use crate::topology;
use rayon::prelude::*;

/// The offset, in polygonisation cells (the grid's cell, or the finest leaf the octree may
/// have). The winding number, softened over a sample spacing, sinks below one half inside a
/// part thinner than about a cell, and the cell's corners see such a part on one side only: a
/// plate thinner than a cell, or an ear where overlapping scans disagree by about a cell, comes
/// out perforated, with spurious handles (on the grid) or in pieces (over the octree, whose
/// cells are larger). Offset, the part is thick enough to be seen; moving the vertices back
/// puts the surface where the samples are and cannot change the topology. Gaps narrower than
/// twice the offset close, but they are below what the cells resolve faithfully anyway. A
/// single part without handles is never thickened. Pinned by the test
/// `a_plate_thinner_than_the_grid_keeps_its_four_holes` (tests/reconstruct.rs).
pub(super) const THICKEN_CELLS: f32 = 1.5;
/// Ring averages of the mesh's normals before its vertices are moved back.
const NORMAL_SMOOTHING_PASSES: usize = 2;

/// `plain` (the zero set, with what came with it), or where it has handles, or with
/// `smallest` given several parts of at least that area (smaller ones are dropped later), the
/// zero set `THICKEN_CELLS * cell` outside, made by `at_offset` and moved back, if that has
/// fewer such parts, or as many and fewer handles; and whether it was thickened. (The grid's
/// cells are small enough that a thin part only ever perforates there: it counts handles
/// only.)
pub(super) fn where_handles<X>(
    plain: (Mesh, X),
    at_offset: impl FnOnce(f32) -> Option<(Mesh, X)>,
    cell: f32,
    smallest: Option<f64>,
    threads: &Threads,
) -> ((Mesh, X), bool) {
    let parts_of = |mesh: &Mesh| smallest.map_or(1, |smallest| parts_of_area(mesh, smallest));
    let (parts, genus) = (parts_of(&plain.0), topology::closed_surface_parts_and_genus(&plain.0).1);
    if parts <= 1 && genus == 0 {
        return (plain, false);
    }
    let offset = THICKEN_CELLS * cell;
    let better = |thick: &Mesh| {
        let (thick_parts, thick_genus) = (parts_of(thick), topology::closed_surface_parts_and_genus(thick).1);
        !thick.triangles.is_empty() && (thick_parts < parts || (thick_parts == parts && thick_genus < genus))
    };
    match at_offset(offset) {
        Some((mut thick, x)) if better(&thick) => {
            move_inward(&mut thick, offset, threads);
            ((thick, x), true)
        }
        _ => (plain, false),
    }
}

/// How many connected parts of `mesh` have at least `smallest` area (their doubled area, as
/// [`support::regions`] measures it).
fn parts_of_area(mesh: &Mesh, smallest: f64) -> usize {
    support::regions(mesh, &vec![true; mesh.triangles.len()]).1.iter().filter(|p| p.area >= smallest).count()
}

/// Moves every vertex `distance` against its normal: back from the offset the polygonisation
/// was made at onto the implicit function's zero set (near the samples it is a distance). A
/// polygonisation's vertex normals are noisy (slivers), so each normal is averaged over its
/// ring first. Only positions change, so the topology stays.
fn move_inward(mesh: &mut Mesh, distance: f32, threads: &Threads) {
    let neighbours = adjacency::Rows::neighbours(&mesh.triangles, mesh.positions.len());
    let mut normals = mesh.area_weighted_normals();
    for _ in 0..NORMAL_SMOOTHING_PASSES {
        normals = threads.run(|| {
            (0..normals.len() as u32)
                .into_par_iter()
                .map(|v| {
                    neighbours
                        .of(v)
                        .iter()
                        .fold(normals[v as usize], |sum, &w| sum + normals[w as usize])
                        .normalize_or_zero()
                })
                .collect()
        });
    }
    threads.run(|| mesh.positions.par_iter_mut().zip(&normals).for_each(|(p, n)| *p -= distance * *n));
}
