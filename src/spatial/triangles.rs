//! Closest points on triangles: the exact point-triangle distance, and [`TriangleBvh`] over a
//! mesh's triangles for closest-point queries.

use super::bvh::Bvh;
use crate::mesh::Mesh;
use glam::Vec3;
use rayon::prelude::*;

/// The point of triangle (a, b, c) closest to `p`.
///
/// Ericson's region method (Real-Time Collision Detection, 5.1.5): the signs of a few dot
/// products tell which Voronoi region of the triangle (a vertex, an edge, or the face) contains
/// `p`, and only that feature's projection is computed. Degenerate triangles (zero area, or so
/// thin that the face formula is unstable) are handled as their three edges.
pub fn closest_point_on_triangle(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> Vec3 {
    let ab = b - a;
    let ac = c - a;
    let normal = ab.cross(ac);
    if normal.length_squared() <= f32::EPSILON * f32::EPSILON * ab.length_squared() * ac.length_squared() {
        return closest_point_on_edges(p, a, b, c);
    }
    let ap = p - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return a; // vertex region a
    }
    let bp = p - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= 0.0 && d4 <= d3 {
        return b; // vertex region b
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3)); // edge region ab
    }
    let cp = p - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return c; // vertex region c
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6)); // edge region ac
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return b + (c - b) * w; // edge region bc
    }
    // Face region: barycentric coordinates from the three sub-areas.
    let inverse = 1.0 / (va + vb + vc);
    let q = a + ab * (vb * inverse) + ac * (vc * inverse);
    if q.is_finite() {
        q
    } else {
        closest_point_on_edges(p, a, b, c)
    }
}

/// The point of segment [a, b] closest to `p` (a when the segment is a point).
fn closest_point_on_segment(p: Vec3, a: Vec3, b: Vec3) -> Vec3 {
    let ab = b - a;
    let length_squared = ab.length_squared();
    if length_squared <= 0.0 || length_squared.is_nan() {
        return a;
    }
    a + ab * ((p - a).dot(ab) / length_squared).clamp(0.0, 1.0)
}

/// The closest point on the three edges of a (degenerate) triangle.
fn closest_point_on_edges(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> Vec3 {
    [closest_point_on_segment(p, a, b), closest_point_on_segment(p, b, c), closest_point_on_segment(p, c, a)]
        .into_iter()
        .min_by(|x, y| x.distance_squared(p).total_cmp(&y.distance_squared(p)))
        .unwrap_or(a)
}

/// The closest point of a triangle set to a query, as found by [`TriangleBvh::closest_point`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Closest {
    /// Euclidean distance from the query to `point`.
    pub distance: f32,
    /// Index of the triangle in the mesh's `triangles`.
    pub triangle: u32,
    /// The closest point on that triangle.
    pub point: Vec3,
}

/// A bounding volume hierarchy over a mesh's triangles for closest-point queries.
///
/// Triangles with an out-of-range vertex index are left out; zero-area triangles are kept and
/// measured as segments or points.
#[derive(Clone, Debug, Default)]
pub struct TriangleBvh {
    bvh: Bvh,
    /// Corner positions per stored position (leaf order).
    corners: Vec<[Vec3; 3]>,
    /// Original triangle index per stored position.
    ids: Vec<u32>,
}

/// Triangles per leaf: small leaves prune well, and a leaf's corners share cache lines.
const TRIANGLE_LEAF: usize = 4;

fn triangle_box([a, b, c]: &[Vec3; 3]) -> (Vec3, Vec3) {
    (a.min(*b).min(*c), a.max(*b).max(*c))
}

impl TriangleBvh {
    /// Builds the hierarchy over the triangles of `mesh` (none for a point cloud).
    pub fn new(mesh: &Mesh) -> TriangleBvh {
        let p = &mesh.positions;
        let (corners, ids): (Vec<[Vec3; 3]>, Vec<u32>) = mesh
            .triangles
            .par_iter()
            .enumerate()
            .filter(|(_, tri)| tri.iter().all(|&v| (v as usize) < p.len()))
            .map(|(i, tri)| (tri.map(|v| p[v as usize]), i as u32))
            .unzip();
        let boxes: Vec<(Vec3, Vec3)> = corners.par_iter().map(triangle_box).collect();
        let bvh = Bvh::build_morton(&boxes, TRIANGLE_LEAF);
        let corners_sorted = bvh.order.par_iter().map(|&i| corners[i as usize]).collect();
        let ids_sorted = bvh.order.par_iter().map(|&i| ids[i as usize]).collect();
        TriangleBvh { bvh, corners: corners_sorted, ids: ids_sorted }
    }

    /// Number of triangles in the hierarchy.
    pub fn len(&self) -> usize {
        self.ids.len()
    }

    /// True when there are no triangles to measure against.
    pub fn is_empty(&self) -> bool {
        self.ids.is_empty()
    }

    /// The closest point to `p` on any triangle, or `None` when there are no triangles or `p`
    /// has a NaN coordinate.
    pub fn closest_point(&self, p: Vec3) -> Option<Closest> {
        let point_of = |position: usize| {
            let [a, b, c] = self.corners[position];
            closest_point_on_triangle(p, a, b, c)
        };
        let (position, d2) = self.bvh.nearest(p, |position| point_of(position).distance_squared(p))?;
        Some(Closest { distance: d2.sqrt(), triangle: self.ids[position], point: point_of(position) })
    }

