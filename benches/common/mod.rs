//! What the table benches (`benches/table1`, `benches/table2`, `benches/corpus`) share:
//! command-line helpers, inputs drawn on a surface, distances relative to the diagonal, folds, the
//! Markdown report's header and formatting, peak memory in a child process, the Python peers'
//! plumbing, and what the reconstruction benches share (timed runs, the peers' records).
//!
//! Each bench includes this directory with `#[path = "../common/mod.rs"] mod common;`.

// Every bench binary compiles all of this but uses only a part.
#![allow(dead_code)]

pub mod cli;
pub mod distance;
pub mod folds;
pub mod inputs;
pub mod memory;
pub mod peers;
pub mod reconstruction;
pub mod report;
pub mod stats;
