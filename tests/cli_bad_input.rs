//! The `vstree` command on bad input, as a table: every case runs in a fresh folder and must
//! end with the exit code and the message it pins, print nothing on stdout when it fails, and
//! leave the folder as it found it (no output, no hidden `.NAME.tmp-*` file). All cases run,
//! then the test fails listing every case that did not behave.

use glam::Vec3;
use std::collections::BTreeSet;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};
use vstree::{eval::shapes, io, Mesh};

/// Longer than any case needs; a case still running then is a hang.
const TIMEOUT: Duration = Duration::from_secs(10);

/// What a case puts in its folder before the run.
enum Entry {
    /// A file with these bytes.
    Bytes(Vec<u8>),
    /// A mesh or cloud written by `vstree::io`, in the format its name gives.
    Mesh(Mesh),
    Dir,
    Fifo,
    /// A symbolic link to this target.
    Link(&'static str),
}

enum Stderr {
    Exact(String),
    /// Each of these strings occurs in stderr.
    Contains(Vec<String>),
}

struct Case {
    name: &'static str,
    files: Vec<(String, Entry)>,
    /// Run in the case's folder, so paths (and messages) are relative.
    args: Vec<String>,
    code: i32,
    stderr: Stderr,
    /// Whether stdout must be empty.
    quiet_stdout: bool,
    /// The file a successful run adds to the folder.
    creates: Option<String>,
}

fn exact(text: &str) -> Stderr {
    Stderr::Exact(text.to_string())
}

/// The CLI's own error line.
fn error(text: &str) -> Stderr {
    Stderr::Exact(format!("vstree: error: {text}\n"))
}

/// A usage error from the argument parser, with its usual hint.
fn usage_error(text: &str) -> Stderr {
    Stderr::Exact(format!("error: {text}\n\nFor more information, try '--help'.\n"))
}

fn contains(parts: &[&str]) -> Stderr {
    Stderr::Contains(parts.iter().map(|s| s.to_string()).collect())
}

fn file(name: &str, entry: Entry) -> (String, Entry) {
    (name.to_string(), entry)
}

fn text(name: &str, content: &str) -> (String, Entry) {
    file(name, Entry::Bytes(content.as_bytes().to_vec()))
}

/// A failing run (exit 1) with stdout empty.
fn fail(name: &'static str, files: Vec<(String, Entry)>, args: &[&str], stderr: Stderr) -> Case {
    Case {
        name,
        files,
        args: args.iter().map(|s| s.to_string()).collect(),
        code: 1,
        stderr,
        quiet_stdout: true,
        creates: None,
    }
}

/// Refused by the argument parser (exit 2).
fn usage(name: &'static str, files: Vec<(String, Entry)>, args: &[&str], stderr: Stderr) -> Case {
    Case { code: 2, ..fail(name, files, args, stderr) }
}

/// A small closed mesh (642 vertices, 1280 triangles).
fn sphere() -> Mesh {
    shapes::icosphere(1.0, 3)
}

/// A cloud with normals drawn on the sphere.
fn cloud() -> Mesh {
    shapes::sample_surface(&sphere(), 2000, 1)
}

fn sphere_ply() -> (String, Entry) {
    file("in.ply", Entry::Mesh(sphere()))
}

fn cloud_ply() -> (String, Entry) {
    file("cloud.ply", Entry::Mesh(cloud()))
}

/// The cloud without normals, as text: reconstruction must estimate them.
fn bare_cloud() -> (String, Entry) {
    let mut cloud = cloud();
    cloud.normals = None;
    file("bare.xyz", Entry::Mesh(cloud))
}

fn points(positions: Vec<Vec3>) -> Mesh {
    let n = positions.len();
    Mesh::from_points(positions, Some(vec![Vec3::Z; n]))
}

fn cases() -> Vec<Case> {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let simplify_with = |extra: &[&'static str]| -> Vec<&'static str> {
        let mut all = vec!["simplify", "in.ply", "out.ply"];
        all.extend_from_slice(extra);
        all
    };
    let reconstruct_with = |extra: &[&'static str]| -> Vec<&'static str> {
        let mut all = vec!["reconstruct", "cloud.ply", "out.ply"];
        all.extend_from_slice(extra);
        all
    };
    let stats_with = |extra: &[&'static str]| -> Vec<&'static str> {
        let mut all = vec!["stats", "in.ply"];
        all.extend_from_slice(extra);
        all
    };
    let zeros = || Entry::Bytes(vec![0; 4096]);
    let binary_ply = {
        let dir = std::env::temp_dir().join(format!("vstree-cli-bad-binary-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("b.ply");
        io::write(&path, &sphere()).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
        bytes
    };
    let truncated = binary_ply[..binary_ply.len() / 2].to_vec();
    let plane: Vec<Vec3> = (0..900).map(|i| Vec3::new((i % 30) as f32, (i / 30) as f32, 0.0)).collect();
    let line: Vec<Vec3> = (0..500).map(|i| Vec3::new(i as f32, 0.0, 0.0)).collect();
    let long_name = format!("{}.ply", "a".repeat(240));
    let mut rng = vstree::rng::Rng::new(1);
    let scattered: String = (0..10).map(|_| format!("{} {} {}\n", rng.f32(), rng.f32(), rng.f32())).collect();

    let mut cases = vec![
        // --error, on every command.
        fail("simplify --error -1", vec![sphere_ply()], &simplify_with(&["--error", "-1"]), error("--error: -1: must be a finite number > 0")),
        fail("simplify --error 0", vec![sphere_ply()], &simplify_with(&["--error", "0"]), error("--error: 0: must be a finite number > 0")),
        fail("simplify --error NaN", vec![sphere_ply()], &simplify_with(&["--error", "NaN"]), error("--error: NaN: must be a finite number > 0")),
        fail("simplify --error inf", vec![sphere_ply()], &simplify_with(&["--error", "inf"]), error("--error: inf: must be a finite number > 0")),
        usage("simplify --error abc", vec![sphere_ply()], &simplify_with(&["--error", "abc"]), usage_error("invalid value 'abc' for '--error <ERROR>': invalid float literal")),
        usage("simplify --error ''", vec![sphere_ply()], &simplify_with(&["--error", ""]), usage_error("invalid value '' for '--error <ERROR>': cannot parse float from empty string")),
        fail(
            "simplify --metric l21 --error 5",
            vec![sphere_ply()],
            &simplify_with(&["--metric", "l21", "--error", "5"]),
            error("--error: 5: the L2,1 bound must be in (0, 4]"),
        ),
        fail(
            "simplify --metric density --error 0.5",
            vec![sphere_ply()],
            &simplify_with(&["--metric", "density", "--error", "0.5"]),
            error("--error: 0.5 samples per cell: must be at least 1"),
        ),
        fail("stats --error -1", vec![sphere_ply()], &stats_with(&["--error", "-1"]), error("--error: -1: must be a finite number > 0")),
        fail("reconstruct --error nan", vec![cloud_ply()], &reconstruct_with(&["--error", "nan"]), error("--error: NaN: must be a finite number > 0")),
        // --da and --dd outside [0, 1].
        // Negative values, with `=` or a space, reach the range checks.
        fail("simplify --da=-0.1", vec![sphere_ply()], &simplify_with(&["--da=-0.1"]), error("--da: -0.1: must be in [0, 1]")),
        fail("simplify --da -0.1", vec![sphere_ply()], &simplify_with(&["--da", "-0.1"]), error("--da: -0.1: must be in [0, 1]")),
        fail("reconstruct --trim -1", vec![cloud_ply()], &reconstruct_with(&["--trim", "-1"]), error("--trim: -1: must be a finite number >= 0")),
        fail("simplify --da 1.5", vec![sphere_ply()], &simplify_with(&["--da", "1.5"]), error("--da: 1.5: must be in [0, 1]")),
        fail("simplify --dd=-1", vec![sphere_ply()], &simplify_with(&["--dd=-1"]), error("--dd: -1: must be in [0, 1]")),
        fail("simplify --dd 2", vec![sphere_ply()], &simplify_with(&["--dd", "2"]), error("--dd: 2: must be in [0, 1]")),
        fail("stats --dd NaN", vec![sphere_ply()], &stats_with(&["--dd", "NaN"]), error("--dd: NaN: must be in [0, 1]")),
        usage("simplify --da x", vec![sphere_ply()], &simplify_with(&["--da", "x"]), usage_error("invalid value 'x' for '--da <DA>': invalid float literal")),
        // Depth, cell size, threads.
        fail("simplify --max-depth 0", vec![sphere_ply()], &simplify_with(&["--max-depth", "0"]), error("--max-depth: 0: must be from 1 to 30")),
        fail("simplify --max-depth 31", vec![sphere_ply()], &simplify_with(&["--max-depth", "31"]), error("--max-depth: 31: must be from 1 to 30")),
        fail("simplify --max-depth=-1", vec![sphere_ply()], &simplify_with(&["--max-depth=-1"]), error("--max-depth: -1: must be from 1 to 30")),
        fail(
            "simplify --min-cell-size 1",
            vec![sphere_ply()],
            &simplify_with(&["--min-cell-size", "1"]),
            error("--min-cell-size: 1: must be in [0, 1)"),
        ),
        fail(
            "simplify --min-cell-size=-1",
            vec![sphere_ply()],
            &simplify_with(&["--min-cell-size=-1"]),
            error("--min-cell-size: -1: must be in [0, 1)"),
        ),
        fail("simplify --threads 2000", vec![sphere_ply()], &simplify_with(&["--threads", "2000"]), contains(&["vstree: error: --threads: 2000 is absurd (0 = all cores, at most 1024)\n"])),
        fail("stats --threads 2000", vec![sphere_ply()], &stats_with(&["--threads", "2000"]), contains(&["vstree: error: --threads: 2000 is absurd (0 = all cores, at most 1024)\n"])),
        fail("simplify --threads=-1", vec![sphere_ply()], &simplify_with(&["--threads=-1"]), error("--threads: -1: must be from 0 (all cores) to 1024")),
        usage("stats --threads x", vec![sphere_ply()], &stats_with(&["--threads", "x"]), usage_error("invalid value 'x' for '--threads <THREADS>': invalid digit found in string")),
        // Reconstruction's own flags.
        fail("reconstruct --levels 13", vec![cloud_ply()], &reconstruct_with(&["--levels", "13"]), error("--levels: 13: must be from 0 to 12")),
        fail("reconstruct --target=-1", vec![cloud_ply()], &reconstruct_with(&["--target=-1"]), error("--target: -1: must be a finite number >= 0")),
        fail("reconstruct --trim=-1", vec![cloud_ply()], &reconstruct_with(&["--trim=-1"]), error("--trim: -1: must be a finite number >= 0")),
        fail("reconstruct --target inf", vec![cloud_ply()], &reconstruct_with(&["--target", "inf"]), error("--target: inf: must be a finite number >= 0")),
        fail("reconstruct --trim NaN", vec![cloud_ply()], &reconstruct_with(&["--trim", "NaN"]), error("--trim: NaN: must be a finite number >= 0")),
        // Checked even when the cloud's own normals are kept and none are estimated.
        fail("reconstruct --neighbours 2 with normals", vec![cloud_ply()], &reconstruct_with(&["--neighbours", "2"]), error("--neighbours: 2: must be from 3 to 256")),
        fail(
            "reconstruct --neighbours 2",
            vec![bare_cloud()],
            &["reconstruct", "bare.xyz", "out.ply", "--neighbours", "2"],
            error("--neighbours: 2: must be from 3 to 256"),
        ),
        fail(
            "reconstruct --neighbours 300",
            vec![bare_cloud()],
            &["reconstruct", "bare.xyz", "out.ply", "--neighbours", "300"],
            error("--neighbours: 300: must be from 3 to 256"),
        ),
        usage(
            "reconstruct --levels x",
            vec![cloud_ply()],
            &reconstruct_with(&["--levels", "x"]),
            usage_error("invalid value 'x' for '--levels <LEVELS>': invalid digit found in string"),
        ),
        // Unknown values, unknown flags, missing arguments.
        // Sizes: a count the input has, a ratio in (0, 1], one way to ask, meshes only.
        fail("simplify --faces 1281", vec![sphere_ply()], &simplify_with(&["--faces", "1281"]), error("--faces: 1281: more than the input's 1280 triangles")),
        fail("simplify --faces -5", vec![sphere_ply()], &simplify_with(&["--faces", "-5"]), error("--faces: -5: must be a triangle count >= 1 (0 = use --error)")),
        usage("simplify --faces x", vec![sphere_ply()], &simplify_with(&["--faces", "x"]), usage_error("invalid value 'x' for '--faces <FACES>': invalid digit found in string")),
        fail("simplify --ratio 0", vec![sphere_ply()], &simplify_with(&["--ratio", "0"]), error("--ratio: 0: must be in (0, 1], a fraction of the input's triangles")),
        fail("simplify --ratio 1.5", vec![sphere_ply()], &simplify_with(&["--ratio", "1.5"]), error("--ratio: 1.5: must be in (0, 1], a fraction of the input's triangles")),
        fail("simplify --ratio -0.1", vec![sphere_ply()], &simplify_with(&["--ratio", "-0.1"]), error("--ratio: -0.1: must be in (0, 1], a fraction of the input's triangles")),
        fail("simplify --ratio NaN", vec![sphere_ply()], &simplify_with(&["--ratio", "NaN"]), error("--ratio: NaN: must be in (0, 1], a fraction of the input's triangles")),
        usage("simplify --faces --ratio", vec![sphere_ply()], &simplify_with(&["--faces", "100", "--ratio", "0.1"]), usage_error("the argument '--faces <FACES>' cannot be used with '--ratio <RATIO>'\n\nUsage: vstree simplify --faces <FACES> <INPUT> <OUTPUT>")),
        usage("simplify --faces --error", vec![sphere_ply()], &simplify_with(&["--faces", "100", "--error", "1e-3"]), usage_error("the argument '--faces <FACES>' cannot be used with '--error <ERROR>'\n\nUsage: vstree simplify --faces <FACES> <INPUT> <OUTPUT>")),
        usage("simplify --ratio --error", vec![sphere_ply()], &simplify_with(&["--ratio", "0.1", "--error", "1e-3"]), usage_error("the argument '--ratio <RATIO>' cannot be used with '--error <ERROR>'\n\nUsage: vstree simplify --ratio <RATIO> <INPUT> <OUTPUT>")),
        usage("simplify --keep-topology --no-keep-topology", vec![sphere_ply()], &simplify_with(&["--keep-topology", "--no-keep-topology"]), usage_error("the argument '--keep-topology' cannot be used with '--no-keep-topology'\n\nUsage: vstree simplify --keep-topology <INPUT> <OUTPUT>")),
        fail("simplify a cloud --faces 10", vec![cloud_ply()], &["simplify", "cloud.ply", "out.ply", "--faces", "10"], error("--faces: 10 triangles asked of a point cloud: a target needs a mesh (use the error bound)")),
        usage("simplify --tree bsp", vec![sphere_ply()], &simplify_with(&["--tree", "bsp"]), usage_error("invalid value 'bsp' for '--tree <TREE>'\n  [possible values: vstree, octree]")),
        usage("simplify --metric l3", vec![sphere_ply()], &simplify_with(&["--metric", "l3"]), usage_error("invalid value 'l3' for '--metric <METRIC>'\n  [possible values: l2, l21, density]")),
        usage(
            "simplify --sampling edges",
            vec![sphere_ply()],
            &simplify_with(&["--sampling", "edges"]),
            usage_error("invalid value 'edges' for '--sampling <SAMPLING>'\n  [possible values: vertices, faces]"),
        ),
        usage("stats --compare=yes", vec![sphere_ply()], &stats_with(&["--compare=yes"]), usage_error("unexpected value 'yes' for '--compare' found; no more were expected\n\nUsage: vstree stats --compare <INPUT>")),
        usage("simplify --ascii=1", vec![sphere_ply()], &simplify_with(&["--ascii=1"]), usage_error("unexpected value '1' for '--ascii' found; no more were expected\n\nUsage: vstree simplify --ascii <INPUT> <OUTPUT>")),
        usage("simplify --error without value", vec![sphere_ply()], &simplify_with(&["--error"]), usage_error("a value is required for '--error <ERROR>' but none was supplied")),
        usage("simplify --frobnicate", vec![sphere_ply()], &simplify_with(&["--frobnicate"]), usage_error("unexpected argument '--frobnicate' found\n\n  tip: to pass '--frobnicate' as a value, use '-- --frobnicate'\n\nUsage: vstree simplify <INPUT> <OUTPUT>")),
        usage("simplify without output", vec![sphere_ply()], &["simplify", "in.ply"], usage_error("the following required arguments were not provided:\n  <OUTPUT>\n\nUsage: vstree simplify <INPUT> <OUTPUT>")),
        usage("simplify without arguments", vec![], &["simplify"], usage_error("the following required arguments were not provided:\n  <INPUT>\n  <OUTPUT>\n\nUsage: vstree simplify <INPUT> <OUTPUT>")),
        usage("reconstruct without output", vec![cloud_ply()], &["reconstruct", "cloud.ply"], usage_error("the following required arguments were not provided:\n  <OUTPUT>\n\nUsage: vstree reconstruct <INPUT> <OUTPUT>")),
        usage("stats without input", vec![], &["stats"], usage_error("the following required arguments were not provided:\n  <INPUT>\n\nUsage: vstree stats <INPUT>")),
        usage("stats with two inputs", vec![sphere_ply()], &["stats", "in.ply", "in.ply"], usage_error("unexpected argument 'in.ply' found\n\nUsage: vstree stats [OPTIONS] <INPUT>")),
        usage("no subcommand", vec![], &[], contains(&["Usage: vstree <COMMAND>", "simplify", "reconstruct", "stats", "demo"])),
        usage("unknown subcommand", vec![], &["smooth", "in.ply"], usage_error("unrecognized subcommand 'smooth'\n\nUsage: vstree <COMMAND>")),
        usage("demo with a positional argument", vec![], &["demo", "out"], usage_error("unexpected argument 'out' found\n\nUsage: vstree demo [OPTIONS]")),
        fail("demo --out is a file", vec![text("taken", "x")], &["demo", "--out", "taken"], error("taken: exists and is not a folder: name a folder for --out")),
        // Input problems.
        fail("missing input", vec![], &["simplify", "missing.ply", "out.ply"], error("missing.ply: No such file or directory (os error 2)")),
        fail("input is a directory", vec![file("dir.ply", Entry::Dir)], &["simplify", "dir.ply", "out.ply"], error("dir.ply: a directory, not a regular file: vstree reads meshes from regular files only")),
        fail(
            "unsupported input extension",
            vec![text("in.stl", "solid x\nendsolid x\n")],
            &["simplify", "in.stl", "out.ply"],
            error("in.stl: unsupported file format (expected .ply, .obj, .off, .xyz or .pwn)"),
        ),
        fail(
            "input without extension",
            vec![text("in", "0 0 0\n")],
            &["simplify", "in", "out.ply"],
            error("in: unsupported file format (expected .ply, .obj, .off, .xyz or .pwn)"),
        ),
        fail("empty .ply", vec![text("e.ply", "")], &["simplify", "e.ply", "out.ply"], error("e.ply: line 1: file is empty")),
        fail("empty .xyz", vec![text("e.xyz", "")], &["stats", "e.xyz"], error("e.xyz: line 1: file is empty")),
        fail("whitespace-only .xyz", vec![text("w.xyz", " \n\t\n\n")], &["stats", "w.xyz"], error("w.xyz: line 1: file is empty")),
        fail("whitespace-only .off", vec![text("w.off", " \n\t\n\n")], &["stats", "w.off"], error("w.off: line 1: file is empty")),
        fail("zeros named .ply", vec![file("z.ply", zeros())], &["stats", "z.ply"], error("z.ply: line 1: not a PLY file: it must start with a `ply` line")),
        fail("zeros named .xyz", vec![file("z.xyz", zeros())], &["stats", "z.xyz"], error("z.xyz: line 1: a NUL byte: this is binary data, not a text file")),
        fail("zeros named .off", vec![file("z.off", zeros())], &["stats", "z.off"], error("z.off: line 1: a NUL byte: this is binary data, not a text file")),
        fail("zeros named .obj", vec![file("z.obj", zeros())], &["stats", "z.obj"], error("z.obj: line 1: a NUL byte: this is binary data, not a text file")),
        fail(
            "malformed PLY header",
            vec![text("h.ply", "ply\nformat ascii 1.0\nelement vertex abc\nproperty float x\nend_header\n")],
            &["stats", "h.ply"],
            error("h.ply: line 3: element count `abc` is not a number"),
        ),
        fail(
            "PLY without end_header",
            vec![text("h.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n")],
            &["stats", "h.ply"],
            error("h.ply: header: file ends before `end_header`"),
        ),
        fail(
            "OFF with fewer vertices than its counts",
            vec![text("c.off", "OFF\n5 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")],
            &["stats", "c.off"],
            error("c.off: line 6: file ends after 4 of the 5 vertices"),
        ),
        fail(
            "OFF with non-numeric counts",
            vec![text("c.off", "OFF\nthree 1 0\n")],
            &["stats", "c.off"],
            error("c.off: line 2: expected a number, found `three`"),
        ),
        fail(
            "OBJ face index out of range",
            vec![text("f.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n")],
            &["stats", "f.obj"],
            error("f.obj: line 4: vertex index 9 is out of range: the file has 3 `v` lines"),
        ),
        fail(
            "OBJ face with 2 corners",
            vec![text("f.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n")],
            &["stats", "f.obj"],
            error("f.obj: line 4: a face with 2 corners: a face needs at least 3 (a line is written with `l`)"),
        ),
        fail("XYZ with 2 columns", vec![text("p.xyz", "0 0\n1 1\n2 2\n")], &["stats", "p.xyz"], error("p.xyz: line 1: expected 3 or 6 numbers (x y z [nx ny nz]), found 2")),
        fail(
            "NaN coordinate in XYZ",
            vec![text("n.xyz", "0 0 0\n1 0 0\nnan 0 0\n0 1 0\n")],
            &["stats", "n.xyz"],
            error("n.xyz: line 3: point 2: has a NaN or infinite coordinate (NaN, 0, 0)"),
        ),
        fail(
            "NaN coordinate in OFF",
            vec![text("n.off", "OFF\n3 1 0\n0 0 0\n1 NaN 0\n0 1 0\n3 0 1 2\n")],
            &["simplify", "n.off", "out.ply"],
            error("n.off: line 4: vertex 1: has a NaN or infinite coordinate (1, NaN, 0)"),
        ),
        fail(
            "coordinate 3e18",
            vec![text("far.xyz", "0 0 0 0 0 1\n3e18 0 0 0 0 1\n0 1 0 0 0 1\n0 0 1 0 0 1\n")],
            &["simplify", "far.xyz", "out.ply"],
            error("far.xyz: line 2: point 1: has a coordinate of 3e18: at most 1e18 in magnitude is supported (32-bit geometry); rescale the input"),
        ),
        fail(
            "truncated binary PLY",
            vec![file("t.ply", Entry::Bytes(truncated))],
            &["simplify", "t.ply", "out.ply"],
            error("t.ply: face 37: file ends after 37 of the 1280 `face` elements"),
        ),
        fail("FIFO input", vec![file("fifo.ply", Entry::Fifo)], &["simplify", "fifo.ply", "out.ply"], error("fifo.ply: a FIFO (named pipe), not a regular file: vstree reads meshes from regular files only")),
        fail("symlink to /dev/zero", vec![file("z.ply", Entry::Link("/dev/zero"))], &["stats", "z.ply"], error("z.ply: a character device, not a regular file: vstree reads meshes from regular files only")),
        fail(
            "reconstruct from a FIFO",
            vec![file("fifo.xyz", Entry::Fifo)],
            &["reconstruct", "fifo.xyz", "out.ply"],
            error("fifo.xyz: a FIFO (named pipe), not a regular file: vstree reads meshes from regular files only"),
        ),
        // Output problems.
        fail("unsupported output extension", vec![sphere_ply()], &["simplify", "in.ply", "out.stl"], error("out.stl: unsupported file format (expected .ply, .obj, .off, .xyz or .pwn)")),
        fail("output without extension", vec![sphere_ply()], &["simplify", "in.ply", "out"], error("out: unsupported file format (expected .ply, .obj, .off, .xyz or .pwn)")),
        fail("output is the input", vec![sphere_ply()], &["simplify", "in.ply", "in.ply"], error("invalid input: the output in.ply is the input file: write the result to another file")),
        fail(
            "output is a link to the input",
            vec![sphere_ply(), file("link.ply", Entry::Link("in.ply"))],
            &["simplify", "in.ply", "link.ply"],
            error("invalid input: the output link.ply is the input file: write the result to another file"),
        ),
        fail(
            "reconstruct onto its input",
            vec![cloud_ply()],
            &["reconstruct", "cloud.ply", "./cloud.ply"],
            error("invalid input: the output ./cloud.ply is the input file: write the result to another file"),
        ),
        fail("output into a missing folder", vec![sphere_ply()], &["simplify", "in.ply", "no/out.ply"], error("no/out.ply: No such file or directory (os error 2)")),
        fail(
            "output is a directory",
            vec![sphere_ply(), file("out.ply", Entry::Dir)],
            &simplify_with(&[]),
            error("out.ply: a directory, not a regular file: vstree replaces regular files only"),
        ),
        fail("output is a FIFO", vec![sphere_ply(), file("out.ply", Entry::Fifo)], &simplify_with(&[]), error("out.ply: a FIFO (named pipe), not a regular file: vstree replaces regular files only")),
        fail(
            "output is a link to /dev/null",
            vec![sphere_ply(), file("out.ply", Entry::Link("/dev/null"))],
            &simplify_with(&[]),
            error("out.ply: a character device, not a regular file: vstree replaces regular files only"),
        ),
        fail(
            "output through a dangling link",
            vec![sphere_ply(), file("out.ply", Entry::Link("gone/target.ply"))],
            &simplify_with(&[]),
            error("out.ply: a symbolic link to a missing file: not writing through a dangling link"),
        ),
        // Runs whose result would be wrong.
        fail(
            "simplify --error 100 collapses every triangle",
            vec![sphere_ply()],
            &simplify_with(&["--error", "100", "--no-keep-topology", "-q"]),
            error("--error: 100: every triangle collapsed (1 cluster for the whole model): the model is within this bound of too few planes; use a smaller bound (a flat model, within any bound of one plane, needs the density metric)"),
        ),
        fail("reconstruct --tree octree", vec![cloud_ply()], &reconstruct_with(&["--tree", "octree"]), error("--tree: octree: reconstruction needs the VS-Tree, whose T-nodes make the base mesh (the octree is for simplification)")),
        fail("reconstruct --max-depth 1", vec![cloud_ply()], &reconstruct_with(&["--max-depth", "1", "-q"]), error("--max-depth: 1: the tree reached this depth before any cell saw the surface as a height field, so there is nothing to make the base mesh from; allow a deeper tree (default 24)")),
        // At these ends no cell passes the height-field test: refused before the work.
        fail("reconstruct --da 1", vec![cloud_ply()], &reconstruct_with(&["--da", "1", "-q"]), error("--da: 1: the height-field test (every normal's dot product with the cell's mean normal above d_a) can never hold, so no cell becomes a T-node and there is no base mesh; reconstruction needs d_a below 1 (default 0)")),
        fail("reconstruct --dd 0", vec![cloud_ply()], &reconstruct_with(&["--dd", "0", "-q"]), error("--dd: 0: the height-field test (every sample's height over the cell's plane below d_d times the cell's radius) can never hold, so no cell becomes a T-node and there is no base mesh; reconstruction needs d_d above 0 (default 0.1667)")),
        fail(
            "reconstruct ten scattered points",
            vec![text("scattered.xyz", &scattered)],
            &["reconstruct", "scattered.xyz", "out.ply", "-q"],
            contains(&["vstree: error: invalid input: ", "(10 points, normals estimated: too few or too scattered to sample a surface, or normals that do not face one way)\n"]),
        ),
        fail("reconstruct --error 1e300", vec![cloud_ply()], &reconstruct_with(&["--error", "1e300", "-q"]), error("--error: 1e300: the cloud fits this bound in 1 octree cell too coarse to see the surface as a height field, so there is nothing to make the base mesh from; use a smaller bound (default 1e-5)")),
        fail(
            "reconstruct a flat plane",
            vec![file("cloud.ply", Entry::Mesh(points(plane)))],
            &reconstruct_with(&["-q"]),
            error("invalid input: all 900 points lie in one plane (thickness 0 of the cloud's extent): they enclose no volume, so there is no closed surface to reconstruct"),
        ),
        fail(
            "reconstruct identical points",
            vec![file("cloud.ply", Entry::Mesh(points(vec![Vec3::splat(0.5); 2000])))],
            &reconstruct_with(&["-q"]),
            error("invalid input: all 2000 points are at the same place: no surface passes through them"),
        ),
        fail(
            "reconstruct collinear points",
            vec![file("cloud.ply", Entry::Mesh(points(line)))],
            &reconstruct_with(&["-q"]),
            error("invalid input: all 500 points lie on one line: no surface passes through them"),
        ),
        fail(
            "reconstruct 5 points",
            vec![file("cloud.ply", Entry::Mesh(points(vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z, Vec3::ONE])))],
            &reconstruct_with(&["-q"]),
            error("invalid input: 5 points: at least 10 are needed"),
        ),
    ];

    // Runs that succeed, with their note.
    let threads_note = if cores < 1024 {
        format!("vstree: --threads 1024: this machine runs {cores} at once; using {cores}\n")
    } else {
        String::new()
    };
    cases.push(Case {
        quiet_stdout: false,
        creates: Some("out.ply".into()),
        code: 0,
        ..fail(
            "simplify --threads 1024",
            vec![sphere_ply()],
            &simplify_with(&["--threads", "1024"]),
            exact(&threads_note),
        )
    });
    // A size the topology cannot reach: the smallest closed mesh, and a warning (not an
    // empty mesh, not an error).
    cases.push(Case {
        quiet_stdout: false,
        creates: Some("out.ply".into()),
        code: 0,
        ..fail(
            "simplify --faces 1 on a sphere gives a tetrahedron",
            vec![sphere_ply()],
            &simplify_with(&["--faces", "1", "-q"]),
            exact("vstree: warning: 4 triangles instead of the 1 asked for: fewer would change the topology (genus, borders); --no-keep-topology allows it\n"),
        )
    });
    cases.push(Case {
        quiet_stdout: false,
        creates: Some("out.ply".into()),
        code: 0,
        ..fail(
            "simplify --faces 0 uses the bound",
            vec![sphere_ply()],
            &simplify_with(&["--faces", "0", "-q"]),
            exact(""),
        )
    });
    let mut bom = b"\xEF\xBB\xBF".to_vec();
    for p in &cloud().positions {
        bom.extend_from_slice(format!("{} {} {}\n", p.x, p.y, p.z).as_bytes());
    }
    cases.push(Case {
        quiet_stdout: false,
        code: 0,
        ..fail("XYZ with a UTF-8 BOM", vec![file("bom.xyz", Entry::Bytes(bom))], &["stats", "bom.xyz", "-q"], exact(""))
    });
    let mut long = fail("244-character output name", vec![sphere_ply()], &["simplify", "in.ply"], exact(""));
    long.args.push(long_name.clone());
    long.code = 0;
    long.quiet_stdout = false;
    long.creates = Some(long_name);
    cases.push(long);
    cases.extend(flag_cases());
    // A PLY is read up to the end of the elements its header declares: a body of another kind
    // is refused at its first byte, named (never copied into the message), and a tail after
    // the elements is ignored.
    let mut nul_body =
        b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n"
            .to_vec();
    nul_body.extend([0; 4096]);
    cases.push(fail(
        "ASCII PLY header then NUL bytes",
        vec![file("n.ply", Entry::Bytes(nul_body))],
        &["stats", "n.ply"],
        error("n.ply: line 8: vertex 0: byte 0x00: this is binary data, but the header says `format ascii`"),
    ));
    let mut tail = binary_ply.clone();
    tail.extend([0; 4096]);
    cases.push(Case {
        quiet_stdout: false,
        code: 0,
        ..fail(
            "binary PLY with a tail after its elements",
            vec![file("tail.ply", Entry::Bytes(tail))],
            &["stats", "tail.ply", "-q"],
            exact(""),
        )
    });
    cases.push(fail(
        "OBJ with an escape sequence for a number",
        vec![text("e.obj", "v 0 0 0\nv 1 \x1b[2J 0\n")],
        &["stats", "e.obj"],
        error("e.obj: line 2: expected a number, found `\\u{1b}[2J`"),
    ));
    // Vertex colours are not used, so colours on some vertices only are no error.
    cases.push(Case {
        quiet_stdout: false,
        code: 0,
        ..fail(
            "OBJ with colours on some vertices",
            vec![text("c.obj", "v 0 0 0 1 0 0\nv 1 0 0\nv 0 1 0 0 0 1\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n")],
            &["stats", "c.obj", "-q"],
            exact(""),
        )
    });
    // A line no real file holds (digits without end) is refused once it passes its bound.
    cases.push(fail(
        "XYZ line of 17 MiB of digits",
        vec![file("d.xyz", Entry::Bytes([b"0 0 0\n".to_vec(), vec![b'7'; 17 << 20]].concat()))],
        &["stats", "d.xyz"],
        error("d.xyz: line 2: the line goes on past 16 MiB without a line break: no mesh file has such a line"),
    ));
    cases.push(fail(
        "PLY header line of 2 MiB",
        vec![file("h.ply", Entry::Bytes([b"ply\ncomment ".to_vec(), vec![b'x'; 2 << 20]].concat()))],
        &["stats", "h.ply"],
        error("h.ply: line 2: the header goes on past 1 MiB without `end_header`: no PLY header is that long"),
    ));
    cases
}

/// Negative values for every numeric flag, each metric's default bound, sizes that ignore the
/// bound, and runs that would keep nothing of the shape, named by the flag that made them so.
fn flag_cases() -> Vec<Case> {
    let simplify_with = |extra: &[&'static str]| -> Vec<&'static str> {
        let mut all = vec!["simplify", "in.ply", "out.ply"];
        all.extend_from_slice(extra);
        all
    };
    let reconstruct_with = |extra: &[&'static str]| -> Vec<&'static str> {
        let mut all = vec!["reconstruct", "cloud.ply", "out.ply"];
        all.extend_from_slice(extra);
        all
    };
    let succeeds = |mut case: Case| {
        (case.code, case.quiet_stdout, case.creates) = (0, false, Some("out.ply".into()));
        case
    };
    // Two small spheres in opposite corners of the bounding box: each within one octant, so a
    // tree of depth 1 (or one cell) collapses every triangle.
    let mut apart = sphere();
    let mut other = sphere();
    for p in &mut apart.positions {
        *p = *p * 0.1 - Vec3::splat(5.0);
    }
    for p in &mut other.positions {
        *p = *p * 0.1 + Vec3::splat(5.0);
    }
    let offset = apart.positions.len() as u32;
    apart.positions.extend(other.positions);
    apart.triangles.extend(other.triangles.iter().map(|t| t.map(|v| v + offset)));
    apart.normals = None;
    let apart = || file("in.ply", Entry::Mesh(apart.clone()));
    let plane: Vec<Vec3> = (0..900).map(|i| Vec3::new((i % 30) as f32, (i / 30) as f32, 0.0)).collect();
    let flat = || file("cloud.ply", Entry::Mesh(points(plane.clone())));
    let three = || file("cloud.ply", Entry::Mesh(points(vec![Vec3::ZERO, Vec3::X, Vec3::Y])));
    let simplify_cloud = |extra: &[&'static str]| -> Vec<&'static str> {
        let mut all = vec!["simplify", "cloud.ply", "out.ply", "-q"];
        all.extend_from_slice(extra);
        all
    };
    let collapsed_cloud = |n: usize| {
        format!(
            "--error: 0.001: all {n} points collapsed into one (1 cluster for the whole model): the model is within this \
             bound of too few planes; use a smaller bound (a flat model, within any bound of one plane, needs the density metric)"
        )
    };
    vec![
        // A value starting with '-' is a value, whatever follows it.
        fail("simplify --dd -inf", vec![sphere_ply()], &simplify_with(&["--dd", "-inf"]), error("--dd: -inf: must be in [0, 1]")),
        fail("simplify --da -nan", vec![sphere_ply()], &simplify_with(&["--da", "-nan"]), error("--da: NaN: must be in [0, 1]")),
        fail("simplify --error -1e-3", vec![sphere_ply()], &simplify_with(&["--error", "-1e-3"]), error("--error: -0.001: must be a finite number > 0")),
        fail(
            "simplify --min-cell-size -1e-9",
            vec![sphere_ply()],
            &simplify_with(&["--min-cell-size", "-1e-9"]),
            error("--min-cell-size: -0.000000001: must be in [0, 1)"),
        ),
        fail("simplify --max-depth -1", vec![sphere_ply()], &simplify_with(&["--max-depth", "-1"]), error("--max-depth: -1: must be from 1 to 30")),
        fail(
            "simplify --max-depth 1e12",
            vec![sphere_ply()],
            &simplify_with(&["--max-depth", "99999999999"]),
            error("--max-depth: 99999999999: must be from 1 to 30"),
        ),
        fail("stats --threads -2", vec![sphere_ply()], &["stats", "in.ply", "--threads", "-2"], error("--threads: -2: must be from 0 (all cores) to 1024")),
        fail("simplify --ratio -1e-3", vec![sphere_ply()], &simplify_with(&["--ratio", "-1e-3"]), error("--ratio: -0.001: must be in (0, 1], a fraction of the input's triangles")),
        fail("reconstruct --levels -1", vec![cloud_ply()], &reconstruct_with(&["--levels", "-1"]), error("--levels: -1: must be from 0 to 12")),
        fail("reconstruct --neighbours -3", vec![cloud_ply()], &reconstruct_with(&["--neighbours", "-3"]), error("--neighbours: -3: must be from 3 to 256")),
        fail("reconstruct --target -1e-9", vec![cloud_ply()], &reconstruct_with(&["--target", "-1e-9"]), error("--target: -0.000000001: must be a finite number >= 0")),
        fail("reconstruct --trim -inf", vec![cloud_ply()], &reconstruct_with(&["--trim", "-inf"]), error("--trim: -inf: must be a finite number >= 0")),
        // A ratio is a mesh's: on a cloud it is named as given.
        fail(
            "simplify a cloud --ratio 0.5",
            vec![cloud_ply()],
            &["simplify", "cloud.ply", "out.ply", "--ratio", "0.5", "-q"],
            error("--ratio: 0.5: the input is a point cloud, with no triangles to take a fraction of: a ratio needs a mesh"),
        ),
        // Each metric's own default bound; a size ignores the bound.
        succeeds(fail("simplify --metric density", vec![sphere_ply()], &simplify_with(&["--metric", "density", "-q"]), exact(""))),
        succeeds(fail("simplify --metric density --faces 500", vec![sphere_ply()], &simplify_with(&["--metric", "density", "--faces", "500", "-q"]), exact(""))),
        succeeds(fail("simplify --metric l21 --ratio 0.5", vec![sphere_ply()], &simplify_with(&["--metric", "l21", "--ratio", "0.5", "-q"]), exact(""))),
        Case { code: 0, quiet_stdout: false, ..fail("stats --metric density", vec![sphere_ply()], &["stats", "in.ply", "--metric", "density", "-q"], exact("")) },
        // Everything collapsed: the flag that made the tree that coarse is named.
        fail(
            "simplify --max-depth 1 collapses every triangle",
            vec![apart()],
            &simplify_with(&["--max-depth", "1", "--no-keep-topology", "-q"]),
            error("--max-depth: 1: every triangle collapsed (2 clusters for the whole model): the tree stopped at this depth, coarser than the bound asks; allow a deeper tree (default 24)"),
        ),
        fail(
            "simplify --min-cell-size 0.99 collapses every triangle",
            vec![apart()],
            &simplify_with(&["--min-cell-size", "0.99", "--no-keep-topology", "-q"]),
            error("--min-cell-size: 0.99: every triangle collapsed (1 cluster for the whole model): cells this small (relative to the diagonal) are not split, so the tree is coarser than the bound asks; use a smaller size (default 1e-7)"),
        ),
        fail(
            "simplify --metric density --error 1e6 collapses every triangle",
            vec![sphere_ply()],
            &simplify_with(&["--metric", "density", "--error", "1e6", "--no-keep-topology", "-q"]),
            error("--error: 1e6 samples per cell: every triangle collapsed (1 cluster for the whole model): the model has too few samples for clusters this large; use a smaller count (at least 1)"),
        ),
        // A cloud collapsed into one point: an error, as a mesh's collapse is; density splits it.
        fail("simplify 3 points", vec![three()], &simplify_cloud(&[]), error(&collapsed_cloud(3))),
        fail("simplify a flat cloud", vec![flat()], &simplify_cloud(&[]), error(&collapsed_cloud(900))),
        fail(
            "simplify 3 points --metric density",
            vec![three()],
            &simplify_cloud(&["--metric", "density"]),
            error("--error: 16 samples per cell: all 3 points collapsed into one (1 cluster for the whole model): the model has too few samples for clusters this large; use a smaller count (at least 1)"),
        ),
        succeeds(fail("simplify 3 points --metric density --error 1", vec![three()], &simplify_cloud(&["--metric", "density", "--error", "1"]), exact(""))),
        succeeds(fail("simplify a flat cloud --metric density", vec![flat()], &simplify_cloud(&["--metric", "density"]), exact(""))),
        succeeds(fail(
            "simplify identical points",
            vec![file("cloud.ply", Entry::Mesh(points(vec![Vec3::splat(0.5); 50])))],
            &simplify_cloud(&[]),
            exact(""),
        )),
    ]
}

/// What a run did.
struct Outcome {
    code: Option<i32>,
    stdout: String,
    stderr: String,
    listing: BTreeSet<String>,
}

fn make(dir: &Path, name: &str, entry: &Entry) {
    let path = dir.join(name);
    match entry {
        Entry::Bytes(bytes) => std::fs::write(&path, bytes).unwrap(),
        Entry::Mesh(mesh) => io::write(&path, mesh).unwrap(),
        Entry::Dir => std::fs::create_dir(&path).unwrap(),
        Entry::Fifo => {
            let status = Command::new("mkfifo").arg(&path).status().unwrap();
            assert!(status.success(), "mkfifo {}", path.display());
        }
        Entry::Link(target) => std::os::unix::fs::symlink(target, &path).unwrap(),
    }
}

fn listing(dir: &Path) -> BTreeSet<String> {
    std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect()
}

/// Runs `case` in `dir`, killing it after [`TIMEOUT`] (a FIFO or a device must not block it).
fn run(case: &Case, dir: &Path) -> Outcome {
    for (name, entry) in &case.files {
        make(dir, name, entry);
    }
    let mut child = Command::new(env!("CARGO_BIN_EXE_vstree"))
        .args(&case.args)
        .current_dir(dir)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let drain = |mut pipe: Box<dyn Read + Send>| {
        std::thread::spawn(move || {
            let mut bytes = Vec::new();
            let _ = pipe.read_to_end(&mut bytes);
            String::from_utf8_lossy(&bytes).into_owned()
        })
    };
    let stdout = drain(Box::new(child.stdout.take().unwrap()));
    let stderr = drain(Box::new(child.stderr.take().unwrap()));
    let start = Instant::now();
    let code = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status.code();
        }
        if start.elapsed() > TIMEOUT {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    Outcome { code, stdout: stdout.join().unwrap(), stderr: stderr.join().unwrap(), listing: listing(dir) }
}

/// What is wrong with `got` for `case`, if anything.
fn check(case: &Case, got: &Outcome) -> Vec<String> {
    let mut wrong = Vec::new();
    match got.code {
        None => wrong.push(format!("no exit code: killed after {TIMEOUT:?} (hung) or by a signal")),
        Some(code) if code != case.code => wrong.push(format!("exit code: got {code}, expected {}", case.code)),
        Some(_) => {}
    }
    match &case.stderr {
        Stderr::Exact(text) if got.stderr != *text => {
            wrong.push(format!("stderr: got {:?}, expected {:?}", got.stderr, text))
        }
        Stderr::Contains(parts) => {
            for part in parts.iter().filter(|p| !got.stderr.contains(p.as_str())) {
                wrong.push(format!("stderr: got {:?}, expected it to contain {part:?}", got.stderr));
            }
        }
        _ => {}
    }
    if case.quiet_stdout && !got.stdout.is_empty() {
        wrong.push(format!("stdout: got {:?}, expected nothing", got.stdout));
    }
    let mut expected: BTreeSet<String> = case.files.iter().map(|(name, _)| name.clone()).collect();
    expected.extend(case.creates.clone());
    if got.listing != expected {
        wrong.push(format!("folder: got {:?}, expected {:?}", got.listing, expected));
    }
    if let Some(tmp) = got.listing.iter().find(|n| n.starts_with('.') && n.contains(".tmp-")) {
        wrong.push(format!("a temporary file was left: {tmp}"));
    }
    wrong
}

#[test]
fn bad_input_table() {
    let cases = cases();
    assert!(cases.len() >= 60, "{} cases", cases.len());
    let names: BTreeSet<&str> = cases.iter().map(|c| c.name).collect();
    assert_eq!(names.len(), cases.len(), "case names must be unique");
    let root: PathBuf = std::env::temp_dir().join(format!("vstree-cli-bad-input-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&root);
    std::fs::create_dir_all(&root).unwrap();
    // Most cases fail at once; run them side by side so the table stays fast.
    let next = std::sync::atomic::AtomicUsize::new(0);
    let failures = std::sync::Mutex::new(Vec::new());
    let workers = std::thread::available_parallelism().map_or(1, |n| n.get()).clamp(1, 8);
    std::thread::scope(|scope| {
        for _ in 0..workers {
            scope.spawn(|| loop {
                let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                let Some(case) = cases.get(i) else { break };
                let dir = root.join(format!("case-{i}"));
                std::fs::create_dir(&dir).unwrap();
                let got = run(case, &dir);
                let wrong = check(case, &got);
                if !wrong.is_empty() {
                    failures
                        .lock()
                        .unwrap()
                        .push((i, format!("{} ({:?}):\n    {}", case.name, case.args, wrong.join("\n    "))));
                }
            });
        }
    });
    let _ = std::fs::remove_dir_all(&root);
    let mut failures = failures.into_inner().unwrap();
    failures.sort();
    if !failures.is_empty() {
        let list: Vec<String> = failures.into_iter().map(|(_, f)| f).collect();
        panic!("{} of {} cases failed:\n{}", list.len(), cases.len(), list.join("\n"));
    }
}
