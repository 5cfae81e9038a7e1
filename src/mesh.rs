//! The indexed triangle mesh that every stage reads and writes. A point cloud is a `Mesh`
//! with no triangles.

use crate::error::{Error, Result};
use glam::{DVec3, Vec3};

/// An indexed triangle mesh, or a point cloud when `triangles` is empty.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// Vertex positions, relative to `origin`.
    pub positions: Vec<Vec3>,
    /// Per-vertex normals, when the source has them (same length as `positions`).
    pub normals: Option<Vec<Vec3>>,
    /// Triangles as counter-clockwise vertex index triples (the input's winding is kept).
    pub triangles: Vec<[u32; 3]>,
    /// Where `positions` are measured from: a vertex is at `origin + position`. Zero unless the
    /// mesh was read from a file far from the origin for its size (see [`crate::io`]), where
    /// f32 coordinates would lose its detail. Every stage works on the relative positions and
    /// gives its result the input's origin; the writers add it back in f64.
    pub origin: DVec3,
}

/// Largest coordinate magnitude accepted. The geometry is `f32`: squared lengths of
/// coordinate differences must stay finite (below 3.4e38), with room for sums of them.
pub const MAX_COORDINATE: f32 = 1e18;

/// Checks that every point is finite and within [`MAX_COORDINATE`]; the error names the first
/// offender as `{what} {index}` (e.g. "vertex 12").
pub fn check_positions(points: &[Vec3], what: &str) -> Result<()> {
    // (`max_element` skips NaN, so finiteness is tested on its own.)
    let Some(i) = points.iter().position(|p| !p.is_finite() || p.abs().max_element() > MAX_COORDINATE) else {
        return Ok(());
    };
    let p = points[i];
    Err(Error::input(if p.is_finite() {
        format!(
            "{what} {i} has a coordinate of {:e}: at most {MAX_COORDINATE:e} in magnitude is supported \
             (32-bit geometry); rescale the input",
            p.abs().max_element()
        )
    } else {
        format!("{what} {i} has a NaN or infinite coordinate")
    }))
}

/// An axis-aligned bounding box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub min: Vec3,
    pub max: Vec3,
}

impl Aabb {
    /// The box of `points`, or `None` when there are none.
    pub fn of(points: &[Vec3]) -> Option<Aabb> {
        let first = *points.first()?;
        let (min, max) = points.iter().fold((first, first), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
        Some(Aabb { min, max })
    }

    /// Length of the diagonal: the unit all relative thresholds are measured in. Computed in
    /// `f64`, so neither very large nor very small boxes overflow or underflow on the way.
    pub fn diagonal(&self) -> f32 {
        (self.max.as_dvec3() - self.min.as_dvec3()).length() as f32
    }

    pub fn center(&self) -> Vec3 {
        0.5 * (self.min + self.max)
    }
}

impl Mesh {
    /// A mesh at the origin (see [`Mesh::origin`]).
    pub fn new(positions: Vec<Vec3>, normals: Option<Vec<Vec3>>, triangles: Vec<[u32; 3]>) -> Mesh {
        Mesh { positions, normals, triangles, origin: DVec3::ZERO }
    }

    /// A point cloud (no triangles), with or without normals.
    pub fn from_points(positions: Vec<Vec3>, normals: Option<Vec<Vec3>>) -> Mesh {
        Mesh::new(positions, normals, Vec::new())
    }

    /// The absolute position of vertex `i`, in f64.
    pub fn absolute(&self, i: usize) -> DVec3 {
        self.origin + self.positions[i].as_dvec3()
    }

    pub fn is_point_cloud(&self) -> bool {
        self.triangles.is_empty()
    }

    pub fn bounds(&self) -> Option<Aabb> {
        Aabb::of(&self.positions)
    }

    /// Checks what every algorithm relies on: finite coordinates within [`MAX_COORDINATE`], a
    /// finite origin, normals (if any) as many as positions and finite, triangle indices in
    /// range. The error names the first offender.
    pub fn check(&self) -> Result<()> {
        check_positions(&self.positions, "vertex")?;
        if !self.origin.is_finite() {
            return Err(Error::input(format!("the origin {} is not finite", self.origin)));
        }
        if let Some(normals) = &self.normals {
            if normals.len() != self.positions.len() {
                return Err(Error::input(format!("{} normals for {} vertices", normals.len(), self.positions.len())));
            }
            if let Some(i) = normals.iter().position(|n| !n.is_finite()) {
                return Err(Error::input(format!("normal {i} has a NaN or infinite component")));
            }
        }
        let n = self.positions.len() as u64;
        for (t, tri) in self.triangles.iter().enumerate() {
            if let Some(&bad) = tri.iter().find(|&&i| u64::from(i) >= n) {
                return Err(Error::input(format!("triangle {t} uses vertex {bad}, but there are only {n} vertices")));
            }
        }
        Ok(())
    }

    /// Unit vertex normals as the area-weighted average of the incident faces' normals
    /// (+z where undefined: unreferenced vertices, or only zero-area faces around).
    /// Triangles with an index out of range are skipped.
    pub fn area_weighted_normals(&self) -> Vec<Vec3> {
        let p = &self.positions;
        let mut sums = vec![Vec3::ZERO; p.len()];
        for tri in &self.triangles {
            if tri.iter().any(|&v| v as usize >= p.len()) {
                continue;
            }
            let [a, b, c] = tri.map(|v| p[v as usize]);
            // The cross product's length is twice the area: the weighting comes for free.
            let n = (b - a).cross(c - a);
            for &v in tri {
                sums[v as usize] += n;
            }
        }
        sums.into_iter().map(|n| n.normalize_or(Vec3::Z)).collect()
    }
}
