//! Reading an input file with bounds: only regular files are read (a device, a FIFO or a
//! socket could be endless or block forever), never more than the size the file had when it
//! was opened, and only as far as the reader gets: [`Input`] pulls bytes from the file as the
//! reader asks for them, so a reader that stops (at the end of the elements a PLY header
//! declares, or at a byte no file of its format holds) leaves the rest of the file unread.

use crate::error::{Error, Result};
use std::borrow::Cow;
use std::fs::{File, Metadata, OpenOptions};
use std::io::{self, Read};
use std::ops::Range;
use std::path::Path;

/// Bytes read and checked before the rest of a file: enough for any real PLY header and for
/// many lines of a text format, little enough to be instant.
pub(crate) const PREFIX_BYTES: usize = 64 * 1024;

/// The least an [`Input`] reads from its source at a time, so that readers asking for a few
/// bytes at a time do not make a system call each. Reading stops at most this far past the
/// last byte a reader asked for.
const CHUNK: usize = 64 * 1024;

/// A streaming input drops the bytes a reader has released once they are this many (1 MiB): a
/// copy of what is left to the front of the buffer costs little next to reading that much.
const RELEASE_AT: usize = 1 << 20;

/// The most bytes a line of an OFF, XYZ or ASCII PLY file may hold (16 MiB): its longest real
/// line is a face, and a face of a million corners with 10-digit indices takes 11 MB, so a
/// longer line is not one of these formats and reading stops there instead of holding it.
pub(crate) const MAX_LINE: usize = 16 << 20;

/// Runs `read` on the bytes of the regular file at `path`, pulled from the file as `read` asks
/// for them; an error reading the file, or a file that grows meanwhile, is reported instead of
/// what `read` returns.
pub(crate) fn read<T>(path: &Path, read: impl FnOnce(&mut Input) -> Result<T>) -> Result<T> {
    read_file(path, false, read)
}

/// [`read`] for a reader that goes through the file once, front to back, and calls
/// [`Input::release`] as it goes: only the bytes from the last release on stay in memory, so
/// a file larger than memory can be read.
pub(crate) fn stream<T>(path: &Path, read: impl FnOnce(&mut Input) -> Result<T>) -> Result<T> {
    read_file(path, true, read)
}

fn read_file<T>(path: &Path, streaming: bool, read: impl FnOnce(&mut Input) -> Result<T>) -> Result<T> {
    let io_error = |e| Error::io(path, e);
    let (file, size) = open_regular(path).map_err(io_error)?;
    let size = usize::try_from(size).map_err(|_| Error::TooLarge(format!("{}: {size} bytes", path.display())))?;
    // One byte more than the size, to notice a file that grows while it is read.
    let mut source = file.take(size as u64 + 1);
    let mut input = Input::reading(&mut source, size);
    input.streaming = streaming;
    let result = read(&mut input);
    if let Some(e) = input.failed.take() {
        return Err(io_error(e));
    }
    if input.end() > size {
        return Err(io_error(io::Error::other("the file grew while it was read: read it once it is complete")));
    }
    result
}

/// The bytes of an input, in memory or pulled from a source as a reader asks for them.
/// Positions are from the start of the input; what has been pulled stays in memory, unless the
/// input streams (see [`stream`]), where bytes before the last [`Input::release`] are dropped.
pub(crate) struct Input<'a> {
    /// The bytes from `base` on.
    data: Cow<'a, [u8]>,
    base: usize,
    /// Whether bytes before `released` may be dropped.
    streaming: bool,
    released: usize,
    /// Where more bytes come from; `None` once it has ended or failed, or for bytes in memory.
    source: Option<&'a mut dyn Read>,
    /// The input's whole size as far as it is known (a file's size when it was opened), which
    /// bounds what a reader reserves room for.
    size: usize,
    /// The error that ended the source, reported by [`read`].
    failed: Option<io::Error>,
}

