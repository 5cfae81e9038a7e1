//! Thin parts made whole: where a polygonisation of the base mesh's implicit function has
//! handles or several parts, it is made again a little outside the zero set (near the samples
//! of parts thinner than the cells resolve, and everywhere), its vertices moved back onto the
//! samples, and kept if it has fewer parts, or as many and fewer handles, without surface the
//! samples do not support.

use super::{adjacency, support};
use crate::mesh::Mesh;
use crate::progress::Threads;
use crate::spatial::KdTree;
use crate::topology;
use crate::tree::TreeSample;
use glam::Vec3;
use rayon::prelude::*;

/// The offset, in polygonisation cells (the grid's cell, or the finest leaf the octree may
/// have). The winding number, softened over a sample spacing, sinks below one half inside a
/// part thinner than about a cell, and the cell's corners see such a part on one side only: a
/// plate thinner than a cell, or an ear where overlapping scans disagree by about a cell, comes
/// out perforated, with spurious handles (on the grid) or in pieces (over the octree, whose
/// cells are larger). Offset, the part is thick enough to be seen; moving the vertices back
/// puts the surface where the samples are and cannot change the topology. A single part
/// without handles is never thickened. Pinned by the test
/// `a_plate_thinner_than_the_grid_keeps_its_four_holes` (tests/reconstruct.rs).
pub(super) const THICKEN_CELLS: f32 = 1.5;

/// A sample lies on a thin part when a sample behind it, with a normal turned against its own
/// (cosine below `OPPOSED`), lies within this many cells: the other side of a plate thinner
/// than twice the offset, which is what the offset surface joins. A gap between sheets facing
/// each other (a bolt hole a few samples across) is no thin part: offset near thin parts only,
/// it stays open, where offsetting the whole surface closes it (turbine at 200k points keeps
/// its 11; offset everywhere, it has 1). Pinned by
/// `a_plates_sides_are_thin_a_bores_wall_is_not`.
const THIN_CELLS: f32 = 2.0 * THICKEN_CELLS;
/// Thin parts are judged on one sample per box of this many cells (see [`one_per_box`]), a
/// third of the reach within which the offset is whole (`THIN_REACH` offsets).
const SPREAD_CELLS: f32 = 1.0;
/// Opposed normals: over 120 degrees apart, as the two sides of a plate; a curved or noisy
/// sheet's neighbours turn by less.
const OPPOSED: f32 = -0.5;
/// The offset is whole within this many offsets of a thin part's samples (the offset surface
/// lies one offset out, a perforation's rim a little farther) and fades to none over one more.
const THIN_REACH: f32 = 2.0;

/// The offset surface, moved back, may leave at most this share of its area more unsupported
/// than the plain one: a cap over a real hole has no sample under it facing its way, where a
/// mended perforation lies on the plate's samples. Measured on the corpus at 200k points: caps
/// over real holes added 0.25% to 3.5% (turbine's bolt holes offset everywhere, couplingdown's
/// holes and refined_elephant's handles with noise); mended perforations -0.3% to 0.02%
/// (rotor_small, homer, man, camel). Pinned by
/// `a_thickened_surface_that_caps_a_hole_without_samples_is_refused`.
const UNSUPPORTED_ADDED: f64 = 0.001;
/// Unless the plain surface lost what the samples hold: an offset surface with this many
/// times its supported area is kept however much it adds unsupported (a ratio of areas). A
/// plate perforated into pieces, or an open scan's sheet polygonised as a closed surface into
/// a sliver, leaves most of the samples without surface; the offset surface brings them back
/// with its rims and (on an open scan) its closure, which trimming removes later. Measured:
/// 3.5 on the perforated plate, 16 on a dome of 10,000 points; at most 1.12 on the corpus at
/// 200k points. Pinned by `a_plate_thinner_than_the_grid_keeps_its_four_holes` and the dome of
/// `normals_that_all_point_inward_are_turned_out_for_a_closed_surface` (tests/reconstruct.rs).
const LOST_SURFACE: f64 = 1.5;
/// Support is judged within this many cells of a point (the reach the octree's chords and
/// the grid's diagonals need, see [`support::SUPPORT_REACH`]), at points this far apart.
const SUPPORT_CELLS: f32 = 2.0;

