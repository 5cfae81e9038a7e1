//! Marching tetrahedra of an implicit function over a regular grid, in two ways that share the
//! grid, the vertex placement and the per-cube triangulation: densely over the whole grid
//! ([`polygonise_grid`], for generated shapes, [`crate::eval::shapes::implicit_mesh`]), and by
//! tracking the surface from seed cells ([`track_surface`], which reconstruction uses to mesh
//! its implicit function, evaluating only the cells the surface crosses).
//!
//! Every cube is split the same way (Kuhn), vertices sit on grid edges and diagonals where the
//! function changes sign, and each such vertex is shared by every tetrahedron around its edge:
//! the result is watertight and 2-manifold, with outward (counter-clockwise) triangles for a
//! function that is negative inside.

use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::progress::Threads;
use glam::Vec3;
use rayon::prelude::*;
use std::collections::{HashMap, HashSet};
use std::hash::{BuildHasherDefault, Hasher};

/// The tetrahedra of the Kuhn (Freudenthal) split of a cube: one per axis permutation, each the
/// path from corner 0 to corner 7 along the permuted axes. Corners are numbered by bits
/// (x = 1, y = 2, z = 4). Along each path the corners only gain bits, so every tet edge runs from
/// a corner to a componentwise-greater one; all cubes split their faces along the same
/// diagonals, so neighbouring cubes agree. The bool is true for an odd permutation, whose tet
/// is negatively oriented.
pub(crate) const KUHN_TETS: [([u8; 4], bool); 6] = [
    ([0, 1, 3, 7], false), // x, y, z
    ([0, 2, 6, 7], false), // y, z, x
    ([0, 4, 5, 7], false), // z, x, y
    ([0, 1, 5, 7], true),  // x, z, y
    ([0, 2, 3, 7], true),  // y, x, z
    ([0, 4, 6, 7], true),  // z, y, x
];

/// Interpolation parameters closer than this to a grid point are pushed away from it, so no
/// two vertices coincide (a value exactly 0 at a grid point counts as slightly positive).
const MIN_EDGE_FRACTION: f32 = 1e-3;

/// Where along an edge from value `fa` to value `fb` (of opposite signs) the zero lies, in
/// `(0, 1)`, kept away from the ends.
fn crossing_fraction(fa: f32, fb: f32) -> f32 {
    let t = fa / (fa - fb);
    let t = if t.is_finite() { t } else { 0.5 };
    t.clamp(MIN_EDGE_FRACTION, 1.0 - MIN_EDGE_FRACTION)
}

/// Emits the outward triangles of one cube whose corners (bits x = 1, y = 2, z = 4) are
/// `inside` or not. `vertex(lower, upper)` gives the index and position of the vertex on the
/// cube edge or diagonal from corner `lower` to corner `upper` (`lower` ⊂ `upper` as bit sets),
/// creating it on first use.
pub(crate) fn cube_triangles(
    inside: &[bool; 8],
    mut vertex: impl FnMut(u8, u8) -> (u32, Vec3),
    out: &mut Vec<[u32; 3]>,
) {
    if inside.iter().all(|&x| x == inside[0]) {
        return;
    }
    for (corners, odd_tet) in KUHN_TETS {
        tetrahedron(corners, odd_tet, inside, &mut vertex, out);
    }
}

/// Parity of a permutation of 0..4 (true when odd), by counting inversions.
fn is_odd_permutation(p: [usize; 4]) -> bool {
    let mut inversions = 0;
    for i in 0..4 {
        for j in i + 1..4 {
            if p[i] > p[j] {
                inversions += 1;
            }
        }
    }
    inversions % 2 == 1
}

