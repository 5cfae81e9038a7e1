//! Replacing a file all at once: the content goes to a temporary file next to the target, is
//! flushed and synced, and only then renamed over the target. Readers of the target see
//! either the old file or the complete new one, never a partial write.

use crate::error::{Error, Result};
use std::ffi::OsString;
use std::fs::{self, File, OpenOptions};
use std::io::{self, BufWriter};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Writes `path` by calling `fill` on a buffered temporary file, then renaming it over `path`.
/// On any error the temporary file is removed and `path` is left as it was.
pub(crate) fn replace<F>(path: &Path, fill: F) -> Result<()>
where
    F: FnOnce(&mut BufWriter<File>) -> io::Result<()>,
{
    let io_error = |e| Error::io(path, e);
    let (temp, file) = TempFile::create(path).map_err(io_error)?;
    let mut out = BufWriter::with_capacity(1 << 20, file);
    fill(&mut out).map_err(io_error)?;
    let file = out.into_inner().map_err(|e| io_error(e.into_error()))?;
    file.sync_all().map_err(io_error)?;
    drop(file);
    temp.commit(path).map_err(io_error)
}

/// The path of a temporary file, which is deleted on drop unless it was renamed into place.
struct TempFile {
    path: Option<PathBuf>,
}

impl TempFile {
    /// Creates `.<name>.tmp-<pid>-<n>` in the directory of `target`.
    fn create(target: &Path) -> io::Result<(TempFile, File)> {
        static COUNTER: AtomicU64 = AtomicU64::new(0);
        let name =
            target.file_name().ok_or_else(|| io::Error::new(io::ErrorKind::InvalidInput, "the path names no file"))?;
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let mut temp_name = OsString::from(".");
        temp_name.push(name);
        temp_name.push(format!(".tmp-{}-{n}", std::process::id()));
        let path = target.with_file_name(temp_name);
        let file = OpenOptions::new().write(true).create_new(true).open(&path)?;
        Ok((TempFile { path: Some(path) }, file))
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
        let err = replace(&target, |w| {
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
        replace(&target, |w| w.write_all(b"new")).unwrap();
        assert_eq!(fs::read_to_string(&target).unwrap(), "new");
        assert_eq!(entries(&dir), vec!["out.txt"]);
        fs::remove_dir_all(&dir).unwrap();
    }
}
