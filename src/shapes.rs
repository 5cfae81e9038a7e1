//! Generated shapes (placeholder).
