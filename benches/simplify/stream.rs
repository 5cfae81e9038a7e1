//! Streamed simplification of files larger than memory (issue 29, point 4): the `vstree`
//! command run as a child on generated bumpy tori of 14M, 50M and 200M triangles (written once
//! under `target/bench-simplify/stream/`, ring by ring) and on the `--large` inputs' files,
//! streamed and, where it fits, read whole; its wall time and peak resident memory (the
//! kernel's figure for the child, `wait4`), and the output's distance to the true torus.

use crate::common::report::{seconds, thousands};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;
use vstree::eval::written::{bumpy_torus_distance, write_bumpy_torus_ply};

/// The generated files `--stream` takes: name, rings, segments (triangles: twice their product).
pub const TORI: [(&str, u32, u32); 3] = [("14M", 2000, 3500), ("50M", 2500, 10_000), ("200M", 5000, 20_000)];

/// The torus's shape: circle radius, tube radius, bump (a fraction of the tube's radius).
const SHAPE: (f32, f32, f32) = (1.0, 0.3, 0.2);

/// Files read whole too when at most this large (bytes): the in-memory path's peak is about 7
/// times a binary PLY's size, and the machine has 24 GB.
const WHOLE_AT_MOST: u64 = 1 << 30;

/// One file to stream: its name in the table, its path, the target, and whether it is a torus
/// (whose output is measured against the true surface).
pub struct StreamInput {
    pub name: String,
    pub path: PathBuf,
    pub faces: usize,
    pub torus: bool,
}

/// The generated torus `name` (one of [`TORI`]), written under `dir` when absent, to be
/// simplified to 1% (at most 1M triangles).
pub fn torus(name: &str, dir: &Path) -> Result<StreamInput, String> {
    let &(_, rings, segments) =
        TORI.iter().find(|t| t.0 == name).ok_or_else(|| format!("unknown torus {name} (one of 14M, 50M, 200M)"))?;
    let path = dir.join(format!("torus-{name}.ply"));
    let triangles = 2 * rings as usize * segments as usize;
    if !path.exists() {
        eprintln!("simplify: writing the {name} torus ({} triangles)", thousands(triangles));
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        let partial = path.with_extension("ply.partial");
        let file = std::fs::File::create(&partial).map_err(|e| format!("{}: {e}", partial.display()))?;
        let mut out = std::io::BufWriter::new(file);
        let (major, minor, bump) = SHAPE;
        write_bumpy_torus_ply(&mut out, rings, segments, major, minor, bump)
            .and_then(|_| std::io::Write::flush(&mut out))
            .map_err(|e| format!("{}: {e}", partial.display()))?;
        std::fs::rename(&partial, &path).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    Ok(StreamInput {
        name: format!("bumpy torus ({name})"),
        path,
        faces: (triangles / 100).min(1_000_000),
        torus: true,
    })
}

/// One run of the command: wall seconds and peak resident bytes, or why it failed.
struct Run {
    seconds: f64,
    peak: u64,
}

/// Runs `vstree simplify` on `input` with `--stream stream`, writing `out`.
fn run_command(input: &StreamInput, stream: &str, out: &Path) -> Result<Run, String> {
    let start = Instant::now();
    let child = Command::new(env!("CARGO_BIN_EXE_vstree"))
        .args(["simplify", &input.path.to_string_lossy(), &out.to_string_lossy(), "--quiet"])
        .args(["--faces", &input.faces.to_string(), "--stream", stream])
        .spawn()
        .map_err(|e| format!("vstree: {e}"))?;
    let mut status = 0;
    // SAFETY: `usage` is a plain struct the kernel fills; the pid is our child's, waited once.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    let pid = unsafe { libc::wait4(child.id() as i32, &mut status, 0, &mut usage) };
    let seconds = start.elapsed().as_secs_f64();
    if pid <= 0 || !libc::WIFEXITED(status) || libc::WEXITSTATUS(status) != 0 {
        return Err(format!("vstree simplify --stream {stream} failed (status {status:#x})"));
    }
    Ok(Run { seconds, peak: usage.ru_maxrss as u64 * 1024 })
}

/// Mean and largest distance of `out`'s vertices to the true torus, over its diagonal.
fn torus_error(out: &Path) -> Result<(f64, f64), String> {
    let mesh = vstree::io::read(out).map_err(|e| e.to_string())?;
    let diagonal = vstree::Aabb::of(&mesh.positions).map_or(1.0, |b| b.diagonal()) as f64;
    let (major, minor, bump) = SHAPE;
    let d: Vec<f64> = mesh
        .positions
        .iter()
        .map(|&p| (p.as_dvec3() + mesh.origin).as_vec3())
        .map(|p| f64::from(bumpy_torus_distance(p, major, minor, bump)) / diagonal)
        .collect();
    Ok((d.iter().sum::<f64>() / d.len().max(1) as f64, d.iter().fold(0.0, |a: f64, &b| a.max(b))))
}

/// The table: each input streamed, and read whole when small enough.
pub fn report(inputs: &[StreamInput], dir: &Path) -> Result<String, String> {
    let mut md = String::from("### Streaming (issue 29, point 4)\n\n");
    md.push_str(
        "`vstree simplify IN.ply OUT.ply --faces N --stream on|off`, run as a child process: wall time of the \
         whole command (reading and writing included) and its peak resident memory (`wait4`), against the input \
         file's size. Streamed: three passes over the file, plain clustering. Read whole: the default, topology kept. \
         Tori: mean and largest distance of the output's vertices to the true surface, over the diagonal.\n\n",
    );
    md.push_str(
        "| input | triangles | file | target | mode | time | peak memory | peak / file | distance mean / max |\n",
    );
    md.push_str("|---|--:|--:|--:|---|--:|--:|--:|--:|\n");
    let out = dir.join("out.ply");
    for input in inputs {
        let bytes = std::fs::metadata(&input.path).map_err(|e| format!("{}: {e}", input.path.display()))?.len();
        let triangles = vstree::io::ply::declared(&input.path).map_err(|e| e.to_string())?.faces;
        for mode in ["on", "off"] {
            if mode == "off" && bytes > WHOLE_AT_MOST {
                let _ = writeln!(
                    md,
                    "| {} | {} | {} MB | {} | read whole | not run: about {} GB | | | |",
                    input.name,
                    thousands(triangles),
                    bytes >> 20,
                    thousands(input.faces),
                    (7 * bytes) >> 30
                );
                continue;
            }
            eprintln!("simplify: {} --stream {mode}", input.name);
            let run = run_command(input, mode, &out)?;
            let distance = if input.torus {
                let (mean, max) = torus_error(&out)?;
                format!("{mean:.2e} / {max:.2e}")
            } else {
                String::new()
            };
            let _ = writeln!(
                md,
                "| {} | {} | {} MB | {} | {} | {} | {} MB | {:.2} | {distance} |",
                input.name,
                thousands(triangles),
                bytes >> 20,
                thousands(input.faces),
                if mode == "on" { "streamed" } else { "read whole" },
                seconds(run.seconds),
                run.peak >> 20,
                run.peak as f64 / bytes as f64,
            );
        }
    }
    let _ = std::fs::remove_file(&out);
    md.push('\n');
    Ok(md)
}