/// Emits the outward triangles of one tetrahedron. `corners` are the tet's cube corners, each
/// containing the previous one; `odd_tet` is true when the tet is negatively oriented.
///
/// For a positively oriented tet (v0, v1, v2, v3), the triangle through the edges v0-v1, v0-v2,
/// v0-v3 (in that order) faces away from v0. Relabelling the tet by an odd permutation flips
/// that, so every case reduces to "write the vertices in a fixed order, flip when the
/// permutation's parity and the tet's orientation disagree".
fn tetrahedron(
    corners: [u8; 4],
    odd_tet: bool,
    inside: &[bool; 8],
    vertex: &mut impl FnMut(u8, u8) -> (u32, Vec3),
    out: &mut Vec<[u32; 3]>,
) {
    let is_in: [bool; 4] = corners.map(|c| inside[c as usize]);
    // The vertex on the edge between tet corners x and y.
    let mut edge = |x: usize, y: usize| vertex(corners[x.min(y)], corners[x.max(y)]);
    // The tet's inside corners first, then its outside ones, each in order.
    let mut order = [0usize; 4];
    let mut inside_count = 0;
    for v in (0..4).filter(|&v| is_in[v]) {
        order[inside_count] = v;
        inside_count += 1;
    }
    for (slot, v) in (inside_count..4).zip((0..4).filter(|&v| !is_in[v])) {
        order[slot] = v;
    }
    let (ins, outs) = order.split_at(inside_count);
    let orient = |mut tri: [u32; 3], flip: bool| {
        if flip {
            tri.swap(1, 2);
        }
        tri
    };
    match ins.len() {
        1 => {
            // The triangle must face away from the single inside corner.
            let (i, o) = (ins[0], outs);
            let flip = odd_tet ^ is_odd_permutation([i, o[0], o[1], o[2]]);
            out.push(orient([edge(i, o[0]).0, edge(i, o[1]).0, edge(i, o[2]).0], flip));
        }
        3 => {
            // The triangle must face towards the single outside corner.
            let (o, i) = (outs[0], ins);
            let flip = !(odd_tet ^ is_odd_permutation([o, i[0], i[1], i[2]]));
            out.push(orient([edge(o, i[0]).0, edge(o, i[1]).0, edge(o, i[2]).0], flip));
        }
        2 => {
            // For a positive tet and an even (i, j, k, l) the quad ik, il, jl, jk faces the
            // outside pair k, l.
            let (i, j, k, l) = (ins[0], ins[1], outs[0], outs[1]);
            let mut quad = [edge(i, k), edge(i, l), edge(j, l), edge(j, k)];
            if odd_tet ^ is_odd_permutation([i, j, k, l]) {
                quad.reverse();
            }
            // Split along the shorter diagonal for better-shaped triangles.
            let (v, p) = (quad.map(|q| q.0), quad.map(|q| q.1));
            if p[0].distance_squared(p[2]) <= p[1].distance_squared(p[3]) {
                out.extend([[v[0], v[1], v[2]], [v[0], v[2], v[3]]]);
            } else {
                out.extend([[v[1], v[2], v[3]], [v[1], v[3], v[0]]]);
            }
        }
        _ => {}
    }
}

/// A regular grid: point `(i, j, k)` is at `origin + cell * (i, j, k)` for `i < dims[0]`, etc.
/// Cell `(i, j, k)` is the cube whose lowest corner is point `(i, j, k)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Grid {
    pub origin: Vec3,
    pub cell: f32,
    pub dims: [u32; 3],
}

/// Grid coordinates fit in 21 bits each, so a point or cell packs into one `u64` key.
pub(crate) const MAX_GRID_POINTS_PER_AXIS: u32 = 1 << 21;

impl Grid {
    fn key(i: u32, j: u32, k: u32) -> u64 {
        u64::from(i) | u64::from(j) << 21 | u64::from(k) << 42
    }

    fn unkey(key: u64) -> [u32; 3] {
        let mask = (1 << 21) - 1;
        [(key & mask) as u32, (key >> 21 & mask) as u32, (key >> 42) as u32]
    }

    fn point(&self, [i, j, k]: [u32; 3]) -> Vec3 {
        self.origin + self.cell * Vec3::new(i as f32, j as f32, k as f32)
    }

    /// The vertex on the grid edge or diagonal from point `a` to point `b`, whose values `fa` and
    /// `fb` have opposite signs.
    fn crossing(&self, a: [u32; 3], b: [u32; 3], fa: f32, fb: f32) -> Vec3 {
        let t = crossing_fraction(fa, fb);
        let (pa, pb) = (self.point(a), self.point(b));
        pa + (pb - pa) * t
    }

    fn on_border(&self, [i, j, k]: [u32; 3]) -> bool {
        i == 0 || j == 0 || k == 0 || i + 1 >= self.dims[0] || j + 1 >= self.dims[1] || k + 1 >= self.dims[2]
    }

