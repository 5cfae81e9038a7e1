//! Whether `simplify` streams its input (`--stream`), and the messages that say why not.

use crate::args::Stream;
use crate::{console, Size};
use std::path::Path;
use vstree::io::{ply, Format};
use vstree::simplify::KeepTopology;

/// The in-memory path's peak, in multiples of a binary PLY file's size (unitless): read whole
/// with the topology kept, the 18M-triangle cheese (346 MB) peaked at 1.93 GB (5.6x) and a
/// 14M-triangle torus (253 MB) at 1.28 GB (5.0x, docs/benchmarks.md); with a margin, a file
/// larger than the memory available over this streams by default.
const MEMORY_PER_FILE_BYTE: u64 = 8;

/// The faces the PLY header declares when the input is to be streamed, `None` when it is read
/// whole. `on` refuses what a stream cannot do; `auto` streams only a PLY file too large for
/// memory, with a target size and the topology not asked for.
pub(crate) fn decide(
    stream: Stream,
    input: &Path,
    size: &Size,
    keep: KeepTopology,
    quiet: bool,
) -> vstree::Result<Option<usize>> {
    let refuse =
        |message: &str| Err(vstree::Error::InvalidParameter { name: "stream", message: format!("on: {message}") });
    let ply = Format::from_path(input) == Some(Format::Ply);
    match stream {
        Stream::Off => return Ok(None),
        Stream::On if !ply => return refuse("only PLY files are streamed"),
        Stream::On if matches!(size, Size::Bound) => {
            return refuse("a streamed simplification needs --faces or --ratio")
        }
        Stream::On if keep == KeepTopology::On => {
            return refuse("keeping the topology needs the whole mesh in memory: drop --keep-topology")
        }
        Stream::On => {}
        Stream::Auto if !ply || matches!(size, Size::Bound) || keep == KeepTopology::On => return Ok(None),
        Stream::Auto => {}
    }
    let declared = ply::declared(input)?;
    if stream == Stream::Auto {
        let Some(available) = memory_available() else { return Ok(None) };
        if declared.bytes.saturating_mul(MEMORY_PER_FILE_BYTE) <= available {
            return Ok(None);
        }
        if !quiet {
            say!(
                "streaming: the file ({} MB) would take more than the {} MB of memory available (--stream off to read it whole)",
                declared.bytes >> 20,
                available >> 20
            );
        }
    }
    Ok(Some(declared.faces))
}

/// The memory the system can give without swapping (`MemAvailable`), in bytes; `None` where
/// it is not known (not Linux).
fn memory_available() -> Option<u64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}
