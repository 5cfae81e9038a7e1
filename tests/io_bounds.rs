//! Reading has bounds: a file that is not what its extension says fails at once, with little
//! memory, whatever its size; devices and FIFOs are refused without blocking; a PLY file is
//! read up to the end of the elements its header declares, and no further. Measured on the
//! CLI in a child process, whose peak memory the kernel reports (`wait4`), and in this
//! process by an allocator that keeps the peak of the bytes allocated.

#![cfg(unix)]

mod common;

use common::scratch::Scratch;
use std::fs;
use std::io::Read;
use std::os::unix::fs::symlink;
use std::path::Path;
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

/// The system allocator, counting the bytes allocated now and their peak.
struct Counting;

static ALLOCATED: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

// SAFETY: every call is passed on to the system allocator unchanged; only counts are added.
unsafe impl std::alloc::GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: std::alloc::Layout) -> *mut u8 {
        let p = std::alloc::System.alloc(layout);
        if !p.is_null() {
            let now = ALLOCATED.fetch_add(layout.size(), Ordering::Relaxed) + layout.size();
            PEAK.fetch_max(now, Ordering::Relaxed);
        }
        p
    }

    unsafe fn dealloc(&self, p: *mut u8, layout: std::alloc::Layout) {
        std::alloc::System.dealloc(p, layout);
        ALLOCATED.fetch_sub(layout.size(), Ordering::Relaxed);
    }
}

#[global_allocator]
static COUNTING: Counting = Counting;

/// What `f` returns, and the most bytes allocated meanwhile beyond those allocated before.
fn peak_allocation<T>(f: impl FnOnce() -> T) -> (T, usize) {
    let before = ALLOCATED.load(Ordering::Relaxed);
    PEAK.store(before, Ordering::Relaxed);
    let result = f();
    (result, PEAK.load(Ordering::Relaxed).saturating_sub(before))
}

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

#[test]
fn a_ply_file_is_read_up_to_its_declared_elements_whatever_follows() {
    let scratch = Scratch::new("bounds-tail");
    let mesh = vstree::eval::shapes::icosphere(1.0, 4);
    let tail = 2u64 << 30;
    // A complete binary PLY followed by 2 GiB of zeros (sparse: nothing is written to disk):
    // read, and the tail ignored without being read.
    let binary = scratch.0.join("tail.ply");
    vstree::io::write(&binary, &mesh).unwrap();
    let file = fs::OpenOptions::new().write(true).open(&binary).unwrap();
    file.set_len(file.metadata().unwrap().len() + tail).unwrap();
    let (read, peak) = peak_allocation(|| vstree::io::read(&binary));
    assert_eq!(read.unwrap(), mesh);
    assert!(peak < 16 << 20, "peak allocation {} MB for a 1 MB mesh", peak >> 20);
    // An ASCII header followed by 2 GiB of zeros: refused at the first byte of the body.
    let ascii = scratch.0.join("zeros.ply");
    let header = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                  property float z\nend_header\n";
    fs::write(&ascii, header).unwrap();
    fs::OpenOptions::new().write(true).open(&ascii).unwrap().set_len(header.len() as u64 + tail).unwrap();
    let (read, peak) = peak_allocation(|| vstree::io::read(&ascii));
    let expected = format!(
        "{}: line 8: vertex 0: byte 0x00: this is binary data, but the header says `format ascii`",
        ascii.display()
    );
    assert_eq!(read.unwrap_err().to_string(), expected);
    assert!(peak < 16 << 20, "peak allocation {} MB for a file refused at line 8", peak >> 20);
}
