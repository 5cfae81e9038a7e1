//! File formats (being built up).

#![allow(dead_code)]

mod assemble;
mod atomic;
pub mod obj;
pub mod off;
pub mod ply;
mod text;
pub mod xyz;
