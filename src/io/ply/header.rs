//! The PLY header: format, elements and their properties, up to `end_header`.

use super::scalar::Scalar;
use crate::error::{Error, Result};
use crate::io::text;
use std::path::Path;

/// How the body after the header is encoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Encoding {
    Ascii,
    BinaryLittleEndian,
    BinaryBigEndian,
}

/// A property's type: one scalar, or a list with its own count and item types.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Kind {
    Scalar(Scalar),
    List { count: Scalar, item: Scalar },
}

/// One `property` line.
#[derive(Clone, Debug)]
pub(crate) struct Property {
    pub name: String,
    pub kind: Kind,
}

/// One `element` line with the properties that follow it.
#[derive(Clone, Debug)]
pub(crate) struct Element {
    pub name: String,
    pub count: usize,
    pub properties: Vec<Property>,
    /// The header line declaring the element, for error messages.
    pub line: usize,
}

/// A parsed header.
#[derive(Clone, Debug)]
pub(crate) struct Header {
    pub encoding: Encoding,
    pub elements: Vec<Element>,
    /// Byte offset of the body.
    pub body_start: usize,
    /// Number of header lines; the body starts on the next line.
    pub lines: usize,
}

/// The location of the error for a header without `end_header`.
pub(crate) const UNFINISHED: &str = "header";

/// Parses the header at the start of `bytes`. With `more`, the input goes on after `bytes`:
/// their last line may be cut, so it is only checked for binary bytes, and a header that
/// `bytes` do not finish is the [`UNFINISHED`] error.
pub(crate) fn parse(bytes: &[u8], more: bool, path: &Path) -> Result<Header> {
    const BAD_MAGIC: &str = "not a PLY file: it must start with a `ply` line";
    if bytes.is_empty() {
        return Err(Error::parse(path, "line 1", "file is empty"));
    }
    if !bytes.starts_with(b"ply") {
        return Err(Error::parse(path, "line 1", BAD_MAGIC));
    }
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    let mut offset = 0;
    for (number, line) in text::lines(bytes) {
        let start = offset;
        offset += line_length(bytes.get(offset..).unwrap_or_default());
        let fail = |message: String| Error::parse(path, format!("line {number}"), message);
        if let Some(&b) = bytes[start..offset].iter().find(|&&b| text::is_binary(b)) {
            return Err(fail(format!("byte {b:#04x}: this is binary data, but a PLY header is text")));
        }
        if more && !bytes[..offset].ends_with(b"\n") {
            break;
        }
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["ply"] if number == 1 => {}
            _ if number == 1 => return Err(fail(BAD_MAGIC.into())),
            [] | ["comment", ..] | ["obj_info", ..] => {}
            ["format", format, version] => {
                if *version != "1.0" && *version != "1" {
                    return Err(fail(format!("unsupported PLY version {}", text::quoted(version))));
                }
                encoding = Some(match *format {
                    "ascii" => Encoding::Ascii,
                    "binary_little_endian" => Encoding::BinaryLittleEndian,
                    "binary_big_endian" => Encoding::BinaryBigEndian,
                    other => return Err(fail(format!("unknown format {}", text::quoted(other)))),
                });
            }
            ["element", name, count] => {
                let count = count
                    .parse()
                    .map_err(|_| fail(format!("element count {} is not a number", text::quoted(count))))?;
                elements.push(Element { name: name.to_string(), count, properties: Vec::new(), line: number });
            }
            ["property", rest @ ..] => {
                let element = elements.last_mut().ok_or_else(|| fail("property before any element".into()))?;
                element.properties.push(property(rest).map_err(fail)?);
            }
            ["end_header"] => {
                let encoding = encoding.ok_or_else(|| fail("no `format` line before end_header".into()))?;
                return Ok(Header { encoding, elements, body_start: offset, lines: number });
            }
            _ => return Err(fail(format!("unexpected header line {}", text::quoted(&line)))),
        }
    }
    Err(Error::parse(path, UNFINISHED, "file ends before `end_header`"))
}

/// Length of the first line of `bytes` including its `\n`.
fn line_length(bytes: &[u8]) -> usize {
    bytes.iter().position(|&b| b == b'\n').map_or(bytes.len(), |i| i + 1)
}

/// Parses the words after `property`.
fn property(words: &[&str]) -> Result<Property, String> {
    let scalar =
        |name: &str| Scalar::from_name(name).ok_or_else(|| format!("unknown property type {}", text::quoted(name)));
    let (kind, name) = match words {
        ["list", count, item, name] => (Kind::List { count: scalar(count)?, item: scalar(item)? }, name),
        [ty, name] if *ty != "list" => (Kind::Scalar(scalar(ty)?), name),
        _ => return Err("malformed property line".into()),
    };
    Ok(Property { name: name.to_string(), kind })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse_str(s: &str) -> Result<Header> {
        parse(s.as_bytes(), false, Path::new("t.ply"))
    }

    #[test]
    fn reads_elements_properties_and_body_offset() {
        let src = "ply\r\nformat binary_big_endian 1.0\r\ncomment hi\r\nobj_info x\r\n\
                   element vertex 2\r\nproperty float32 x\r\nelement face 1\r\n\
                   property list uint8 int32 vertex_indices\r\nend_header\r\nBODY";
        let h = parse_str(src).unwrap();
        assert_eq!(h.encoding, Encoding::BinaryBigEndian);
        assert_eq!(h.elements.len(), 2);
        assert_eq!(h.elements[1].line, 7);
        assert_eq!(h.elements[1].properties[0].kind, Kind::List { count: Scalar::Uint8, item: Scalar::Int32 });
        assert_eq!(&src.as_bytes()[h.body_start..], b"BODY");
        assert_eq!(h.lines, 9);
    }

    #[test]
    fn reports_the_bad_line() {
        let err =
            parse_str("ply\nformat ascii 1.0\nelement v 1\nproperty quux x\nend_header\n").unwrap_err().to_string();
        assert!(err.contains("line 4") && err.contains("`quux`"), "{err}");
        let err = parse_str("ply\nformat weird 1.0\nend_header\n").unwrap_err().to_string();
        assert!(err.contains("line 2") && err.contains("unknown format"), "{err}");
        for bad in ["plx\n", "plyx\n", "ply 1\n"] {
            let err = parse_str(bad).unwrap_err().to_string();
            assert!(err.contains("line 1: not a PLY file"), "{err}");
        }
        assert!(parse_str("ply \r\nformat ascii 1.0\nend_header\n").is_ok());
        assert!(parse_str("ply\nformat ascii 1.0\n").is_err());
    }
}
