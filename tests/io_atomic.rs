//! Writes replace the target whole or not at all, and leave no temporary files behind.

mod common;

use common::scratch::Scratch;
use glam::Vec3;
use std::fs;
use std::path::Path;
use vstree::{io, Error, Mesh};

fn grid(n: u32) -> Mesh {
    let positions = (0..n * n).map(|i| Vec3::new((i % n) as f32, (i / n) as f32, 0.0)).collect();
    let mut triangles = Vec::new();
    for y in 0..n - 1 {
        for x in 0..n - 1 {
            let i = y * n + x;
            triangles.push([i, i + 1, i + n]);
            triangles.push([i + 1, i + n + 1, i + n]);
        }
    }
    Mesh::new(positions, None, triangles)
}

#[test]
fn missing_directory_is_an_io_error_and_creates_nothing() {
    let scratch = Scratch::new("io-atomic-missing");
    let target = scratch.0.join("no/such/dir/out.ply");
    let err = io::write(&target, &grid(3)).unwrap_err();
    assert!(matches!(err, Error::Io { ref path, .. } if path == &target), "{err:?}");
    assert!(!scratch.0.join("no").exists());
    assert!(scratch.names().is_empty());
}

#[test]
fn successful_writes_leave_only_the_target() {
    let scratch = Scratch::new("io-atomic-clean");
    for name in ["a.ply", "b.obj", "c.off", "d.xyz", "e.pwn"] {
        io::write(&scratch.0.join(name), &grid(4)).unwrap();
    }
    assert_eq!(scratch.names(), vec!["a.ply", "b.obj", "c.off", "d.xyz", "e.pwn"]);
}

#[test]
fn writing_over_a_file_replaces_it_whole() {
    let scratch = Scratch::new("io-atomic-replace");
    let target = scratch.0.join("m.ply");
    io::write(&target, &grid(50)).unwrap();
    let small = grid(3);
    io::write(&target, &small).unwrap();
    assert_eq!(io::read(&target).unwrap(), small);
    let fresh = scratch.0.join("fresh.ply");
    io::write(&fresh, &small).unwrap();
    assert_eq!(fs::read(&target).unwrap(), fs::read(&fresh).unwrap());
}

#[test]
fn rejected_writes_leave_the_target_untouched() {
    let scratch = Scratch::new("io-atomic-reject");
    let target = scratch.0.join("m.obj");
    fs::write(&target, "precious").unwrap();
    let mut bad = grid(3);
    bad.triangles.push([0, 1, 99]);
    assert!(matches!(io::write(&target, &bad), Err(Error::InvalidInput(_))));
    let mut nan = grid(3);
    nan.positions[4].y = f32::NAN;
    assert!(matches!(io::write(&target, &nan), Err(Error::InvalidInput(_))));
    assert!(matches!(io::write(&scratch.0.join("m.stl"), &grid(3)), Err(Error::UnsupportedFormat { .. })));
    // A directory in the way: the rename fails after the temporary file was written.
    fs::create_dir(scratch.0.join("dir.ply")).unwrap();
    fs::write(scratch.0.join("dir.ply/keep"), "x").unwrap();
    assert!(matches!(io::write(&scratch.0.join("dir.ply"), &grid(3)), Err(Error::Io { .. })));
    assert_eq!(fs::read_to_string(&target).unwrap(), "precious");
    assert_eq!(scratch.names(), vec!["dir.ply", "m.obj"]);
}

#[test]
fn reading_and_writing_the_same_file_is_safe() {
    let scratch = Scratch::new("io-atomic-inplace");
    let path = scratch.0.join("m.off");
    io::write(&path, &grid(5)).unwrap();
    let mesh = io::read(&path).unwrap();
    io::write(Path::new(&path), &mesh).unwrap();
    assert_eq!(io::read(&path).unwrap(), mesh);
}

/// The error message of a write that must fail with an I/O error.
#[cfg(unix)]
fn io_message(result: vstree::Result<()>) -> String {
    match result {
        Err(e @ Error::Io { .. }) => e.to_string(),
        other => panic!("expected an I/O error, got {other:?}"),
    }
}

