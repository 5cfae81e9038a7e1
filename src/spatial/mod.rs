//! Spatial indexes: one over points, one over triangles.
//!
//! - [`KdTree`]: the point index. The k nearest points of a query or of every point (normal
//!   estimation, moving least squares), and the nearest one, optionally among the points a
//!   filter keeps and within a radius (the reconstruction's support and trimming tests, the
//!   benchmarks' distances). Exact, ties broken by the smaller input index.
//! - [`TriangleBvh`]: closest point on a mesh's triangles (the reconstruction's projection, the
//!   distances to a mesh), exact, over a linear bounding volume hierarchy.
//!
//! Both are built in parallel on the current rayon pool and give the same answers for any
//! thread count, and both have a `validate()` that checks the invariants their queries rely on.

mod bvh;
mod kd_tree;
mod triangles;

pub use kd_tree::{knn_all, KdTree, Neighbour, MAX_K};
pub use triangles::{closest_point_on_triangle, Closest, TriangleBvh};
