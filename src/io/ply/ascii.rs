//! The body of an ASCII PLY file: whitespace-separated tokens, read in header order.

use super::header::Header;
use super::items::{self, Cursor, Fail, Parts};
use super::plan::Plan;
use super::scalar::Scalar;
use crate::error::Result;
use crate::io::text;
use crate::mesh::Mesh;
use std::path::Path;

/// Reads the body `bytes`, which starts on line `first_line`.
pub(crate) fn read(bytes: &[u8], first_line: usize, header: &Header, plan: &Plan, path: &Path) -> Result<Mesh> {
    let mut tokens = Tokens { bytes, pos: 0, line: first_line, token_line: first_line };
    let mut parts = Parts::new(plan.vertex_count, plan.has_normals);
    for (element, job) in header.elements.iter().zip(&plan.jobs) {
        items::read_element(&mut tokens, element, job, &mut parts, path)?;
    }
    Ok(parts.into_mesh())
}

/// Whitespace-separated tokens with line tracking (`\r` counts as whitespace).
struct Tokens<'a> {
    bytes: &'a [u8],
    pos: usize,
    /// Line at `pos`.
    line: usize,
    /// Line of the last token returned.
    token_line: usize,
}

impl<'a> Tokens<'a> {
    fn next_token(&mut self) -> Option<&'a [u8]> {
        while let Some(&b) = self.bytes.get(self.pos) {
            if !b.is_ascii_whitespace() {
                break;
            }
            if b == b'\n' {
                self.line += 1;
            }
            self.pos += 1;
        }
        let start = self.pos;
        while self.bytes.get(self.pos).is_some_and(|b| !b.is_ascii_whitespace()) {
            self.pos += 1;
        }
        let token = self.bytes.get(start..self.pos).filter(|t| !t.is_empty())?;
        self.token_line = self.line;
        Some(token)
    }

    fn parse<T: std::str::FromStr>(&mut self) -> Result<T, Fail> {
        let token = self.next_token().ok_or(Fail::End)?;
        let token = String::from_utf8_lossy(token);
        text::number(&token).map_err(Fail::Bad)
    }
}

impl Cursor for Tokens<'_> {
    fn coord(&mut self, _: Scalar) -> Result<f32, Fail> {
        self.parse()
    }

    fn number(&mut self, _: Scalar) -> Result<f64, Fail> {
        self.parse()
    }

    fn remaining(&self) -> usize {
        self.bytes.len().saturating_sub(self.pos)
    }

    fn line(&self) -> Option<usize> {
        Some(self.token_line)
    }
}
