//! Surface reconstruction from a point cloud (paper §5).

mod base_mesh;
mod implicit;
