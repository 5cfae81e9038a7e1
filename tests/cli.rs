//! The `vstree` command end to end on a generated shape.

use std::path::PathBuf;
use std::process::Command;
use vstree::{eval::shapes, io};

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("vstree-cli-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn vstree(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_vstree")).args(args).output().unwrap()
}

#[test]
fn simplify_writes_a_smaller_mesh_and_reports_what_it_did() {
    let dir = temp_dir("simplify");
    let input = dir.join("torus.ply");
    let output = dir.join("torus-simplified.obj");
    let torus = shapes::torus(1.0, 0.3, 128, 64);
    io::write(&input, &torus).unwrap();
    let run = vstree(&["simplify", input.to_str().unwrap(), output.to_str().unwrap(), "--error", "1e-4"]);
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(run.status.success(), "{stdout}\n{}", String::from_utf8_lossy(&run.stderr));
    // stderr is a pipe here, not a terminal: no progress bar, nothing at all.
    assert!(run.stderr.is_empty(), "stderr: {}", String::from_utf8_lossy(&run.stderr));
    let out = io::read(&output).unwrap();
    assert!(out.triangles.len() < torus.triangles.len() / 4 && !out.triangles.is_empty());
    for needle in [
        "samples: 8192",
        "T-layer depth",
        "clusters (leaves)",
        "time: read",
        &format!("{} triangles", out.triangles.len()),
    ] {
        assert!(stdout.contains(needle), "missing {needle:?} in:\n{stdout}");
    }
    // Below the T-layer (a finer bound) the octree needs more clusters on the same input.
    let count = |tree: &str| {
        let path = dir.join(format!("{tree}.ply"));
        let run = vstree(&[
            "simplify",
            input.to_str().unwrap(),
            path.to_str().unwrap(),
            "--error",
            "1e-5",
            "--tree",
            tree,
            "-q",
        ]);
        assert!(run.status.success() && run.stdout.is_empty());
        io::read(&path).unwrap().positions.len()
    };
    assert!(count("octree") > count("vstree"));
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn stats_compares_both_trees() {
    let dir = temp_dir("stats");
    let input = dir.join("sphere.off");
    io::write(&input, &shapes::icosphere(1.0, 5)).unwrap();
    let run = vstree(&["stats", input.to_str().unwrap(), "--compare", "--error", "1e-4"]);
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(run.status.success(), "{stdout}");
    assert!(
        stdout.contains("VsTree: built") && stdout.contains("Octree: built") && stdout.contains("clusters:"),
        "{stdout}"
    );
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn errors_name_the_problem_and_leave_no_output() {
    let dir = temp_dir("errors");
    let input = dir.join("broken.off");
    std::fs::write(&input, "OFF\n3 1 0\n0 0 0\n1 0 0\n").unwrap();
    let output = dir.join("out.ply");
    let run = vstree(&["simplify", input.to_str().unwrap(), output.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success());
    assert!(stderr.contains("broken.off"), "{stderr}");
    assert!(!output.exists());

    io::write(&input, &shapes::icosphere(1.0, 2)).unwrap();
    let run = vstree(&["simplify", input.to_str().unwrap(), output.to_str().unwrap(), "--error", "-1"]);
    assert!(!run.status.success());
    assert!(String::from_utf8_lossy(&run.stderr).contains("--error: -1"));
    assert!(!output.exists());
    let run = vstree(&["simplify", input.to_str().unwrap(), output.to_str().unwrap(), "--dd", "2"]);
    assert!(String::from_utf8_lossy(&run.stderr).contains("--dd: 2: must be in [0, 1]"));
    assert!(!output.exists());
    let run = vstree(&["simplify", input.to_str().unwrap(), dir.join("out.stl").to_str().unwrap()]);
    assert!(String::from_utf8_lossy(&run.stderr).contains("unsupported"));
    // The output's format is checked before the input is read: no wait for a useless run.
    let missing = dir.join("missing.ply");
    let run = vstree(&["simplify", missing.to_str().unwrap(), dir.join("out.stl").to_str().unwrap()]);
    assert!(String::from_utf8_lossy(&run.stderr).contains("out.stl: unsupported"));

    // The input is never overwritten, even by a run that would succeed; nor through a link.
    let before = std::fs::read(&input).unwrap();
    let link = dir.join("link.off");
    std::os::unix::fs::symlink(&input, &link).unwrap();
    for out in [&input, &link] {
        for command in ["simplify", "reconstruct"] {
            let run = vstree(&[command, input.to_str().unwrap(), out.to_str().unwrap()]);
            let stderr = String::from_utf8_lossy(&run.stderr);
            assert!(!run.status.success() && stderr.contains("is the input file"), "{command}: {stderr}");
        }
    }
    assert_eq!(std::fs::read(&input).unwrap(), before);
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn help_explains_every_parameter() {
    let run = vstree(&["simplify", "--help"]);
    let help = String::from_utf8_lossy(&run.stdout);
    for flag in ["--tree", "--metric", "--error", "--da", "--dd", "--threads", "--sampling", "--max-depth"] {
        assert!(help.contains(flag), "--help lacks {flag}");
    }
    assert!(help.contains("sqrt(error)"), "the error bound is not explained");
    assert!(help.contains("--min-cell-size"), "--help lacks --min-cell-size");
    // Each value of --tree and --metric is explained, not just listed.
    for value in ["Quadric error", "Normal deviation", "Sample count", "plain octree"] {
        assert!(help.contains(value), "--help does not explain {value:?}");
    }
    let run = vstree(&["stats", "--help"]);
    let help = String::from_utf8_lossy(&run.stdout);
    for flag in ["--tree", "--metric", "--error", "--da", "--dd", "--threads", "--sampling", "--compare"] {
        assert!(help.contains(flag), "stats --help lacks {flag}");
    }
}

#[test]
fn a_cloud_without_normals_gets_them_estimated() {
    let dir = temp_dir("no-normals");
    let input = dir.join("points.xyz");
    let mut cloud = shapes::sample_surface(&shapes::icosphere(1.0, 4), 20_000, 3);
    cloud.normals = None;
    io::write(&input, &cloud).unwrap();
    let run = vstree(&["stats", input.to_str().unwrap(), "--error", "1e-4"]);
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(run.status.success(), "{stdout}{}", String::from_utf8_lossy(&run.stderr));
    assert!(stdout.contains("normals: 20000 estimated") && stdout.contains("T-layer depth"), "{stdout}");
    let output = dir.join("simplified.ply");
    let run = vstree(&["simplify", input.to_str().unwrap(), output.to_str().unwrap(), "--error", "1e-4"]);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let out = io::read(&output).unwrap();
    // One point per cluster, each with a unit normal pointing out of the sphere.
    let normals = out.normals.expect("clusters carry normals");
    assert!(out.positions.len() > 100 && out.positions.len() < 20_000);
    for (p, n) in out.positions.iter().zip(&normals) {
        assert!((n.length() - 1.0).abs() < 1e-4 && n.dot(p.normalize()) > 0.9, "{p} {n}");
    }
    std::fs::remove_dir_all(dir).unwrap();
}

/// The output folder is checked before the input is even read: a run that could not be saved
/// fails at once instead of after all its work.
#[test]
fn an_unwritable_output_fails_before_the_work() {
    let dir = temp_dir("output-first");
    let input = dir.join("broken.off");
    std::fs::write(&input, "OFF\n3 1 0\n0 0 0\n").unwrap();
    let output = dir.join("missing-folder/out.ply");
    for command in ["simplify", "reconstruct"] {
        let run = vstree(&[command, input.to_str().unwrap(), output.to_str().unwrap()]);
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert_eq!(stderr, format!("vstree: error: {}: No such file or directory (os error 2)\n", output.display()));
    }
    std::fs::remove_dir_all(dir).unwrap();
}

/// Every signal that ends a process and can be caught (Ctrl-C, SIGTERM, SIGHUP, SIGQUIT, the
/// user, timer and CPU-limit signals, the real-time ones) leaves no hidden temporary output
/// behind when it arrives during a run, and the process still ends by the signal (so shells
/// see it as interrupted). A signal the run was started with ignored (`nohup`) stays ignored.
#[cfg(target_os = "linux")]
#[test]
fn an_interrupted_run_leaves_no_temporary_file() {
    use std::os::unix::process::{CommandExt, ExitStatusExt};
    use std::time::{Duration, Instant};
    let dir = temp_dir("signals");
    let input = dir.join("cloud.ply");
    // Large enough that reconstruction runs for a while after the output is reserved.
    io::write(&input, &shapes::sample_surface(&shapes::genus_n_pretzel(2), 300_000, 5)).unwrap();
    let output = dir.join("out.ply");
    let signals = [
        libc::SIGINT,
        libc::SIGTERM,
        libc::SIGHUP,
        libc::SIGQUIT,
        libc::SIGUSR1,
        libc::SIGUSR2,
        libc::SIGALRM,
        libc::SIGVTALRM,
        libc::SIGPROF,
        libc::SIGXCPU,
        libc::SIGIO,
        libc::SIGPWR,
        libc::SIGSTKFLT,
        libc::SIGRTMIN(),
        libc::SIGRTMAX(),
    ];
    // The last run starts with SIGHUP ignored: the SIGHUP it gets is no end, its SIGTERM is.
    let runs = signals.iter().map(|&s| (s, None)).chain([(libc::SIGTERM, Some(libc::SIGHUP))]);
    for (signal, ignored) in runs {
        let mut command = Command::new(env!("CARGO_BIN_EXE_vstree"));
        command.args(["reconstruct", input.to_str().unwrap(), output.to_str().unwrap(), "-q"]);
        // SAFETY: only async-signal-safe calls between fork and exec. No core files from the
        // signals that dump core (SIGQUIT, SIGXCPU).
        unsafe {
            command.pre_exec(move || {
                let none = libc::rlimit { rlim_cur: 0, rlim_max: 0 };
                libc::setrlimit(libc::RLIMIT_CORE, &none);
                if let Some(ignored) = ignored {
                    libc::signal(ignored, libc::SIG_IGN);
                }
                Ok(())
            });
        }
        let mut child = command.spawn().unwrap();
        let start = Instant::now();
        let temporary = || {
            std::fs::read_dir(&dir)
                .unwrap()
                .any(|e| e.unwrap().file_name().to_string_lossy().starts_with(".out.ply.tmp-"))
        };
        while !temporary() {
            assert!(start.elapsed() < Duration::from_secs(20), "no temporary output appeared");
            assert!(child.try_wait().unwrap().is_none(), "the run ended before it could be interrupted");
            std::thread::sleep(Duration::from_millis(2));
        }
        if let Some(ignored) = ignored {
            // SAFETY: the child is alive (not yet waited for).
            unsafe { libc::kill(child.id() as libc::pid_t, ignored) };
            std::thread::sleep(Duration::from_millis(200));
            assert!(child.try_wait().unwrap().is_none(), "an ignored signal {ignored} ended the run");
            assert!(temporary(), "an ignored signal {ignored} removed the temporary output");
        }
        // SAFETY: the child is alive (not yet waited for).
        unsafe { libc::kill(child.id() as libc::pid_t, signal) };
        let status = child.wait().unwrap();
        assert_eq!(status.signal(), Some(signal), "{status:?}");
        let names: Vec<String> =
            std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
        assert_eq!(names, vec!["cloud.ply"], "signal {signal}");
    }
    std::fs::remove_dir_all(dir).unwrap();
}

/// A surface that does not follow the cloud (here the closed blob that the paper's base mesh,
/// asked to close, makes of an open hemisphere) is not passed off as a result: the run says so
/// on stderr.
#[test]
fn a_surface_far_from_its_samples_is_reported() {
    let dir = temp_dir("far-surface");
    let mut cloud = shapes::sample_surface(&shapes::icosphere(1.0, 5), 20_000, 7);
    let normals = cloud.normals.take().unwrap();
    let (positions, normals): (Vec<_>, Vec<_>) =
        cloud.positions.iter().zip(&normals).filter(|(p, _)| p.z >= 0.0).unzip();
    let input = dir.join("hemisphere.ply");
    io::write(&input, &vstree::Mesh::from_points(positions, Some(normals))).unwrap();
    let output = dir.join("out.ply");
    let run =
        vstree(&["reconstruct", input.to_str().unwrap(), output.to_str().unwrap(), "--closed", "--base-mesh", "paper"]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{stderr}");
    assert!(stderr.contains("warning: the surface is far from the samples (RMS "), "{stderr}");
    // A closed sphere from the same sampler gets no warning.
    let sphere = dir.join("sphere.ply");
    io::write(&sphere, &shapes::sample_surface(&shapes::icosphere(1.0, 5), 20_000, 7)).unwrap();
    let run = vstree(&["reconstruct", sphere.to_str().unwrap(), dir.join("sphere-out.ply").to_str().unwrap()]);
    assert!(run.status.success() && run.stderr.is_empty(), "{}", String::from_utf8_lossy(&run.stderr));
    std::fs::remove_dir_all(dir).unwrap();
}

/// The CLI's defaults are the library's (the C API, Python, MeshLab and Blender take theirs
/// from it too): every `[default: …]` in `--help` is read back and compared.
#[test]
fn help_shows_the_library_defaults() {
    use vstree::reconstruct::ReconstructParams;
    use vstree::tree::{Metric, TreeParams};
    let default_of = |command: &str, flag: &str| -> String {
        let help = String::from_utf8(vstree(&[command, "--help"]).stdout).unwrap();
        let at = help.find(&format!("--{flag} <")).unwrap_or_else(|| panic!("{command} --help lacks --{flag}"));
        let rest = &help[at..];
        let start = rest.find("[default: ").unwrap() + "[default: ".len();
        rest[start..start + rest[start..].find(']').unwrap()].to_string()
    };
    let number = |command: &str, flag: &str| default_of(command, flag).parse::<f64>().unwrap();
    let tree = TreeParams::default();
    let recon = ReconstructParams::default();
    for command in ["simplify", "reconstruct", "stats"] {
        assert_eq!(number(command, "da"), f64::from(tree.d_a), "{command} --da");
        assert_eq!(number(command, "dd") as f32, tree.d_d, "{command} --dd");
        assert_eq!(number(command, "max-depth"), f64::from(tree.max_depth), "{command} --max-depth");
        assert_eq!(number(command, "min-cell-size"), tree.min_cell_size, "{command} --min-cell-size");
        assert_eq!(default_of(command, "tree"), "vstree");
        assert_eq!(default_of(command, "metric"), "l2");
        let error = default_of(command, "error");
        assert_eq!(
            error,
            format!(
                "{:e} to simplify and for stats, {:e} to reconstruct; l21: {:e}; density: {}",
                TreeParams::DEFAULT_ERROR,
                recon.tree.error,
                Metric::L21.default_error(),
                Metric::Density.default_error()
            )
        );
    }
    assert_eq!(number("reconstruct", "target"), recon.target_distance);
    assert_eq!(number("reconstruct", "levels"), f64::from(recon.max_levels));
    assert_eq!(number("reconstruct", "trim"), f64::from(recon.trim));
    assert_eq!(number("reconstruct", "neighbours"), recon.normals.neighbours as f64);
    assert_eq!(vstree::SimplifyParams::default().tree.error, TreeParams::DEFAULT_ERROR);
}

/// A reader that goes away (`vstree stats … | head -c 10`) ends the report quietly: no message,
/// and the run ends with its own status, its output file written. A report that cannot be
/// written (a full disk) is an error naming standard output.
#[cfg(unix)]
#[test]
fn a_closed_or_full_standard_output_never_panics() {
    use std::process::Stdio;
    let dir = temp_dir("stdout");
    let cloud = dir.join("cloud.xyz");
    let mut points = shapes::sample_surface(&shapes::icosphere(1.0, 3), 3000, 2);
    points.normals = None; // a report line before the work, about the estimated normals
    io::write(&cloud, &points).unwrap();
    let mesh = dir.join("sphere.ply");
    io::write(&mesh, &shapes::icosphere(1.0, 3)).unwrap();
    let output = dir.join("out.ply");
    let closed_pipe = |args: &[&str]| {
        let mut child = Command::new(env!("CARGO_BIN_EXE_vstree"))
            .args(args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        drop(child.stdout.take()); // the reader is gone before the first line
        child.wait_with_output().unwrap()
    };
    for args in [
        vec!["stats", cloud.to_str().unwrap(), "--compare"],
        vec!["simplify", cloud.to_str().unwrap(), output.to_str().unwrap()],
        vec!["simplify", mesh.to_str().unwrap(), output.to_str().unwrap()],
    ] {
        let _ = std::fs::remove_file(&output);
        let run = closed_pipe(&args);
        assert_eq!(run.status.code(), Some(0), "{args:?}: {}", String::from_utf8_lossy(&run.stderr));
        assert_eq!(String::from_utf8_lossy(&run.stderr), "", "{args:?}");
        assert_eq!(output.exists(), args[0] == "simplify", "{args:?}");
    }
    let full = |args: &[&str]| {
        let dev_full = std::fs::OpenOptions::new().write(true).open("/dev/full").unwrap();
        Command::new(env!("CARGO_BIN_EXE_vstree")).args(args).stdout(dev_full).output().unwrap()
    };
    for args in [
        vec!["simplify", mesh.to_str().unwrap(), output.to_str().unwrap()],
        vec!["stats", cloud.to_str().unwrap()],
        vec!["--help"],
    ] {
        let run = full(&args);
        assert_eq!(run.status.code(), Some(1), "{args:?}");
        assert_eq!(
            String::from_utf8_lossy(&run.stderr),
            "vstree: error: standard output: No space left on device (os error 28)\n",
            "{args:?}"
        );
    }
    std::fs::remove_dir_all(dir).unwrap();
}

/// A run stopped by the file-size limit (`ulimit -f`) fails like any other write: a message
/// naming the output and the cause, exit code 1, no temporary file left and the old output
/// untouched (instead of dying of SIGXFSZ with the temporary file left behind).
#[cfg(unix)]
#[test]
fn a_file_size_limit_is_a_write_error() {
    use std::os::unix::process::CommandExt;
    let dir = temp_dir("fsize");
    let input = dir.join("sphere.ply");
    io::write(&input, &shapes::icosphere(1.0, 4)).unwrap();
    let output = dir.join("out.ply");
    std::fs::write(&output, "old").unwrap();
    let mut command = Command::new(env!("CARGO_BIN_EXE_vstree"));
    // A bound fine enough to keep most of the 2562 vertices: about 90 kB to write.
    command.args(["simplify", input.to_str().unwrap(), output.to_str().unwrap(), "--error", "1e-9", "-q"]);
    // SAFETY: setrlimit is async-signal-safe.
    unsafe {
        command.pre_exec(|| {
            let limit = libc::rlimit { rlim_cur: 16 * 1024, rlim_max: 16 * 1024 };
            libc::setrlimit(libc::RLIMIT_FSIZE, &limit);
            Ok(())
        });
    }
    let run = command.output().unwrap();
    assert_eq!(run.status.code(), Some(1), "{:?}", run.status);
    assert_eq!(
        String::from_utf8_lossy(&run.stderr),
        format!("vstree: error: {}: File too large (os error 27)\n", output.display())
    );
    assert_eq!(std::fs::read_to_string(&output).unwrap(), "old");
    let mut names: Vec<String> =
        std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    names.sort();
    assert_eq!(names, vec!["out.ply", "sphere.ply"]);
    std::fs::remove_dir_all(dir).unwrap();
}

/// A cloud far beyond unit size, with one stray point 1000 diameters away: reconstructed, the
/// stray point left out and said (issue 26: "the blended T-node planes have no zero crossing"
/// at 1e14-1e17, "the base mesh is empty" with the stray point).
#[test]
fn a_huge_cloud_with_a_stray_point_is_reconstructed() {
    let dir = temp_dir("stray");
    let cloud = shapes::sample_surface(&shapes::icosphere(1.0, 4), 3_000, 5);
    let scale = 1e14f32;
    let mut positions: Vec<glam::Vec3> = cloud.positions.iter().map(|&p| p * scale).collect();
    let mut normals = cloud.normals.unwrap();
    positions.push(glam::Vec3::new(2000.0 * scale, 0.0, 0.0));
    normals.push(glam::Vec3::X);
    let input = dir.join("cloud.ply");
    io::write(&input, &vstree::Mesh::from_points(positions, Some(normals))).unwrap();
    let output = dir.join("out.ply");
    let run = vstree(&["reconstruct", input.to_str().unwrap(), output.to_str().unwrap()]);
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    assert!(stdout.contains("isolated points: 1 left out"), "{stdout}");
    let mesh = io::read(&output).unwrap();
    let report = vstree::topology::analyze(&mesh);
    assert!(report.is_watertight() && report.genus() == Some(0), "{report:?}");
    let worst = (0..mesh.positions.len())
        .map(|i| (mesh.absolute(i).length() / f64::from(scale) - 1.0).abs())
        .fold(0.0, f64::max);
    assert!(worst < 0.01, "a vertex {worst} off the sphere's radius");
    std::fs::remove_dir_all(dir).unwrap();
}

/// `--keep-topology` keeps a flap's border (issue 26: a sphere with a strip joined along one
/// edge lost the strip and its border).
#[test]
fn keeping_topology_keeps_a_flaps_border() {
    let dir = temp_dir("flap");
    let mut mesh = shapes::icosphere(1.0, 3);
    mesh.normals = None;
    let [a, b, _] = mesh.triangles[0];
    let (pa, pb) = (mesh.positions[a as usize], mesh.positions[b as usize]);
    let out = (pa + pb).normalize() * pa.distance(pb);
    let mut base = (a, b);
    for row in 1..=20u32 {
        let next = mesh.positions.len() as u32;
        mesh.positions.extend([pa + out * row as f32, pb + out * row as f32]);
        mesh.triangles.extend([[base.0, base.1, next + 1], [base.0, next + 1, next]]);
        base = (next, next + 1);
    }
    let input = dir.join("flap.ply");
    io::write(&input, &mesh).unwrap();
    for bound in ["1e-3", "3e-2"] {
        let output = dir.join(format!("out-{bound}.ply"));
        let run = vstree(&[
            "simplify",
            input.to_str().unwrap(),
            output.to_str().unwrap(),
            "--keep-topology",
            "--error",
            bound,
        ]);
        assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
        let r = vstree::topology::analyze(&io::read(&output).unwrap());
        assert!(r.boundary_edges >= 2 && r.non_manifold_edges == 1, "--error {bound}: {r:?}");
    }
    std::fs::remove_dir_all(dir).unwrap();
}
