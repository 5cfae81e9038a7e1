//! Reading an input file with bounds: only regular files are read (a device, a FIFO or a
//! socket could be endless or block forever), never more than the size the file had when it
//! was opened, and the first [`PREFIX_BYTES`] are checked against the format before the rest
//! is read, so a file of another kind fails at once and with little memory whatever its size.

use super::Format;
use crate::error::{Error, Result};
use std::fs::{File, Metadata, OpenOptions};
use std::io::{self, Read};
use std::path::Path;

/// Bytes read and checked before the rest of a file: enough for any real PLY header and for
/// many lines of a text format, little enough to be instant.
pub(crate) const PREFIX_BYTES: usize = 64 * 1024;

/// The whole content of the regular file at `path`, once its start looks like `format`.
pub(crate) fn read(path: &Path, format: Format) -> Result<Vec<u8>> {
    let io_error = |e| Error::io(path, e);
    let (file, size) = open_regular(path).map_err(io_error)?;
    let size = usize::try_from(size).map_err(|_| Error::TooLarge(format!("{}: {size} bytes", path.display())))?;
    // One byte more than the size, to notice a file that grows while it is read.
    let mut reader = file.take(size as u64 + 1);
    let mut bytes = Vec::with_capacity(size.min(PREFIX_BYTES));
    (&mut reader).take(PREFIX_BYTES as u64).read_to_end(&mut bytes).map_err(io_error)?;
    format.check_start(&bytes, bytes.len() < size, path)?;
    bytes.reserve_exact(size.saturating_sub(bytes.len()));
    reader.read_to_end(&mut bytes).map_err(io_error)?;
    if bytes.len() > size {
        return Err(io_error(io::Error::other("the file grew while it was read: read it once it is complete")));
    }
    Ok(bytes)
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
    let Some(at) = bytes.iter().position(|&b| b == 0) else {
        return Ok(());
    };
    let line = 1 + bytes[..at].iter().filter(|&&b| b == b'\n').count();
    Err(Error::parse(path, format!("line {line}"), "a NUL byte: this is binary data, not a text file"))
}
