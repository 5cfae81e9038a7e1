//! The body of an ASCII PLY file: one item per line, its values separated by spaces or tabs,
//! read in header order.
//!
//! Each item must be exactly one line: too few or too many values are reported at that line,
//! with the count expected. Blank (whitespace-only) lines between items are skipped, since an
//! item always holds at least one value and so a blank line cannot be one; trailing
//! whitespace and `\r\n` line ends are accepted. A byte that no text holds (NUL, another
//! control character) is refused where it is met, so a binary body behind an `ascii` header
//! is not read on, and so is a line longer than [`MAX_LINE`], which no real file holds.

use super::header::Header;
use super::items::{self, Cursor, Fail, Sink};
use super::plan::{Plan, Target};
use super::scalar::Scalar;
use crate::error::Result;
use crate::io::input::{self, Input, MAX_LINE};
use crate::io::text;
use std::path::Path;

/// Reads the body that starts at byte `start` of `input`, on line `first_line`, into `sink`.
pub(crate) fn read(
    input: &mut Input,
    start: usize,
    first_line: usize,
    header: &Header,
    plan: &Plan,
    sink: &mut impl Sink,
    path: &Path,
) -> Result<()> {
    let mut tokens = Tokens { input, pos: start, line: first_line, line_start: start, item_line: first_line, found: 0 };
    for (element, job) in header.elements.iter().zip(&plan.jobs) {
        if job.target == Target::Faces && !sink.wants_faces() {
            break;
        }
        items::read_element(&mut tokens, element, job, plan.vertex_count, sink, path)?;
    }
    Ok(())
}

/// Whether a byte may be in a token: it is neither whitespace nor a byte that no text holds.
/// A table, since every byte of the body is looked up in it.
static IN_TOKEN: [bool; 256] = {
    let mut table = [false; 256];
    let mut b = 0;
    while b < 256 {
        table[b] = !(b as u8).is_ascii_whitespace() && !text::is_binary(b as u8);
        b += 1;
    }
    table
};

/// Whitespace-separated tokens, read one line (item) at a time.
struct Tokens<'i, 'a> {
    input: &'i mut Input<'a>,
    pos: usize,
    /// Line at `pos`.
    line: usize,
    /// Where that line starts, which bounds how far it may go on.
    line_start: usize,
    /// Line of the current item.
    item_line: usize,
    /// Values read so far from the current item's line.
    found: usize,
}

impl Tokens<'_, '_> {
    /// Moves over the bytes for which `keep` holds; returns the byte it stops at, if any. The
    /// line may not go on past [`MAX_LINE`]: this is checked each time the bytes pulled so far
    /// are used up, so no more than that (and one pull) is pulled.
    #[inline]
    fn advance(&mut self, keep: impl Fn(u8) -> bool) -> Result<Option<u8>, Fail> {
        loop {
            let bytes = self.input.available(self.pos);
            if bytes.is_empty() {
                return Ok(None);
            }
            match bytes.iter().position(|&b| !keep(b)) {
                Some(at) => {
                    let stop = bytes[at];
                    self.pos += at;
                    return Ok(Some(stop));
                }
                None => self.pos += bytes.len(),
            }
            if self.pos - self.line_start > MAX_LINE {
                return Err(Fail::Bad(input::line_too_long()));
            }
        }
    }

    /// Skips whitespace up to, not over, the end of the line (`\r` is whitespace).
    fn skip_spaces(&mut self) -> Result<(), Fail> {
        self.advance(|b| b != b'\n' && b.is_ascii_whitespace()).map(drop)
    }

    /// Moves over the line break at `pos`.
    fn next_line(&mut self) {
        self.pos += 1;
        self.line += 1;
        self.line_start = self.pos;
    }

    /// The next token on the current line, or `None` at the line's end; an error at a byte
    /// that no text holds. Inlined into its callers: it runs once per value of the body.
    #[inline(always)]
    fn next_token(&mut self) -> Result<Option<&[u8]>, Fail> {
        self.skip_spaces()?;
        let start = self.pos;
        match self.advance(|b| IN_TOKEN[b as usize])? {
            Some(b) if text::is_binary(b) => {
                Err(Fail::Bad(format!("byte {b:#04x}: this is binary data, but the header says `format ascii`")))
            }
            // The token's bytes are pulled: `advance` went over them.
            _ => Ok(Some(self.input.slice(start..self.pos)).filter(|t| !t.is_empty())),
        }
    }

    fn parse<T: std::str::FromStr>(&mut self) -> Result<T, Fail> {
        let found = self.found;
        let token = self.next_token()?.ok_or(Fail::Count { found })?;
        // Borrows unless the token is invalid UTF-8, which is not a number anyway.
        let parsed = text::number(&String::from_utf8_lossy(token)).map_err(Fail::Bad);
        self.found += 1;
        parsed
    }
}

impl Cursor for Tokens<'_, '_> {
    fn number(&mut self, _: Scalar) -> Result<f64, Fail> {
        self.parse()
    }

    fn start_item(&mut self) -> Result<(), Fail> {
        loop {
            self.skip_spaces()?;
            match self.input.byte(self.pos) {
                None => return Err(Fail::End),
                Some(b'\n') => self.next_line(),
                Some(_) => break,
            }
        }
        self.item_line = self.line;
        self.found = 0;
        Ok(())
    }

    fn finish_item(&mut self) -> Result<(), Fail> {
        let mut extra = 0;
        while self.next_token()?.is_some() {
            extra += 1;
        }
        if extra > 0 {
            return Err(Fail::Count { found: self.found + extra });
        }
        // Now at the line break, or at the end of a file whose last line has none.
        if self.input.byte(self.pos) == Some(b'\n') {
            self.next_line();
        }
        Ok(())
    }

    fn remaining(&self) -> usize {
        self.input.remaining(self.pos)
    }

    #[inline]
    fn release(&mut self) {
        self.input.release(self.pos);
    }

    fn line(&self) -> Option<usize> {
        Some(self.item_line)
    }
}