/// Ring averages of the mesh's normals before its vertices are moved back.
const NORMAL_SMOOTHING_PASSES: usize = 2;

/// `plain` (the zero set, with what came with it), or where it has handles, or with
/// `smallest` given several parts of at least that area (smaller ones are dropped later), the
/// zero set lifted outside by `THICKEN_CELLS * cell`, near thin parts of `samples` (indexed by
/// `index`) or everywhere, made by `at_offset` from the lift at each point and moved back: the
/// first with fewer such parts, or as many and fewer handles, that the samples support
/// (see [`supported_enough`]); and whether it was thickened. Both are tried because neither
/// mends every perforation: offset where thin keeps the narrow holes that offset everywhere
/// closes, but sees no thin part where the field perforates a single sheet (an open scan's
/// rim, a ring whose T-nodes' planes flatten it). (The grid's cells are small
/// enough that a thin part only ever perforates there: it counts handles only.)
pub(super) fn where_handles<X>(
    plain: (Mesh, X),
    at_offset: impl Fn(&(dyn Fn(Vec3) -> f32 + Sync)) -> Option<(Mesh, X)>,
    (samples, index, normals): (&[TreeSample], &KdTree, &[Vec3]),
    cell: f32,
    smallest: Option<f64>,
    threads: &Threads,
) -> ((Mesh, X), bool) {
    let parts_of = |mesh: &Mesh| smallest.map_or(1, |smallest| parts_of_area(mesh, smallest));
    let handles = |mesh: &Mesh| (parts_of(mesh), topology::closed_surface_parts_and_genus(mesh).1);
    let plain_handles = handles(&plain.0);
    if plain_handles.0 <= 1 && plain_handles.1 == 0 {
        return (plain, false);
    }
    let support = |mesh: &Mesh| Support::of(mesh, index, normals, SUPPORT_CELLS * cell, threads);
    let plain_support = std::cell::OnceCell::new();
    let offset = THICKEN_CELLS * cell;
    let thickened = |lift: &(dyn Fn(Vec3) -> f32 + Sync)| {
        let (mut thick, x) = at_offset(lift).filter(|(thick, _)| !thick.triangles.is_empty())?;
        let thick_handles = handles(&thick);
        if thick_handles >= plain_handles {
            return None;
        }
        move_inward(&mut thick, lift, threads);
        let thick_support = support(&thick);
        supported_enough(plain_support.get_or_init(|| support(&plain.0)), &thick_support).then_some((thick, x))
    };
    // Offset where thin first: it moves less of the surface.
    let where_thin =
        ThinParts::new(samples, cell, threads).and_then(|thin| thickened(&|p: Vec3| offset * thin.weight(p, offset)));
    match where_thin.or_else(|| thickened(&|_| offset)) {
        Some(thick) => (thick, true),
        None => (plain, false),
    }
}

/// Whether the offset surface, moved back, adds no more unsupported area than
/// `UNSUPPORTED_ADDED` of its area, or brings back surface the plain one lost (`LOST_SURFACE`).
fn supported_enough(plain: &Support, thick: &Support) -> bool {
    thick.unsupported - plain.unsupported <= UNSUPPORTED_ADDED * thick.area()
        || thick.supported >= LOST_SURFACE * plain.supported
}

/// The samples of parts thinner than `THIN_CELLS`, indexed.
struct ThinParts {
    index: KdTree,
}

impl ThinParts {
    /// `None` when no sample lies on a thin part. Judged on one sample per `SPREAD_CELLS` box
    /// and normal's direction (of the six an axis has): thin parts are regions, and a noisy
    /// cloud holds hundreds of samples within `THIN_CELLS` of each (it took 0.7 s of a 1 s
    /// call on 200k points).
    fn new(samples: &[TreeSample], cell: f32, threads: &Threads) -> Option<ThinParts> {
        let spread = one_per_box(samples, SPREAD_CELLS * cell, threads);
        let positions: Vec<Vec3> = spread.iter().map(|s| s.position).collect();
        let index = KdTree::new(&positions).ok()?;
        let radius = THIN_CELLS * cell;
        let thin: Vec<Vec3> = threads.run(|| {
            spread
                .par_iter()
                .filter(|s| {
                    index.any_within_among(s.position, radius, |i| {
                        let q = spread[i as usize];
                        q.normal.dot(s.normal) < OPPOSED && (q.position - s.position).dot(s.normal) < 0.0
                    })
                })
                .map(|s| s.position)
                .collect()
        });
        (!thin.is_empty()).then(|| KdTree::new(&thin).ok()).flatten().map(|index| ThinParts { index })
    }

