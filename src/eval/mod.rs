//! What tests, benchmarks and the CLI's demo use to make inputs and measure outputs, apart from
//! the product: simplifying and reconstructing do not need any of it.
//!
//! - [`shapes`]: generated meshes whose answers are known (spheres, tori, genus-n pretzels, grids,
//!   implicit surfaces), sampling points on a surface, and noise.
//! - [`distance`]: point-to-mesh and mesh-to-mesh distances, Chamfer and Hausdorff.
//! - [`figures`]: valences, enclosed volume and area.
//! - [`written`]: large generated meshes written straight to a file.
//!
//! Counts, watertightness and genus are [`crate::topology`]'s: the product uses them too.

pub mod distance;
pub mod figures;
pub mod shapes;
pub mod written;
