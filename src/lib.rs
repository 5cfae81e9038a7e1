//! # vstree
//!
//! Volume-Surface Trees (Boubekeur, Heidrich, Granier, Schlick, Eurographics 2006): a hierarchical
//! space subdivision that is an octree far from the surface and a set of 2D quadtrees, each in the
//! surface's local frame, near it. It gives better-balanced clusters than an octree for
//! clustering simplification, and drives a fast point-to-mesh reconstruction.

mod chunks;
mod collapse;
mod decimate;
pub mod error;
#[cfg(any(test, feature = "eval"))]
pub mod eval;
pub mod ffi;
pub mod io;
mod linalg;
mod memory;
pub mod mesh;
pub mod normals;
/// cbindgen:ignore
pub mod params;
mod polygonise;
pub mod progress;
mod quad_heap;
pub mod quadric;
pub mod reconstruct;
pub mod rng;
pub mod samples;
pub mod simplify;
pub mod spatial;
pub mod topology;
pub mod tree;
mod union_find;

pub use error::{Error, Result};
pub use mesh::{Aabb, Mesh};
pub use progress::{Progress, Threads};
pub use samples::{MeshSampling, SampleSet};
pub use simplify::{simplify, KeepTopology, SimplifyParams, SimplifyStats};
pub use tree::{Metric, TreeKind, TreeParams, VsTree};