    /// The cell containing `p` (clamped into the grid).
    pub fn cell_of(&self, p: Vec3) -> [u32; 3] {
        let q = ((p - self.origin) / self.cell).floor();
        [0, 1, 2].map(|a| (q[a].max(0.0) as u32).min(self.dims[a].saturating_sub(2)))
    }
}

/// Values, crossing edges and vertex numbers at every point of a grid, for [`polygonise_grid`].
#[cfg(any(test, feature = "eval"))]
struct Sampled {
    /// Points per axis.
    dims: [usize; 3],
    /// `f` at every point, x fastest.
    values: Vec<f32>,
    /// Bit `d - 1` set when the edge from this point to the point offset by corner `d`
    /// (bits x = 1, y = 2, z = 4) crosses the surface.
    crossings: Vec<u8>,
    /// Index of the vertex on this point's first crossing edge.
    first_vertex: Vec<u32>,
}

#[cfg(any(test, feature = "eval"))]
impl Sampled {
    fn point_index(&self, i: usize, j: usize, k: usize) -> usize {
        i + self.dims[0] * (j + self.dims[1] * k)
    }

    /// Index offset of corner `c` (bits x = 1, y = 2, z = 4) from corner 0.
    fn corner_offset(&self, c: u8) -> usize {
        self.point_index(usize::from(c & 1), usize::from((c >> 1) & 1), usize::from((c >> 2) & 1))
    }

    /// Vertex on the crossing edge from point `p` to the point offset by corner `d` (d > 0).
    fn vertex(&self, p: usize, d: u8) -> u32 {
        let below = (1u8 << (d - 1)) - 1;
        self.first_vertex[p] + (self.crossings[p] & below).count_ones()
    }
}

/// Polygonises the zero set of `f` (negative inside) over the whole of `grid`, evaluating `f`
/// at every point: every component is found without seeds, and where the surface leaves the
/// grid it has a boundary. NaN counts as outside (the largest positive value), and so does 0.
/// Vertices are numbered by grid point (x fastest) and then by the corner their edge goes to;
/// triangles come cell by cell in the same order.
///
/// Evaluation and triangulation run in parallel over z-slabs; the output is the same for any
/// number of threads. A grid with fewer than 2 points along an axis gives an empty mesh.
#[cfg(any(test, feature = "eval"))]
pub(crate) fn polygonise_grid(f: impl Fn(Vec3) -> f32 + Sync, grid: &Grid) -> Mesh {
    if grid.dims.iter().any(|&d| d < 2) {
        return Mesh::default();
    }
    let dims = grid.dims.map(|d| d as usize);
    let at = |i: usize, j: usize, k: usize| [i as u32, j as u32, k as u32];
    let plane = dims[0] * dims[1];
    let mut sampled = Sampled {
        dims,
        values: vec![0.0; plane * dims[2]],
        crossings: vec![0; plane * dims[2]],
        first_vertex: vec![0; plane * dims[2]],
    };

    // 1. Sample f; NaN becomes the largest positive value (outside).
    let values: Vec<Vec<f32>> = (0..dims[2])
        .into_par_iter()
        .map(|k| {
            let mut out = Vec::with_capacity(plane);
            for j in 0..dims[1] {
                for i in 0..dims[0] {
                    let v = f(grid.point(at(i, j, k)));
                    out.push(if v.is_nan() { f32::MAX } else { v });
                }
            }
            out
        })
        .collect();
    for (k, slab) in values.into_iter().enumerate() {
        sampled.values[k * plane..(k + 1) * plane].copy_from_slice(&slab);
    }

    // 2. Per plane of points: crossing edges, plane-local vertex numbers and vertex positions.
    let sampled_ref = &sampled;
    let planes: Vec<(Vec<u8>, Vec<u32>, Vec<Vec3>)> = (0..dims[2])
        .into_par_iter()
        .map(|k| {
            let mut crossings = Vec::with_capacity(plane);
            let mut first = Vec::with_capacity(plane);
            let mut positions = Vec::new();
            for j in 0..dims[1] {
                for i in 0..dims[0] {
                    let fp = sampled_ref.values[sampled_ref.point_index(i, j, k)];
                    let mut bits = 0u8;
                    first.push(positions.len() as u32);
                    for d in 1u8..8 {
                        let (di, dj, dk) = (usize::from(d & 1), usize::from((d >> 1) & 1), usize::from((d >> 2) & 1));
                        if i + di >= dims[0] || j + dj >= dims[1] || k + dk >= dims[2] {
                            continue;
                        }
                        let fq = sampled_ref.values[sampled_ref.point_index(i + di, j + dj, k + dk)];
                        if (fp < 0.0) == (fq < 0.0) {
                            continue;
                        }
                        bits |= 1 << (d - 1);
                        positions.push(grid.crossing(at(i, j, k), at(i + di, j + dj, k + dk), fp, fq));
                    }
                    crossings.push(bits);
                }
            }
            (crossings, first, positions)
        })
        .collect();
    let mut positions = Vec::with_capacity(planes.iter().map(|p| p.2.len()).sum());
    for (k, (crossings, first, plane_positions)) in planes.into_iter().enumerate() {
        let offset = positions.len() as u32;
        sampled.crossings[k * plane..(k + 1) * plane].copy_from_slice(&crossings);
        for (dst, src) in sampled.first_vertex[k * plane..(k + 1) * plane].iter_mut().zip(first) {
            *dst = src + offset;
        }
        positions.extend(plane_positions);
    }

    // 3. Triangles, per slab of cells, concatenated in slab order.
    let sampled = &sampled;
    let positions_ref = &positions;
    let slabs: Vec<Vec<[u32; 3]>> = (0..dims[2] - 1)
        .into_par_iter()
        .map(|k| {
            let mut triangles = Vec::new();
            for j in 0..dims[1] - 1 {
                for i in 0..dims[0] - 1 {
                    let base = sampled.point_index(i, j, k);
                    let inside: [bool; 8] =
                        std::array::from_fn(|c| sampled.values[base + sampled.corner_offset(c as u8)] < 0.0);
                    cube_triangles(
                        &inside,
                        |lower, upper| {
                            let v = sampled.vertex(base + sampled.corner_offset(lower), upper ^ lower);
                            (v, positions_ref[v as usize])
                        },
                        &mut triangles,
                    );
                }
            }
            triangles
        })
        .collect();
    Mesh::new(positions, None, slabs.concat())
}

