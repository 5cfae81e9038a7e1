//! Reading has bounds: a file that is not what its extension says fails at once, with little
//! memory, whatever its size; devices and FIFOs are refused without blocking. Measured on the
//! CLI in a child process, whose peak memory the kernel reports (`wait4`).

#![cfg(unix)]

mod common;

use common::scratch::Scratch;
use std::fs;
use std::io::Read;
use std::os::unix::fs::symlink;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// What a run of the CLI gave: exit code, stderr, wall time, peak resident memory in bytes.
struct Run {
    code: Option<i32>,
    stderr: String,
    seconds: f64,
    peak_bytes: u64,
}

/// Runs `vstree args`, killing it after `limit` (a hang guard, far above what any case needs).
/// The child is reaped by `wait4`, which also gives its peak memory, not by `Child::wait`.
#[allow(clippy::zombie_processes)]
fn run(args: &[&Path], limit: Duration) -> Run {
    let start = Instant::now();
    let mut child = Command::new(env!("CARGO_BIN_EXE_vstree"))
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let pid = child.id() as libc::pid_t;
    let mut stderr = child.stderr.take().unwrap();
    let reader = std::thread::spawn(move || {
        let mut text = String::new();
        stderr.read_to_string(&mut text).unwrap();
        text
    });
    let (mut status, mut usage) = (0, unsafe { std::mem::zeroed::<libc::rusage>() });
    loop {
        // SAFETY: `pid` is our child, not yet reaped; status and usage are valid out-pointers.
        let reaped = unsafe { libc::wait4(pid, &mut status, libc::WNOHANG, &mut usage) };
        assert!(reaped >= 0, "wait4 failed");
        if reaped == pid {
            break;
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            panic!("vstree {args:?} still runs after {limit:?}: it blocks or reads without a bound");
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    let code = libc::WIFEXITED(status).then(|| libc::WEXITSTATUS(status));
    // ru_maxrss is in KiB on Linux.
    Run {
        code,
        stderr: reader.join().unwrap(),
        seconds: start.elapsed().as_secs_f64(),
        peak_bytes: usage.ru_maxrss as u64 * 1024,
    }
}

#[test]
fn a_huge_file_of_zeros_fails_at_its_first_line_with_little_memory() {
    let scratch = Scratch::new("bounds-zeros");
    let output = scratch.0.join("out.ply");
    for extension in ["ply", "xyz", "off", "obj", "pwn"] {
        let input = scratch.0.join(format!("zeros.{extension}"));
        // 300 MB of zeros, sparse: nothing is written to disk.
        fs::File::create(&input).unwrap().set_len(300 << 20).unwrap();
        for command in ["simplify", "reconstruct"] {
            let got = run(&[Path::new(command), &input, &output], Duration::from_secs(20));
            assert_eq!(got.code, Some(1), "{command} {extension}: {}", got.stderr);
            let expected = if extension == "ply" {
                "line 1: not a PLY file: it must start with a `ply` line"
            } else {
                "line 1: a NUL byte: this is binary data, not a text file"
            };
            assert!(got.stderr.contains(expected), "{command} {extension}: {}", got.stderr);
            assert!(
                got.peak_bytes < 100 << 20,
                "{command} {extension}: peak memory {} MB for a file it refuses at line 1",
                got.peak_bytes >> 20
            );
            // A hang guard, not a benchmark: refusing takes milliseconds.
            assert!(got.seconds < 5.0, "{command} {extension}: {:.1} s", got.seconds);
        }
        fs::remove_file(&input).unwrap();
    }
    assert_eq!(fs::read_dir(&scratch.0).unwrap().count(), 0, "no output and no temporary file");
}

#[test]
fn devices_and_fifos_are_refused_without_blocking() {
    let scratch = Scratch::new("bounds-special");
    let output = scratch.0.join("out.ply");
    let zero = scratch.0.join("z.ply");
    symlink("/dev/zero", &zero).unwrap();
    let fifo = scratch.0.join("pipe.xyz");
    assert!(Command::new("mkfifo").arg(&fifo).status().unwrap().success());
    for (input, kind) in [(&zero, "a character device"), (&fifo, "a FIFO (named pipe)")] {
        for command in ["simplify", "reconstruct", "stats"] {
            let mut args = vec![Path::new(command), input.as_path()];
            if command != "stats" {
                args.push(&output);
            }
            let got = run(&args, Duration::from_secs(10));
            assert_eq!(got.code, Some(1), "{}", got.stderr);
            let expected = format!(
                "vstree: error: {}: {kind}, not a regular file: vstree reads meshes from regular files only\n",
                input.display()
            );
            assert_eq!(got.stderr, expected);
            assert!(got.peak_bytes < 100 << 20, "peak memory {} MB", got.peak_bytes >> 20);
        }
    }
    assert!(!output.exists());
}
