//! File formats (placeholder until the I/O module lands).