/// A fast hasher for the packed grid keys (multiplicative, like FxHash, rotated at the end).
#[derive(Default)]
pub(crate) struct KeyHasher(u64);

impl Hasher for KeyHasher {
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(u64::from(b));
        }
    }
    fn write_u8(&mut self, x: u8) {
        self.write_u64(u64::from(x));
    }
    fn write_u64(&mut self, x: u64) {
        self.0 = (self.0.rotate_left(5) ^ x).wrapping_mul(0x517c_c1b7_2722_0a95);
    }
    fn finish(&self) -> u64 {
        // A product's low bits depend only on the factors' low bits: unrotated, the table's
        // bucket (the low bits) would come from the x coordinate alone and every key with the
        // same x would share one probe sequence. The rotation brings the well-mixed middle
        // bits down.
        self.0.rotate_left(26)
    }
}

pub(crate) type FastMap<K, V> = HashMap<K, V, BuildHasherDefault<KeyHasher>>;
type FastSet<K> = HashSet<K, BuildHasherDefault<KeyHasher>>;

/// The six faces of a cube: the axis bit, and whether it is the face where that bit is set.
const FACES: [(u8, bool); 6] = [(1, false), (1, true), (2, false), (2, true), (4, false), (4, true)];

/// The grid point at corner `c` (bits x = 1, y = 2, z = 4) of `cell`.
fn corner(cell: [u32; 3], c: u8) -> [u32; 3] {
    [cell[0] + u32::from(c & 1), cell[1] + u32::from(c >> 1 & 1), cell[2] + u32::from(c >> 2 & 1)]
}

/// Cells per parallel task when triangulating one wave of the surface tracking.
const WAVE_CHUNK: usize = 2048;

/// The triangles of a run of cells, with vertices local to the run: `edges[v]` is vertex v's
/// grid edge (its lower point's key and the corner bits it spans) and position. Vertices on
/// the same edge are merged when the runs are put together.
#[derive(Default)]
struct WaveChunk {
    edges: Vec<((u64, u8), Vec3)>,
    triangles: Vec<[u32; 3]>,
    /// Cells that share a face crossing the surface with one of the run's cells.
    neighbours: Vec<u64>,
}