impl<'a> Input<'a> {
    /// An input whose bytes are all in memory.
    pub(crate) fn memory(bytes: &'a [u8]) -> Input<'a> {
        Input {
            data: Cow::Borrowed(bytes),
            base: 0,
            streaming: false,
            released: 0,
            source: None,
            size: bytes.len(),
            failed: None,
        }
    }

    /// An input read from `source`, which holds about `size` bytes.
    pub(crate) fn reading(source: &'a mut dyn Read, size: usize) -> Input<'a> {
        Input {
            data: Cow::Owned(Vec::new()),
            base: 0,
            streaming: false,
            released: 0,
            source: Some(source),
            size,
            failed: None,
        }
    }

    /// The bytes from `start` on, at least `n` of them unless the input ends before.
    pub(crate) fn get(&mut self, start: usize, n: usize) -> &[u8] {
        let end = start.saturating_add(n);
        self.pull(end);
        self.slice(start..end)
    }

    /// The bytes from `at` to the end of those pulled, pulling more if there are none; empty
    /// past the end of the input.
    #[inline]
    pub(crate) fn available(&mut self, at: usize) -> &[u8] {
        if at >= self.end() {
            self.pull(at + 1);
        }
        self.slice(at..usize::MAX)
    }

    /// The byte at `at`, or `None` past the end of the input.
    #[inline]
    pub(crate) fn byte(&mut self, at: usize) -> Option<u8> {
        if at >= self.end() {
            self.pull(at + 1);
        }
        at.checked_sub(self.base).and_then(|i| self.data.get(i)).copied()
    }

    /// The bytes of `range` that have been pulled (and, streaming, not released).
    #[inline]
    pub(crate) fn slice(&self, range: Range<usize>) -> &[u8] {
        debug_assert!(range.start >= self.base, "byte {} was released", range.start);
        let end = range.end.min(self.end());
        self.data.get(range.start - self.base..end.saturating_sub(self.base)).unwrap_or_default()
    }

    /// Where the bytes pulled so far end.
    #[inline]
    pub(crate) fn end(&self) -> usize {
        self.base + self.data.len()
    }

    /// Says that the reader will not look before byte `at` again: a streaming input drops those
    /// bytes at its next pull once they are [`RELEASE_AT`] or more.
    #[inline]
    pub(crate) fn release(&mut self, at: usize) {
        self.released = self.released.max(at);
    }

    /// Bytes from `at` to the end of the input as far as its size is known.
    pub(crate) fn remaining(&self, at: usize) -> usize {
        self.size.max(self.end()).saturating_sub(at)
    }

    /// Reads from the source until `end` bytes are in memory or the source ends, at least
    /// [`CHUNK`] bytes at a time.
    fn pull(&mut self, end: usize) {
        if self.source.is_none() || end <= self.end() {
            return;
        }
        let releasable = self.released.min(self.end()).saturating_sub(self.base);
        if self.streaming && releasable >= RELEASE_AT {
            self.data.to_mut().drain(..releasable);
            self.base += releasable;
        }
        let Some(source) = self.source.as_mut() else { return };
        let have = self.data.len();
        let want = (end - self.base - have).max(CHUNK);
        let bytes = self.data.to_mut();
        // Room grows geometrically (pulls are small), but never past the size of the input.
        if bytes.capacity() - have < want {
            bytes.reserve_exact(want.max(have).min(self.size.saturating_sub(self.base + have) + 1));
        }
        match source.take(want as u64).read_to_end(bytes) {
            Ok(got) if got == want => {}
            Ok(_) => self.source = None,
            Err(e) => {
                self.failed = Some(e);
                self.source = None;
            }
        }
    }

    /// Pulls the rest of a text file and returns all of it, refusing the first NUL byte:
    /// none is in a text file, and pulling stops there.
    pub(crate) fn text(&mut self, path: &Path) -> Result<&[u8]> {
        let mut checked = 0;
        loop {
            let end = self.data.len();
            if let Some(at) = self.data[checked..].iter().position(|&b| b == 0) {
                return Err(nul_error(&self.data[..checked + at], path));
            }
            checked = end;
            self.pull(end + CHUNK);
            if self.data.len() == end {
                return Ok(&self.data);
            }
        }
    }
}

/// The lines of a text input, pulled one at a time, as [`crate::io::text::lines`] splits
/// bytes in memory: numbered from 1, without their `\n` or `\r\n`, invalid UTF-8 replaced. A
/// NUL byte, which no text file holds, is refused at its line, before the rest is pulled, and
/// so is a line longer than [`MAX_LINE`].
pub(crate) struct Lines {
    pos: usize,
    number: usize,
    ended: bool,
}

impl Lines {
    /// The lines from byte `start` on.
    pub(crate) fn new(start: usize) -> Lines {
        Lines { pos: start, number: 0, ended: false }
    }

    /// The next line, or `None` after the last (which is empty when the input ends with `\n`).
    pub(crate) fn next<'i>(&mut self, input: &'i mut Input, path: &Path) -> Result<Option<(usize, Cow<'i, str>)>> {
        let Some((number, range)) = self.next_range(input, path)? else {
            return Ok(None);
        };
        Ok(Some((number, Lines::text(input, range))))
    }

    /// The number of the next line and where its bytes are in `input`, or `None` after the last.
    pub(crate) fn next_range(&mut self, input: &mut Input, path: &Path) -> Result<Option<(usize, Range<usize>)>> {
        if self.ended {
            return Ok(None);
        }
        let start = self.pos;
        // Bytes from `start` known to hold neither a line feed nor a NUL; more are pulled
        // only while the line is unfinished.
        let mut scanned = 0;
        let length = loop {
            let bytes = match scanned {
                0 => input.available(start),
                _ => input.get(start, scanned + CHUNK),
            };
            match bytes[scanned..].iter().position(|&b| b == b'\n' || b == 0) {
                Some(at) if bytes[scanned + at] == 0 => {
                    return Err(Error::parse(path, format!("line {}", self.number + 1), NUL_BYTE));
                }
                Some(at) => break scanned + at,
                None if bytes.len() == scanned => {
                    self.ended = true;
                    break scanned;
                }
                None if bytes.len() > MAX_LINE => {
                    return Err(Error::parse(path, format!("line {}", self.number + 1), line_too_long()));
                }
                None => scanned = bytes.len(),
            }
        };
        self.number += 1;
        self.pos = start + length + 1;
        Ok(Some((self.number, start..start + length)))
    }

    /// The text of the line at `range` (from [`Lines::next_range`]), without a final `\r`.
    pub(crate) fn text<'i>(input: &'i Input, range: Range<usize>) -> Cow<'i, str> {
        let line = input.slice(range);
        String::from_utf8_lossy(line.strip_suffix(b"\r").unwrap_or(line))
    }
}