    /// How much of the offset applies at `p`: 1 within `THIN_REACH` offsets of a thin part's
    /// sample, falling to 0 one offset farther.
    fn weight(&self, p: Vec3, offset: f32) -> f32 {
        let d = self.index.distance_within(p, (THIN_REACH + 1.0) * offset);
        if d.is_finite() {
            (THIN_REACH + 1.0 - d / offset).clamp(0.0, 1.0)
        } else {
            0.0
        }
    }
}

/// The area of a mesh that samples support and that they do not ([`support::supported_faces`]).
#[derive(Debug)]
struct Support {
    supported: f64,
    unsupported: f64,
}

impl Support {
    /// Judged within `reach` of the samples (`index`, with their `normals`), at points `reach`
    /// apart.
    fn of(mesh: &Mesh, index: &KdTree, normals: &[Vec3], reach: f32, threads: &Threads) -> Support {
        let across = |f: usize| support::points_across(mesh, f, reach);
        let shares = support::supported_faces(mesh, index, normals, |_| reach, across, threads);
        let mut area = Support { supported: 0.0, unsupported: 0.0 };
        for (t, &(_, unsupported)) in mesh.triangles.iter().zip(&shares) {
            let [a, b, c] = t.map(|v| mesh.positions[v as usize]);
            let face = 0.5 * f64::from((b - a).cross(c - a).length());
            area.unsupported += face * f64::from(unsupported);
            area.supported += face * f64::from(1.0 - unsupported);
        }
        area
    }

    fn area(&self) -> f64 {
        self.supported + self.unsupported
    }
}

/// The first of `samples` in each box of side `side` whose normals point most along the same
/// axis, the same way: both sides of a plate thinner than a box are kept.
fn one_per_box<'a>(samples: &'a [TreeSample], side: f32, threads: &Threads) -> Vec<&'a TreeSample> {
    let key = |s: &TreeSample| {
        let n = s.normal;
        let axis = n.abs().max_position();
        let direction = 2 * axis as i32 + i32::from(n[axis] < 0.0);
        let b = (s.position / side).floor().as_ivec3();
        [b.x, b.y, b.z, direction]
    };
    threads.run(|| {
        let mut keyed: Vec<([i32; 4], u32)> = samples.par_iter().enumerate().map(|(i, s)| (key(s), i as u32)).collect();
        keyed.par_sort_unstable();
        keyed.dedup_by_key(|(k, _)| *k);
        keyed.iter().map(|&(_, i)| &samples[i as usize]).collect()
    })
}

/// How many connected parts of `mesh` have at least `smallest` area (their doubled area, as
/// [`support::regions`] measures it).
fn parts_of_area(mesh: &Mesh, smallest: f64) -> usize {
    support::regions(mesh, &vec![true; mesh.triangles.len()]).1.iter().filter(|p| p.area >= smallest).count()
}

