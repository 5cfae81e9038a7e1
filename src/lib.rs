//! # vstree
//!
//! Volume-Surface Trees (Boubekeur, Heidrich, Granier, Schlick, Eurographics 2006): a hierarchical
//! space subdivision that is an octree far from the surface and a set of 2D quadtrees, each in the
//! surface's local frame, near it. It gives better-balanced clusters than an octree for
//! clustering simplification, and drives a fast point-to-mesh reconstruction.

pub mod distance;
pub mod error;
pub mod io;
pub mod mesh;
pub mod rng;
pub mod shapes;
pub mod topology;

pub use error::{Error, Result};
pub use mesh::{Aabb, Mesh};