/// Opens `path` for reading if it is a regular file (links followed), with its size.
/// The type is checked before opening, since opening a FIFO blocks until someone writes
/// to it, and again on the open file, in case the path was replaced in between.
fn open_regular(path: &Path) -> io::Result<(File, u64)> {
    refuse_unless_regular(&std::fs::metadata(path)?)?;
    let mut options = OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        // A FIFO swapped in after the check must not block the open (regular files ignore it).
        options.custom_flags(libc::O_NONBLOCK);
    }
    let file = options.open(path)?;
    let metadata = file.metadata()?;
    refuse_unless_regular(&metadata)?;
    Ok((file, metadata.len()))
}

fn refuse_unless_regular(metadata: &Metadata) -> io::Result<()> {
    if metadata.is_file() {
        return Ok(());
    }
    Err(io::Error::new(
        io::ErrorKind::InvalidInput,
        format!("{}, not a regular file: vstree reads meshes from regular files only", file_kind(metadata)),
    ))
}

/// What kind of file system object `metadata` describes, for messages.
pub(crate) fn file_kind(metadata: &Metadata) -> &'static str {
    let kind = metadata.file_type();
    if kind.is_dir() {
        return "a directory";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if kind.is_char_device() {
            return "a character device";
        }
        if kind.is_block_device() {
            return "a block device";
        }
        if kind.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if kind.is_socket() {
            return "a socket";
        }
    }
    if kind.is_file() {
        "a regular file"
    } else {
        "a special file"
    }
}

/// The error for text data holding a NUL byte, which no text format has: the file is binary
/// (or zeros), so it is refused at the first one instead of being read whole.
pub(crate) fn refuse_binary(bytes: &[u8], path: &Path) -> Result<()> {
    match bytes.iter().position(|&b| b == 0) {
        Some(at) => Err(nul_error(&bytes[..at], path)),
        None => Ok(()),
    }
}

/// The error for a NUL byte that follows `before`.
fn nul_error(before: &[u8], path: &Path) -> Error {
    let line = 1 + before.iter().filter(|&&b| b == b'\n').count();
    Error::parse(path, format!("line {line}"), NUL_BYTE)
}