/// Moves every vertex `lift` (at it) against its normal: back from the offset the
/// polygonisation was made at onto the implicit function's zero set (near the samples it is a
/// distance). A polygonisation's vertex normals are noisy (slivers), so each normal is
/// averaged over its ring first. Only positions change, so the topology stays.
fn move_inward(mesh: &mut Mesh, lift: &(dyn Fn(Vec3) -> f32 + Sync), threads: &Threads) {
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
    threads.run(|| mesh.positions.par_iter_mut().zip(&normals).for_each(|(p, n)| *p -= lift(*p) * *n));
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::shapes::{icosphere, torus};

    /// A torus of tube radius 0.3 sampled at its vertices: with cells of 0.25 its tube is a
    /// thin part (the far side lies 0.6 behind, within `THIN_CELLS`).
    fn sampled_torus() -> (Vec<TreeSample>, KdTree, Vec<Vec3>) {
        let mesh = torus(1.0, 0.3, 96, 32);
        let normals = mesh.normals.as_ref().unwrap();
        let samples: Vec<TreeSample> = (0..mesh.positions.len())
            .map(|i| TreeSample { position: mesh.positions[i], normal: normals[i], index: i as u32 })
            .collect();
        let index = KdTree::new(&mesh.positions).unwrap();
        (samples, index, normals.clone())
    }

    /// `a` and `b` as one mesh.
    fn both(a: Mesh, b: &Mesh) -> Mesh {
        let first = a.positions.len() as u32;
        let positions = a.positions.iter().chain(&b.positions).copied().collect();
        let triangles = a.triangles.iter().copied().chain(b.triangles.iter().map(|t| t.map(|v| v + first))).collect();
        Mesh::new(positions, None, triangles)
    }

    const CELL: f32 = 0.25;

    #[test]
    fn a_plates_sides_are_thin_a_bores_wall_is_not() {
        // A plate 0.2 thick (under twice the offset): each side has the other behind it, facing
        // away. A bore 0.4 across through a solid: its wall's samples face each other across
        // the bore, in front of one another.
        let mut samples = Vec::new();
        for i in 0..40 {
            for j in 0..40 {
                let (x, y) = (i as f32 * 0.05, j as f32 * 0.05);
                for side in [-1.0, 1.0] {
                    let (position, normal) = (Vec3::new(x, y, 0.1 * side), Vec3::new(0.0, 0.0, side));
                    samples.push(TreeSample { position, normal, index: samples.len() as u32 });
                }
                let angle = std::f32::consts::TAU * i as f32 / 40.0;
                let radial = Vec3::new(angle.cos(), angle.sin(), 0.0);
                let position = Vec3::new(5.0, 0.0, y) + 0.2 * radial;
                samples.push(TreeSample { position, normal: -radial, index: samples.len() as u32 });
            }
        }
        let threads = Threads::new(1).unwrap();
        let thin = ThinParts::new(&samples, CELL, &threads).unwrap();
        let offset = THICKEN_CELLS * CELL;
        assert_eq!(thin.weight(Vec3::new(1.0, 1.0, 0.1 + offset), offset), 1.0);
        assert_eq!(thin.weight(Vec3::new(5.0, 0.0, 1.0), offset), 0.0);
    }

    #[test]
    fn a_thickened_surface_that_caps_a_hole_without_samples_is_refused() {
        // The offset surface has no handle, but its cap over the torus' hole (and all of the
        // sphere) lies far from every sample.
        let (samples, index, normals) = sampled_torus();
        let threads = Threads::new(1).unwrap();
        let plain = torus(1.0, 0.3, 96, 32);
        let ((kept, ()), thickened) = where_handles(
            (plain, ()),
            |_| Some((icosphere(1.4, 4), ())),
            (&samples, &index, &normals),
            CELL,
            None,
            &threads,
        );
        assert!(!thickened);
        assert_eq!(topology::closed_surface_parts_and_genus(&kept).1, 1);
    }

    #[test]
    fn a_thickened_surface_with_fewer_handles_on_the_samples_is_kept_and_moved_back() {
        // The plain surface has a spurious second handle away from the samples; the offset
        // surface is the torus one offset out, which moved back lies on the samples.
        let (samples, index, normals) = sampled_torus();
        let threads = Threads::new(1).unwrap();
        let mut far = torus(0.1, 0.03, 16, 8);
        far.positions.iter_mut().for_each(|p| *p += Vec3::new(0.0, 0.0, 3.0));
        let plain = both(torus(1.0, 0.3, 96, 32), &far);
        let offset = THICKEN_CELLS * CELL;
        let at_offset = |lift: &(dyn Fn(Vec3) -> f32 + Sync)| {
            // The lift is whole near the tube's samples.
            assert!((lift(Vec3::new(1.0, 0.0, 0.3 + offset)) - offset).abs() < 1e-6);
            Some((torus(1.0, 0.3 + offset, 96, 32), ()))
        };
        let ((kept, ()), thickened) =
            where_handles((plain, ()), at_offset, (&samples, &index, &normals), CELL, None, &threads);
        assert!(thickened);
        assert_eq!(topology::closed_surface_parts_and_genus(&kept), (1, 1));
        let off = kept.positions.iter().map(|p| (index.distance_within(*p, 1.0)).min(1.0)).fold(0.0f32, f32::max);
        assert!(off < 0.05, "a vertex {off} from the samples");
    }
}
