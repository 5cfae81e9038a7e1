//! Replacing a file all at once: the content goes to a temporary file next to the target, is
//! flushed and synced, and only then renamed over the target. Readers of the target see
//! either the old file or the complete new one, never a partial write.
//!
//! The temporary file is created when the output is reserved ([`Reserved::new`]), before the
//! work that fills it, so a folder that is missing or read-only is reported before any work.
//! What is replaced is what `cp` would write to: a symbolic link is followed to its target,
//! only regular files are replaced (never a device or a FIFO), a file the process may not
//! write is refused, and the new file keeps the old one's permissions (and its owner, where
//! the process may set it).

use super::cleanup::{self, Registration};
use super::input::file_kind;
use crate::error::{Error, Result};
use std::ffi::OsString;
use std::fs::{self, File, Metadata, OpenOptions};
use std::io::{self, BufWriter};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Longest file name most file systems allow, in bytes (`NAME_MAX` on Linux and macOS).
const NAME_MAX: usize = 255;

/// An output path with its temporary file, created and ready to fill.
pub(crate) struct Reserved {
    /// The path as the caller gave it, for messages.
    shown: PathBuf,
    /// The file that is replaced: `shown`, or what it links to.
    target: PathBuf,
    temp: TempFile,
    file: File,
}

impl Reserved {
    /// Checks `path` as an output and creates its temporary file.
    pub(crate) fn new(path: &Path) -> Result<Reserved> {
        let io_error = |e| Error::io(path, e);
        let target = follow_links(path).map_err(io_error)?;
        let existing = match fs::metadata(&target) {
            Ok(metadata) => Some(metadata),
            Err(e) if e.kind() == io::ErrorKind::NotFound => None,
            Err(e) => return Err(io_error(e)),
        };
        if let Some(metadata) = &existing {
            refuse_to_replace(&target, metadata).map_err(io_error)?;
        }
        let (temp, file) = TempFile::create(&target).map_err(io_error)?;
        if let Some(metadata) = &existing {
            keep_permissions(&file, metadata).map_err(io_error)?;
        }
        Ok(Reserved { shown: path.to_path_buf(), target, temp, file })
    }

    /// Writes the content by calling `fill` on the buffered temporary file, then renames it over
    /// the target. On any error the temporary file is removed and the target left as it was.
    pub(crate) fn fill<F>(self, fill: F) -> Result<()>
    where
        F: FnOnce(&mut BufWriter<File>) -> io::Result<()>,
    {
        let Reserved { shown, target, temp, file } = self;
        let io_error = |e| Error::io(&shown, e);
        let mut out = BufWriter::with_capacity(1 << 20, file);
        fill(&mut out).map_err(io_error)?;
        let file = out.into_inner().map_err(|e| io_error(e.into_error()))?;
        file.sync_all().map_err(io_error)?;
        drop(file);
        temp.commit(&target).map_err(io_error)
    }
}

/// Where writing to `path` writes: `path` itself, or the file its chain of symbolic links
/// ends at. A link to a missing file is refused, as `cp` does.
fn follow_links(path: &Path) -> io::Result<PathBuf> {
    match fs::symlink_metadata(path) {
        Ok(metadata) if metadata.file_type().is_symlink() => fs::canonicalize(path).map_err(|e| {
            if e.kind() == io::ErrorKind::NotFound {
                io::Error::new(e.kind(), "a symbolic link to a missing file: not writing through a dangling link")
            } else {
                e
            }
        }),
        _ => Ok(path.to_path_buf()),
    }
}

/// Refuses to replace anything but a regular file the process may write.
fn refuse_to_replace(target: &Path, metadata: &Metadata) -> io::Result<()> {
    if !metadata.is_file() {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("{}, not a regular file: vstree replaces regular files only", file_kind(metadata)),
        ));
    }
    if !may_write(target) {
        return Err(io::Error::new(
            io::ErrorKind::PermissionDenied,
            "the file is read-only for this user: make it writable or remove it first (vstree does not replace it)",
        ));
    }
    Ok(())
}

/// Whether this process may write `path` (as `open` for writing would decide).
fn may_write(path: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStrExt;
        let Ok(c_path) = std::ffi::CString::new(path.as_os_str().as_bytes()) else {
            return false;
        };
        // SAFETY: `c_path` is a valid NUL-terminated string for the duration of the call.
        unsafe { libc::access(c_path.as_ptr(), libc::W_OK) == 0 }
    }
    #[cfg(not(unix))]
    {
        fs::metadata(path).is_ok_and(|m| !m.permissions().readonly())
    }
}