/// Triangulates `cells` (every corner already in `values`) and lists where the surface goes on.
fn triangulate_cells(cells: &[u64], grid: &Grid, values: &FastMap<u64, f32>) -> WaveChunk {
    let mut out = WaveChunk::default();
    for &c in cells {
        let cell = Grid::unkey(c);
        let corner_values: [f32; 8] = std::array::from_fn(|k| {
            let [i, j, l] = corner(cell, k as u8);
            values[&Grid::key(i, j, l)]
        });
        if corner_values.iter().any(|v| v.is_nan()) {
            continue;
        }
        let inside = corner_values.map(|v| v < 0.0);
        let inside_bits = (0..8).filter(|&k| inside[k]).fold(0u8, |bits, k| bits | 1 << k);
        if inside_bits == 0 || inside_bits == u8::MAX {
            continue;
        }
        let edges = &mut out.edges;
        cube_triangles(
            &inside,
            |lower, upper| {
                let (a, b) = (corner(cell, lower), corner(cell, upper));
                let p = grid.crossing(a, b, corner_values[lower as usize], corner_values[upper as usize]);
                edges.push(((Grid::key(a[0], a[1], a[2]), upper ^ lower), p));
                ((edges.len() - 1) as u32, p)
            },
            &mut out.triangles,
        );
        for (bit, upper) in FACES {
            // The face's four corners, as a bit set over the cube's eight.
            let face = (0..8u8).filter(|k| (k & bit != 0) == upper).fold(0u8, |bits, k| bits | 1 << k);
            let face_inside = inside_bits & face;
            if face_inside == 0 || face_inside == face {
                continue;
            }
            let axis = bit.trailing_zeros() as usize;
            let mut n = cell;
            if upper {
                n[axis] += 1;
            } else if n[axis] == 0 {
                continue;
            } else {
                n[axis] -= 1;
            }
            out.neighbours.push(Grid::key(n[0], n[1], n[2]));
        }
    }
    out
}

