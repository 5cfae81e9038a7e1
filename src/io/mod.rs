//! File formats (being built up: shared helpers first).

#![allow(dead_code)]

mod assemble;
mod atomic;
mod text;