    /// Distance from `p` to the triangles: `f32::INFINITY` when there are none, NaN when `p` has
    /// a NaN coordinate.
    pub fn distance(&self, p: Vec3) -> f32 {
        match self.closest_point(p) {
            Some(c) => c.distance,
            None if p.is_nan() => f32::NAN,
            None => f32::INFINITY,
        }
    }

    /// Checks the hierarchy's invariants (see the tree's own `validate`) and that every stored
    /// triangle index is distinct: the first broken rule, named, as the error.
    pub fn validate(&self) -> Result<(), String> {
        if self.corners.len() != self.ids.len() || self.ids.len() != self.bvh.order.len() {
            return Err(format!(
                "{} corners, {} ids, {} items",
                self.corners.len(),
                self.ids.len(),
                self.bvh.order.len()
            ));
        }
        let mut ids = self.ids.clone();
        ids.sort_unstable();
        if let Some(pair) = ids.windows(2).find(|pair| pair[0] == pair[1]) {
            return Err(format!("triangle {} is stored twice", pair[0]));
        }
        self.bvh.validate(TRIANGLE_LEAF, |position| triangle_box(&self.corners[position]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;
    use glam::DVec3;

    /// Independent oracle: project onto the plane in double precision; if the projection is
    /// inside (barycentric test) that is the answer, else the nearest of the three edges.
    fn oracle_distance(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> f64 {
        let (p, a, b, c) = (p.as_dvec3(), a.as_dvec3(), b.as_dvec3(), c.as_dvec3());
        let segment = |a: DVec3, b: DVec3| {
            let ab = b - a;
            let t =
                if ab.length_squared() > 0.0 { ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0) } else { 0.0 };
            (a + ab * t).distance(p)
        };
        let edges = segment(a, b).min(segment(b, c)).min(segment(c, a));
        let n = (b - a).cross(c - a);
        if n.length_squared() == 0.0 {
            return edges;
        }
        let q = p - n * ((p - a).dot(n) / n.length_squared());
        let inside = [(a, b), (b, c), (c, a)].iter().all(|&(u, v)| (v - u).cross(q - u).dot(n) >= 0.0);
        if inside {
            q.distance(p)
        } else {
            edges
        }
    }

    fn random_vec(rng: &mut Rng) -> Vec3 {
        Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 2.0 - Vec3::ONE
    }

    #[test]
    fn point_triangle_matches_oracle() {
        let mut rng = Rng::new(11);
        for _ in 0..20_000 {
            let (a, b, c) = (random_vec(&mut rng), random_vec(&mut rng), random_vec(&mut rng));
            let p = random_vec(&mut rng) * 2.0;
            let got = f64::from(closest_point_on_triangle(p, a, b, c).distance(p));
            let want = oracle_distance(p, a, b, c);
            assert!((got - want).abs() < 1e-5, "{p} {a} {b} {c}: {got} vs {want}");
        }
        // Degenerate triangles: a point, a segment, collinear corners.
        let p = Vec3::new(0.3, 1.0, 0.0);
        let z = Vec3::ZERO;
        assert_eq!(closest_point_on_triangle(p, z, z, z), z);
        let q = closest_point_on_triangle(p, z, Vec3::X, Vec3::X);
        assert!((q - Vec3::new(0.3, 0.0, 0.0)).length() < 1e-6);
        let q = closest_point_on_triangle(p, z, Vec3::X * 0.5, Vec3::X);
        assert!((q - Vec3::new(0.3, 0.0, 0.0)).length() < 1e-6);
    }

    /// A small random triangle soup.
    fn soup(rng: &mut Rng, n: usize) -> Mesh {
        let mut mesh = Mesh::default();
        for t in 0..n as u32 {
            let centre = random_vec(rng);
            for _ in 0..3 {
                mesh.positions.push(centre + random_vec(rng) * 0.2);
            }
            mesh.triangles.push([3 * t, 3 * t + 1, 3 * t + 2]);
        }
        mesh
    }

    #[test]
    fn triangle_bvh_matches_brute_force() {
        let mut rng = Rng::new(5);
        let mesh = soup(&mut rng, 300);
        let bvh = TriangleBvh::new(&mesh);
        assert_eq!(bvh.len(), 300);
        bvh.validate().unwrap();
        for _ in 0..3_000 {
            let p = random_vec(&mut rng) * 1.5;
            let brute = mesh
                .triangles
                .iter()
                .map(|t| {
                    let [a, b, c] = t.map(|v| mesh.positions[v as usize]);
                    closest_point_on_triangle(p, a, b, c).distance_squared(p).sqrt()
                })
                .fold(f32::INFINITY, f32::min);
            let found = bvh.closest_point(p).unwrap();
            assert!((found.distance - brute).abs() <= 1e-6, "{} vs {brute}", found.distance);
            let [a, b, c] = mesh.triangles[found.triangle as usize].map(|v| mesh.positions[v as usize]);
            assert!((closest_point_on_triangle(p, a, b, c) - found.point).length() <= 1e-6);
        }
    }

    #[test]
    fn empty_and_unusable_triangles() {
        assert!(TriangleBvh::new(&Mesh::default()).closest_point(Vec3::ZERO).is_none());
        assert_eq!(TriangleBvh::new(&Mesh::default()).distance(Vec3::ONE), f32::INFINITY);
        TriangleBvh::new(&Mesh::default()).validate().unwrap();
        let mut bad = Mesh::from_points(vec![Vec3::ZERO], None);
        bad.triangles.push([0, 1, 2]);
        assert!(TriangleBvh::new(&bad).is_empty());
        let one = Mesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::Y], None, vec![[0, 1, 2]]);
        assert!(TriangleBvh::new(&one).distance(Vec3::NAN).is_nan());
    }
}