#[cfg(unix)]
#[test]
fn only_regular_files_are_replaced_and_links_are_followed() {
    use std::os::unix::fs::{symlink, FileTypeExt};
    let scratch = Scratch::new("io-atomic-special");
    // A FIFO and a device stay what they are.
    let fifo = scratch.0.join("pipe.ply");
    assert!(std::process::Command::new("mkfifo").arg(&fifo).status().unwrap().success());
    let m = io_message(io::write(&fifo, &grid(3)));
    assert!(
        m.ends_with("pipe.ply: a FIFO (named pipe), not a regular file: vstree replaces regular files only"),
        "{m}"
    );
    assert!(fs::metadata(&fifo).unwrap().file_type().is_fifo());
    let null = scratch.0.join("null.ply");
    symlink("/dev/null", &null).unwrap();
    let m = io_message(io::write(&null, &grid(3)));
    assert!(m.ends_with("null.ply: a character device, not a regular file: vstree replaces regular files only"), "{m}");
    assert!(fs::metadata("/dev/null").unwrap().file_type().is_char_device());
    // A link to a file: the file is replaced, the link stays a link.
    let real = scratch.0.join("real.ply");
    fs::write(&real, "old").unwrap();
    let link = scratch.0.join("link.ply");
    symlink("real.ply", &link).unwrap();
    io::write(&link, &grid(3)).unwrap();
    assert!(fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
    assert_eq!(io::read(&real).unwrap(), grid(3));
    // A link to nothing is not written through, as cp refuses.
    let dangling = scratch.0.join("dangling.ply");
    symlink("missing/target.ply", &dangling).unwrap();
    let m = io_message(io::write(&dangling, &grid(3)));
    assert!(m.ends_with("a symbolic link to a missing file: not writing through a dangling link"), "{m}");
    assert_eq!(scratch.names(), vec!["dangling.ply", "link.ply", "null.ply", "pipe.ply", "real.ply"]);
}

#[cfg(unix)]
#[test]
fn a_replaced_file_keeps_its_permissions() {
    use std::os::unix::fs::PermissionsExt;
    let scratch = Scratch::new("io-atomic-mode");
    for mode in [0o600, 0o640, 0o755] {
        let target = scratch.0.join(format!("m{mode:o}.ply"));
        fs::write(&target, "old").unwrap();
        fs::set_permissions(&target, fs::Permissions::from_mode(mode)).unwrap();
        io::write(&target, &grid(3)).unwrap();
        assert_eq!(fs::metadata(&target).unwrap().permissions().mode() & 0o7777, mode);
    }
}

#[test]
fn a_name_of_244_characters_is_written() {
    let scratch = Scratch::new("io-atomic-long");
    let name = format!("{}.ply", "n".repeat(240));
    io::write(&scratch.0.join(&name), &grid(3)).unwrap();
    assert_eq!(scratch.names(), vec![name]);
}

/// A read-only file is refused, as `cp` refuses it: tried as an unprivileged user (through the
/// CLI run as `nobody` when the tests run as root, since root may write any file).
#[cfg(unix)]
#[test]
fn a_read_only_file_is_not_replaced_by_a_user_who_may_not_write_it() {
    use std::os::unix::fs::PermissionsExt;
    use std::os::unix::process::CommandExt;
    let scratch = Scratch::new("io-atomic-readonly");
    fs::set_permissions(&scratch.0, fs::Permissions::from_mode(0o777)).unwrap();
    let input = scratch.0.join("in.off");
    io::write(&input, &grid(20)).unwrap();
    fs::set_permissions(&input, fs::Permissions::from_mode(0o644)).unwrap();
    let target = scratch.0.join("protected.ply");
    fs::write(&target, "precious").unwrap();
    fs::set_permissions(&target, fs::Permissions::from_mode(0o444)).unwrap();
    // SAFETY: geteuid has no preconditions.
    let root = unsafe { libc::geteuid() } == 0;
    let message = if root {
        // A copy in the scratch folder: the build folder may be closed to other users.
        let binary = scratch.0.join("vstree");
        fs::copy(env!("CARGO_BIN_EXE_vstree"), &binary).unwrap();
        let run = std::process::Command::new(&binary)
            .args(["simplify".as_ref(), input.as_os_str(), target.as_os_str()])
            .uid(65534)
            .gid(65534)
            .output()
            .unwrap();
        assert_eq!(run.status.code(), Some(1));
        String::from_utf8(run.stderr).unwrap()
    } else {
        io_message(io::write(&target, &grid(3)))
    };
    assert!(
        message.contains("protected.ply: the file is read-only for this user: make it writable or remove it first"),
        "{message}"
    );
    assert_eq!(fs::read_to_string(&target).unwrap(), "precious");
    assert_eq!(fs::metadata(&target).unwrap().permissions().mode() & 0o777, 0o444);
    let _ = fs::remove_file(scratch.0.join("vstree"));
    assert_eq!(scratch.names(), vec!["in.off", "protected.ply"]);
}
