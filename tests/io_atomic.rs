//! Writes replace the target whole or not at all, and leave no temporary files behind.

use glam::Vec3;
use std::fs;
use std::path::{Path, PathBuf};
use vstree::{io, Error, Mesh};

/// A directory under the system temp dir, removed on drop.
struct Scratch(PathBuf);

impl Scratch {
    fn new(tag: &str) -> Scratch {
        let dir = std::env::temp_dir().join(format!("vstree-io-{tag}-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).unwrap();
        Scratch(dir)
    }

    fn names(&self) -> Vec<String> {
        let mut names: Vec<String> =
            fs::read_dir(&self.0).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
        names.sort();
        names
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = fs::remove_dir_all(&self.0);
    }
}

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
    Mesh { positions, normals: None, triangles }
}

#[test]
fn missing_directory_is_an_io_error_and_creates_nothing() {
    let scratch = Scratch::new("atomic-missing");
    let target = scratch.0.join("no/such/dir/out.ply");
    let err = io::write(&target, &grid(3)).unwrap_err();
    assert!(matches!(err, Error::Io { ref path, .. } if path == &target), "{err:?}");
    assert!(!scratch.0.join("no").exists());
    assert!(scratch.names().is_empty());
}

#[test]
fn successful_writes_leave_only_the_target() {
    let scratch = Scratch::new("atomic-clean");
    for name in ["a.ply", "b.obj", "c.off", "d.xyz", "e.pwn"] {
        io::write(&scratch.0.join(name), &grid(4)).unwrap();
    }
    assert_eq!(scratch.names(), vec!["a.ply", "b.obj", "c.off", "d.xyz", "e.pwn"]);
}

#[test]
fn writing_over_a_file_replaces_it_whole() {
    let scratch = Scratch::new("atomic-replace");
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
    let scratch = Scratch::new("atomic-reject");
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
    let scratch = Scratch::new("atomic-inplace");
    let path = scratch.0.join("m.off");
    io::write(&path, &grid(5)).unwrap();
    let mesh = io::read(&path).unwrap();
    io::write(Path::new(&path), &mesh).unwrap();
    assert_eq!(io::read(&path).unwrap(), mesh);
}