/// The message for a line longer than [`MAX_LINE`].
pub(crate) fn line_too_long() -> String {
    format!("the line goes on past {} MiB without a line break: no mesh file has such a line", MAX_LINE >> 20)
}

const NUL_BYTE: &str = "a NUL byte: this is binary data, not a text file";

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::{ply, Format};
    use crate::mesh::Mesh;

    /// A source that counts the bytes pulled from it.
    struct Counting<R> {
        inner: R,
        pulled: usize,
    }

    impl<R: Read> Read for Counting<R> {
        fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
            let n = self.inner.read(buf)?;
            self.pulled += n;
            Ok(n)
        }
    }

    const TAIL: u64 = 2 << 30;

    /// Reads `file` followed by 2 GiB of `tail_byte` (generated, never in memory) as `format`;
    /// returns the result and how many bytes were pulled from the source.
    fn read_with_tail(format: Format, file: &[u8], tail_byte: u8) -> (Result<Mesh>, usize) {
        let size = file.len() + TAIL as usize;
        let mut source = Counting { inner: file.chain(io::repeat(tail_byte).take(TAIL)), pulled: 0 };
        let result = format.read(&mut Input::reading(&mut source, size), Path::new("t"));
        (result, source.pulled)
    }

    fn ply_bytes(mesh: &Mesh, ascii: bool) -> Vec<u8> {
        let mut bytes = Vec::new();
        ply::write(&mut bytes, mesh, ascii).unwrap();
        bytes
    }

    #[test]
    fn a_streaming_input_holds_only_what_was_not_released() {
        // 64 MiB read 3000 bytes at a time, each released once read: never more than the
        // release threshold and one pull in memory; without streaming, everything stays.
        let size = 64 << 20;
        for streaming in [true, false] {
            let mut source = io::repeat(7).take(size as u64);
            let mut input = Input::reading(&mut source, size);
            input.streaming = streaming;
            let (mut at, mut most) = (0, 0);
            while !input.get(at, 3000).is_empty() {
                assert!(input.get(at, 3000).iter().all(|&b| b == 7));
                at += input.get(at, 3000).len();
                input.release(at);
                most = most.max(input.data.len());
            }
            assert_eq!(at, size);
            if streaming {
                assert!(most <= RELEASE_AT + 2 * CHUNK, "{most} bytes held");
            } else {
                assert_eq!(most, size);
            }
        }
    }

    #[test]
    fn a_ply_is_read_up_to_its_declared_elements_and_a_tail_is_ignored_unread() {
        // 10242 vertices and 20480 faces: bodies well beyond the first pull.
        let mesh = crate::eval::shapes::icosphere(1.0, 5);
        for ascii in [false, true] {
            let file = ply_bytes(&mesh, ascii);
            for tail_byte in [0, b'7', b'\n'] {
                let (read, pulled) = read_with_tail(Format::Ply, &file, tail_byte);
                assert_eq!(read.unwrap(), mesh, "ascii {ascii}, tail {tail_byte}");
                assert!(
                    pulled <= file.len() + CHUNK,
                    "ascii {ascii}: {pulled} bytes pulled for a {} byte file",
                    file.len()
                );
            }
        }
    }

    #[test]
    fn an_ascii_ply_body_of_nul_bytes_is_refused_at_its_first_byte() {
        let header = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                      property float z\nend_header\n";
        let (read, pulled) = read_with_tail(Format::Ply, header.as_bytes(), 0);
        let message = read.unwrap_err().to_string();
        assert_eq!(message, "t: line 8: vertex 0: byte 0x00: this is binary data, but the header says `format ascii`");
        assert_eq!(pulled, PREFIX_BYTES);
        // The same one line on: a control byte inside a number.
        let (read, pulled) = read_with_tail(Format::Ply, format!("{header}0 0 0\n1 \x1b").as_bytes(), b'2');
        let message = read.unwrap_err().to_string();
        assert_eq!(message, "t: line 9: vertex 1: byte 0x1b: this is binary data, but the header says `format ascii`");
        assert_eq!(pulled, PREFIX_BYTES);
    }

    #[test]
    fn a_ply_header_of_binary_bytes_is_refused_at_its_line() {
        let (read, pulled) = read_with_tail(Format::Ply, b"ply\nformat ascii 1.0\n", 0);
        let message = read.unwrap_err().to_string();
        assert_eq!(message, "t: line 3: byte 0x00: this is binary data, but a PLY header is text");
        assert_eq!(pulled, PREFIX_BYTES);
    }

    #[test]
    fn an_endless_line_is_refused_after_a_bounded_pull() {
        // Each file then 2 GiB of digits: one endless token, on a line that never ends.
        let header = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                      property float z\nend_header\n";
        let long = "the line goes on past 16 MiB without a line break: no mesh file has such a line";
        let cases = [
            (Format::Ply, format!("{header}0 0 0\n1 "), format!("line 9: vertex 1: {long}")),
            (Format::Off, "OFF\n3 1 0\n0 0 0\n".into(), format!("line 4: {long}")),
            (Format::Xyz, "0 0 0\n".into(), format!("line 2: {long}")),
            (
                Format::Ply,
                "ply\nformat ascii 1.0\ncomment ".into(),
                "line 3: the header goes on past 1 MiB \
              without `end_header`: no PLY header is that long"
                    .into(),
            ),
        ];
        for (format, file, expected) in cases {
            let (read, pulled) = read_with_tail(format, file.as_bytes(), b'7');
            assert_eq!(read.unwrap_err().to_string(), format!("t: {expected}"), "{format:?}");
            assert!(pulled <= MAX_LINE + 2 * CHUNK, "{format:?}: {pulled} bytes pulled");
        }
    }

    #[test]
    fn pulled_lines_are_the_lines_in_memory() {
        let long = "x".repeat(3 * CHUNK + 7);
        for text in [format!("a\r\n{long}\r\n\nb \u{e9}\n\r\n"), format!("{long}\nlast"), String::new()] {
            let mut bytes = text.into_bytes();
            bytes.push(0xff);
            let expected: Vec<(usize, String)> = crate::io::text::lines(&bytes).map(|(n, l)| (n, l.into())).collect();
            let mut source = &bytes[..];
            let mut input = Input::reading(&mut source, bytes.len());
            let mut lines = Lines::new(0);
            let mut got = Vec::new();
            while let Some((n, line)) = lines.next(&mut input, Path::new("t")).unwrap() {
                got.push((n, line.into_owned()));
            }
            assert_eq!(got, expected);
        }
    }

    #[test]
    fn text_files_are_read_up_to_their_first_nul_byte_or_bad_line() {
        // Past the first pull: the NUL is found where the file stops being text.
        let lines = "0 0 0\n1 0 0\n0 1 0\n".repeat(10_000);
        let obj: String = lines.lines().map(|l| format!("v {l}\n")).collect();
        for (format, file) in [(Format::Xyz, &lines), (Format::Obj, &obj)] {
            let (read, pulled) = read_with_tail(format, file.as_bytes(), 0);
            let line = file.lines().count() + 1;
            let message = read.unwrap_err().to_string();
            assert_eq!(
                message,
                format!("t: line {line}: a NUL byte: this is binary data, not a text file"),
                "{format:?}"
            );
            assert!(
                pulled <= file.len() + 2 * CHUNK,
                "{format:?}: {pulled} bytes pulled for {} bytes of text",
                file.len()
            );
        }
        // XYZ and OFF are read line by line: a bad line ends the reading.
        let (read, pulled) = read_with_tail(Format::Xyz, b"0 0 0\n1 x 0\n", b'7');
        assert_eq!(read.unwrap_err().to_string(), "t: line 2: expected a number, found `x`");
        assert_eq!(pulled, CHUNK);
        let (read, pulled) = read_with_tail(Format::Off, b"OFF\n3 1 0\n0 0 0\n1 0 0\nx 0 0\n", b'7');
        assert_eq!(read.unwrap_err().to_string(), "t: line 5: vertex 2: expected a number, found `x`");
        assert_eq!(pulled, CHUNK);
        // OFF is read up to its last declared face: a tail is ignored unread.
        let off = format!("OFF\n30000 0 0\n{lines}");
        let (read, pulled) = read_with_tail(Format::Off, off.as_bytes(), 0);
        assert_eq!(read.unwrap().positions.len(), 30_000);
        assert!(pulled <= off.len() + CHUNK, "{pulled} bytes pulled for a {} byte OFF file", off.len());
    }
}
