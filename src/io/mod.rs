//! File formats (being built up).

#![allow(dead_code)]

mod assemble;
mod atomic;
pub mod ply;
mod text;