/// Polygonises the part of the zero set of `f` (negative inside) that passes through the
/// `seeds` cells, by surface tracking (Bloomenthal 1994): a cell is visited when it shares a
/// face whose corners change sign with a visited cell that crosses the surface. Only the cells
/// along the surface are ever evaluated, so the cost follows the surface's area, not the
/// grid's volume. Points on the grid's outer layer count as outside, so the surface is closed
/// there. Where `f` is NaN it is undefined: a cell with an undefined corner is neither
/// triangulated nor crossed (the surface gets a boundary there).
/// `f` is evaluated in parallel, one wave of cells at a time; the output is deterministic.
/// More than `max_cells` visited cells is refused with [`Error::TooLarge`].
pub(crate) fn track_surface(
    f: &(dyn Fn(Vec3) -> f32 + Sync),
    grid: &Grid,
    seeds: &[[u32; 3]],
    max_cells: usize,
    threads: &Threads,
) -> Result<Mesh> {
    let cells_per_axis = grid.dims.map(|d| d.saturating_sub(1));
    let mut visited: FastSet<u64> = FastSet::default();
    let mut frontier: Vec<u64> = seeds
        .iter()
        .filter(|c| (0..3).all(|a| c[a] < cells_per_axis[a]))
        .map(|c| Grid::key(c[0], c[1], c[2]))
        .collect();
    frontier.sort_unstable();
    frontier.dedup();
    visited.extend(frontier.iter().copied());

    let mut values: FastMap<u64, f32> = FastMap::default();
    let mut vertices: FastMap<(u64, u8), u32> = FastMap::default();
    let mut positions: Vec<Vec3> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();

    while !frontier.is_empty() {
        if visited.len() > max_cells {
            return Err(Error::TooLarge(format!("the surface crosses more than {max_cells} grid cells")));
        }
        // Evaluate the corners not seen yet, in parallel.
        let computed: Vec<(u64, f32)> = threads.run(|| {
            let mut needed: Vec<u64> = frontier
                .par_iter()
                .flat_map_iter(|&c| {
                    let cell = Grid::unkey(c);
                    (0..8u8).map(move |k| {
                        let [i, j, l] = corner(cell, k);
                        Grid::key(i, j, l)
                    })
                })
                .filter(|p| !values.contains_key(p))
                .collect();
            needed.par_sort_unstable();
            needed.dedup();
            needed
                .into_par_iter()
                .map(|p| {
                    let ijk = Grid::unkey(p);
                    (p, if grid.on_border(ijk) { f32::MAX } else { f(grid.point(ijk)) })
                })
                .collect()
        });
        values.extend(computed);

        // Triangulate the wave's cells in parallel, in chunks whose results are then merged in
        // order: the output does not depend on the number of threads.
        let chunks: Vec<WaveChunk> = threads
            .run(|| frontier.par_chunks(WAVE_CHUNK).map(|cells| triangulate_cells(cells, grid, &values)).collect());
        let mut next = Vec::new();
        for chunk in chunks {
            let global: Vec<u32> = chunk
                .edges
                .iter()
                .map(|&(key, p)| {
                    *vertices.entry(key).or_insert_with(|| {
                        positions.push(p);
                        (positions.len() - 1) as u32
                    })
                })
                .collect();
            triangles.extend(chunk.triangles.iter().map(|t| t.map(|v| global[v as usize])));
            for n in chunk.neighbours {
                let [i, j, l] = Grid::unkey(n);
                if i < cells_per_axis[0] && j < cells_per_axis[1] && l < cells_per_axis[2] && visited.insert(n) {
                    next.push(n);
                }
            }
        }
        next.sort_unstable();
        frontier = next;
    }
    if positions.len() >= u32::MAX as usize {
        return Err(Error::TooLarge("more than 2^32 vertices".into()));
    }
    Ok(Mesh::new(positions, None, triangles))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::figures::signed_volume;
    use crate::topology::analyze;

    #[test]
    fn kuhn_tets_are_paths_with_the_stated_orientation() {
        for (corners, odd) in KUHN_TETS {
            assert_eq!((corners[0], corners[3]), (0, 7));
            for w in corners.windows(2) {
                assert_eq!((w[1] & w[0]), w[0], "{corners:?} is not monotone");
                assert_eq!((w[1] ^ w[0]).count_ones(), 1);
            }
            let v = corners.map(|c| Vec3::new(f32::from(c & 1), f32::from((c >> 1) & 1), f32::from((c >> 2) & 1)));
            let det = (v[1] - v[0]).dot((v[2] - v[0]).cross(v[3] - v[0]));
            assert_eq!(det < 0.0, odd, "{corners:?}");
        }
    }

    fn torus(p: Vec3) -> f32 {
        let q = glam::Vec2::new(glam::Vec2::new(p.x, p.y).length() - 1.0, p.z);
        q.length() - 0.35
    }

    #[test]
    fn tracking_from_one_seed_finds_the_whole_closed_surface() {
        let grid = Grid { origin: Vec3::splat(-1.6), cell: 0.05, dims: [65, 65, 65] };
        // One seed cell on the torus' outer equator.
        let seed = grid.cell_of(Vec3::new(1.33, 0.01, 0.01));
        let mesh = track_surface(&torus, &grid, &[seed], 1 << 20, &Threads::new(0).unwrap()).unwrap();
        let report = analyze(&mesh);
        assert!(report.is_watertight(), "{report:?}");
        assert_eq!(report.genus(), Some(1));
        assert_eq!(report.components, 1);
        let volume = signed_volume(&mesh);
        let exact = 2.0 * std::f64::consts::PI.powi(2) * 1.0 * 0.35f64.powi(2);
        assert!((volume / exact - 1.0).abs() < 0.02, "volume {volume} vs {exact}");
        // Same mesh as the dense polygoniser on the same grid.
        let dense = crate::eval::shapes::implicit_mesh(torus, grid.origin, grid.origin + grid.cell * 64.0, 64);
        assert_eq!(dense.triangles.len(), mesh.triangles.len());
    }

    #[test]
    fn a_surface_leaving_the_grid_is_closed_at_its_border_and_seeds_outside_are_ignored() {
        let grid = Grid { origin: Vec3::splat(-1.0), cell: 0.1, dims: [21, 21, 21] };
        let plane = |p: Vec3| p.z;
        let mesh =
            track_surface(&plane, &grid, &[[10, 10, 9], [99, 0, 0]], 1 << 20, &Threads::new(1).unwrap()).unwrap();
        assert!(analyze(&mesh).is_watertight());
        let too_small = track_surface(&plane, &grid, &[[10, 10, 9]], 10, &Threads::new(1).unwrap());
        assert!(matches!(too_small, Err(Error::TooLarge(_))));
    }
}
