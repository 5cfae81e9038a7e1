//! Running a Python peer script (`benches/*.py`): it sets up its own virtual environment,
//! prints its progress on stderr (passed through) and one tab-separated record per line on
//! stdout, which the bench reads back.

use std::ffi::OsString;
use std::path::Path;
use std::process::{Command, Stdio};

/// Runs `python3 benches/<script> <args>` from `root` and returns its stdout records, each
/// split at tabs. Fails when the script cannot start, fails, or prints no record.
pub fn run(root: &Path, script: &str, args: &[OsString]) -> Result<Vec<Vec<String>>, String> {
    // Messages name the script as `benches/<script>`: they end up in the committed reports.
    let shown = format!("benches/{script}");
    let script = root.join("benches").join(script);
    let output = Command::new("python3")
        .arg(&script)
        .args(args)
        .stderr(Stdio::inherit())
        .output()
        .map_err(|e| format!("cannot run python3 {shown}: {e}"))?;
    if !output.status.success() {
        return Err(format!("{shown} failed ({})", output.status));
    }
    let records: Vec<Vec<String>> = String::from_utf8_lossy(&output.stdout)
        .lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| l.split('\t').map(str::to_string).collect())
        .collect();
    if records.is_empty() {
        return Err(format!("{shown} reported nothing"));
    }
    Ok(records)
}
