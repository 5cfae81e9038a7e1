//! The `demo` job.

use crate::console;
use crate::report::print_reconstruct;
use crate::with_progress;
use std::path::Path;
use vstree::io;
use vstree::reconstruct::{reconstruct, ReconstructParams};
use vstree::simplify::{simplify, SimplifyParams};
use vstree::tree::{TreeKind, TreeParams};

/// The `demo` job: both algorithms on generated shapes whose answers are known.
pub(crate) fn demo(out: &Path) -> vstree::Result<()> {
    use vstree::{eval::shapes, topology};
    if out.exists() && !out.is_dir() {
        let e = std::io::Error::new(
            std::io::ErrorKind::AlreadyExists,
            "exists and is not a folder: name a folder for --out",
        );
        return Err(vstree::Error::Io { path: out.to_path_buf(), source: e });
    }
    std::fs::create_dir_all(out).map_err(|e| vstree::Error::Io { path: out.to_path_buf(), source: e })?;
    say!("== simplification: a bumpy sphere, VS-Tree against octree at the same L2 bound (1e-5)");
    let mesh = shapes::bumpy_sphere(1.0, 0.08, 5.0, 8);
    let input = out.join("demo-sphere.ply");
    io::write(&input, &mesh)?;
    say!("{}: {} vertices, {} triangles", input.display(), mesh.positions.len(), mesh.triangles.len());
    for (kind, name) in [(TreeKind::VsTree, "vstree"), (TreeKind::Octree, "octree")] {
        let params =
            SimplifyParams { tree: TreeParams { kind, error: 1e-5, ..TreeParams::default() }, ..Default::default() };
        let (simplified, stats) = with_progress(false, |p| simplify(&mesh, &params, p))?;
        let path = out.join(format!("demo-sphere-{name}.ply"));
        io::write(&path, &simplified)?;
        say!(
            "{:7} {} clusters -> {}: {} triangles in {:.3} s",
            name,
            stats.tree.leaves,
            path.display(),
            stats.output_triangles,
            stats.seconds_samples + stats.seconds_tree + stats.seconds_cluster
        );
    }

    say!("\n== reconstruction: 200k noisy points on a genus-3 pretzel");
    let mut cloud = shapes::sample_surface(&shapes::genus_n_pretzel(3), 200_000, 1);
    shapes::add_noise(&mut cloud, 0.002, 0.05, 2);
    let input = out.join("demo-pretzel-points.ply");
    io::write(&input, &cloud)?;
    let (mesh, stats) = with_progress(false, |p| reconstruct(&cloud, &ReconstructParams::default(), p))?;
    let output = out.join("demo-pretzel-reconstructed.ply");
    io::write(&output, &mesh)?;
    print_reconstruct(&input, &output, cloud.positions.len(), &stats, 0.0, 0.0)?;
    let report = topology::analyze(&mesh);
    say!("result: watertight {}, genus {:?} (the shape has genus 3)", report.is_watertight(), report.genus());
    Ok(())
}
