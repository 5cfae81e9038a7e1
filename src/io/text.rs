//! Small helpers shared by the line-oriented text formats (OFF, XYZ, ASCII PLY, OBJ).

use crate::error::Error;
use crate::mesh::Mesh;
use glam::DVec3;
use std::borrow::Cow;
use std::fmt;
use std::path::Path;
use std::str::FromStr;

/// The lines of `bytes`, numbered from 1, without their `\n` or `\r\n` terminator. Invalid
/// UTF-8 is replaced (it can only matter inside comments: numbers are ASCII).
pub(crate) fn lines(bytes: &[u8]) -> impl Iterator<Item = (usize, Cow<'_, str>)> {
    bytes.split(|&b| b == b'\n').enumerate().map(|(i, line)| {
        let line = line.strip_suffix(b"\r").unwrap_or(line);
        (i + 1, String::from_utf8_lossy(line))
    })
}

/// Parses one number token, with a message that shows the offending token.
pub(crate) fn number<T: FromStr>(token: &str) -> Result<T, String> {
    token.parse().map_err(|_| format!("expected a number, found {}", quoted(token)))
}

/// `token` in backquotes, shortened if long, for error messages; control characters (NUL,
/// escape, ...) are escaped, as in `\0` or `\u{1b}`, so a message never carries them.
pub(crate) fn quoted(token: &str) -> String {
    const MAX: usize = 40;
    let (shown, more) = match token.char_indices().nth(MAX) {
        Some((cut, _)) => (&token[..cut], "..."),
        None => (token, ""),
    };
    let mut text = String::from("`");
    for c in shown.chars() {
        if c.is_control() {
            text.extend(c.escape_debug());
        } else {
            text.push(c);
        }
    }
    format!("{text}{more}`")
}

/// Whether `b` is a byte that no text holds: an ASCII control character (NUL, escape,
/// delete, ...) other than tab, line feed, vertical tab, form feed and carriage return.
pub(crate) const fn is_binary(b: u8) -> bool {
    b.is_ascii_control() && !matches!(b, b'\t' | b'\n' | 0x0b | 0x0c | b'\r')
}

/// Vertex `i` of a mesh as `x y z` text: the stored f32 values for a mesh at the origin (the
/// shortest text that reads back to them), else the absolute position in f64, so that a model
/// far from the origin keeps its detail.
pub(crate) struct Position<'a>(pub &'a Mesh, pub usize);

impl fmt::Display for Position<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let Position(mesh, i) = *self;
        if mesh.origin == DVec3::ZERO {
            let p = mesh.positions[i];
            write!(f, "{} {} {}", p.x, p.y, p.z)
        } else {
            let p = mesh.absolute(i);
            write!(f, "{} {} {}", p.x, p.y, p.z)
        }
    }
}

/// The error every reader gives for a file with nothing but whitespace in it.
pub(crate) fn reject_blank(bytes: &[u8], path: &Path) -> Result<(), Error> {
    if bytes.iter().all(u8::is_ascii_whitespace) {
        Err(empty_file(path))
    } else {
        Ok(())
    }
}

/// The error for a file with nothing but whitespace in it.
pub(crate) fn empty_file(path: &Path) -> Error {
    Error::parse(path, "line 1", "file is empty")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_lines_and_strips_crlf() {
        let got: Vec<_> = lines(b"a\r\nb\n\nc").collect();
        assert_eq!(got.len(), 4);
        assert_eq!((got[0].0, &*got[0].1), (1, "a"));
        assert_eq!((got[3].0, &*got[3].1), (4, "c"));
    }

    #[test]
    fn number_errors_quote_the_token() {
        assert_eq!(number::<f32>("1.5"), Ok(1.5));
        assert!(number::<f32>("abc").unwrap_err().contains("`abc`"));
        assert!(quoted(&"x".repeat(100)).ends_with("...`"));
        assert_eq!(quoted("1\u{0}\u{0}\u{1b}[2J\t"), "`1\\0\\0\\u{1b}[2J\\t`");
    }
}