/// Gives the temporary file the replaced file's permissions, and its owner where allowed.
fn keep_permissions(file: &File, old: &Metadata) -> io::Result<()> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::{fchown, MetadataExt, PermissionsExt};
        // Set-user and set-group bits are kept only if the owner is too.
        let owner_kept = fchown(file, Some(old.uid()), Some(old.gid())).is_ok();
        let group_kept = owner_kept || fchown(file, None, Some(old.gid())).is_ok();
        let mut mode = old.mode() & 0o1777;
        if owner_kept && group_kept {
            mode |= old.mode() & 0o6000;
        }
        file.set_permissions(fs::Permissions::from_mode(mode))
    }
    #[cfg(not(unix))]
    {
        file.set_permissions(old.permissions())
    }
}

/// The path of a temporary file, which is deleted on drop unless it was renamed into place.
struct TempFile {
    path: Option<PathBuf>,
    /// Deletes the file if the process is interrupted (see [`cleanup`]).
    _on_signal: Registration,
}

impl TempFile {
    /// Creates `.<name>.tmp-<pid>-<n>` in the directory of `target`, the name shortened to keep
    /// within [`NAME_MAX`].
    fn create(target: &Path) -> io::Result<(TempFile, File)> {
        static COUNTER: AtomicU64 = AtomicU64::new(0);
        let name =
            target.file_name().ok_or_else(|| io::Error::new(io::ErrorKind::InvalidInput, "the path names no file"))?;
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let suffix = format!(".tmp-{}-{n}", std::process::id());
        let path = target.with_file_name(temp_name(name, &suffix));
        // Registered first, so an interruption at any point after creation removes it.
        let on_signal = cleanup::register(&path);
        let file = OpenOptions::new().write(true).create_new(true).open(&path)?;
        Ok((TempFile { path: Some(path), _on_signal: on_signal }, file))
    }

    /// Renames the temporary file over `target`; from then on it is no longer deleted.
    fn commit(mut self, target: &Path) -> io::Result<()> {
        if let Some(path) = &self.path {
            fs::rename(path, target)?;
        }
        self.path = None;
        sync_directory(target);
        Ok(())
    }
}

impl Drop for TempFile {
    fn drop(&mut self) {
        if let Some(path) = &self.path {
            let _ = fs::remove_file(path);
        }
    }
}

/// `.<name><suffix>`, with `name` cut so that the whole stays within [`NAME_MAX`] bytes.
fn temp_name(name: &std::ffi::OsStr, suffix: &str) -> OsString {
    let room = NAME_MAX - 1 - suffix.len();
    let mut temp = OsString::from(".");
    #[cfg(unix)]
    {
        use std::os::unix::ffi::{OsStrExt, OsStringExt};
        let bytes = name.as_bytes();
        temp.push(OsString::from_vec(bytes[..bytes.len().min(room)].to_vec()));
    }
    #[cfg(not(unix))]
    {
        let name = name.to_string_lossy();
        temp.push(name.chars().take(room / 4).collect::<String>());
    }
    temp.push(suffix);
    temp
}

/// Makes the rename durable where the platform allows it; failure only weakens durability.
fn sync_directory(target: &Path) {
    #[cfg(unix)]
    if let Some(dir) = target.parent() {
        let dir = if dir.as_os_str().is_empty() { Path::new(".") } else { dir };
        if let Ok(d) = File::open(dir) {
            let _ = d.sync_all();
        }
    }
    #[cfg(not(unix))]
    let _ = target;
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("vstree-atomic-{name}-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn entries(dir: &Path) -> Vec<String> {
        let mut names: Vec<_> =
            fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
        names.sort();
        names
    }

    #[test]
    fn failed_fill_leaves_target_and_no_temp() {
        let dir = scratch("fail");
        let target = dir.join("out.txt");
        fs::write(&target, "old").unwrap();
        let err = Reserved::new(&target)
            .unwrap()
            .fill(|w| {
                w.write_all(b"partial")?;
                Err(io::Error::other("boom"))
            })
            .unwrap_err();
        assert!(matches!(err, Error::Io { .. }));
        assert_eq!(fs::read_to_string(&target).unwrap(), "old");
        assert_eq!(entries(&dir), vec!["out.txt"]);
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn success_replaces_whole_file() {
        let dir = scratch("ok");
        let target = dir.join("out.txt");
        fs::write(&target, "a much longer old content").unwrap();
        Reserved::new(&target).unwrap().fill(|w| w.write_all(b"new")).unwrap();
        assert_eq!(fs::read_to_string(&target).unwrap(), "new");
        assert_eq!(entries(&dir), vec!["out.txt"]);
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn temporary_names_keep_within_name_max() {
        let long = "n".repeat(250);
        let name = temp_name(std::ffi::OsStr::new(&long), ".tmp-4194304-18446744073709551615");
        assert_eq!(name.len(), NAME_MAX);
        assert!(name.to_string_lossy().starts_with(".nnn") && name.to_string_lossy().ends_with("551615"));
        assert_eq!(temp_name(std::ffi::OsStr::new("a.ply"), ".tmp-1-0"), ".a.ply.tmp-1-0");
    }
}
