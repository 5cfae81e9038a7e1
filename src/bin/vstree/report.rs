//! What the CLI says about a finished job: the tree, the simplification, the reconstruction.

use crate::console;
use std::path::Path;
use vstree::reconstruct::{ReconstructStats, RefinementStop};
use vstree::simplify::SimplifyStats;
use vstree::tree::TreeStats;

/// An RMS sample-to-surface distance above this fraction of the diagonal means the surface
/// does not follow the cloud at all: a faithful one is within a sample spacing, well below 1%
/// of the diagonal even for sparse clouds, and the failures seen (a closed blob under an open
/// hemisphere) are at 30%.
const SURFACE_LOST_ERROR: f64 = 0.05;

pub(crate) fn print_tree(s: &TreeStats) -> vstree::Result<()> {
    say!("  nodes: {} (V {}, T {}, S {}), depth {}", s.nodes, s.v_nodes, s.t_nodes, s.s_nodes, s.max_depth);
    if s.t_nodes > 0 {
        say!("  T-layer depth: {}..{}", s.t_depth_min, s.t_depth_max);
    }
    say!(
        "  clusters (leaves): {}, samples per cluster: mean {:.1}, variance {:.1}",
        s.leaves,
        s.leaf_size_mean,
        s.leaf_size_variance
    );
    Ok(())
}

pub(crate) fn print_simplify(
    input: &Path,
    output: &Path,
    s: &SimplifyStats,
    read_s: f64,
    write_s: f64,
) -> vstree::Result<()> {
    say!("{}: {} vertices, {} triangles", input.display(), s.input_vertices, s.input_triangles);
    say!("samples: {}", s.tree.samples);
    print_tree(&s.tree)?;
    say!("{}: {} vertices, {} triangles", output.display(), s.output_vertices, s.output_triangles);
    say!("topology: {}", if s.kept_topology { "kept" } else { "not kept (plain clustering)" });
    say!(
        "time: read {:.3} s, samples {:.3} s, tree {:.3} s, clustering {:.3} s, write {:.3} s",
        read_s,
        s.seconds_samples,
        s.seconds_tree,
        s.seconds_cluster,
        write_s
    );
    Ok(())
}

pub(crate) fn print_reconstruct(
    input: &Path,
    output: &Path,
    points: usize,
    s: &ReconstructStats,
    read_s: f64,
    write_s: f64,
) -> vstree::Result<()> {
    say!("{}: {} points", input.display(), points);
    if s.isolated_points > 0 {
        say!("isolated points: {} left out (far from the rest for their neighbours' spacing)", s.isolated_points);
    }
    if s.normals.estimated > 0 {
        say!("normals: {} estimated from {} neighbours", s.normals.estimated, s.normals.neighbours);
    }
    if let Some(o) = &s.normals.orient {
        say!("orientation: {} components, {} flipped", o.components, o.flipped);
    }
    say!("noise: {:.3}% of the diagonal (the tree and the fits look past it)", 100.0 * s.noise);
    print_tree(&s.tree)?;
    let genus = s.base_genus.map_or("not a closed manifold".to_string(), |g| format!("genus {g}"));
    let thickened = if s.thickened { " (thickened: the plain one had handles through thin parts)" } else { "" };
    let polygonised = if s.on_grid {
        format!("grid: {} cells across, {} triangles polygonised{thickened}", s.grid_cells, s.fine_triangles)
    } else {
        format!("octree: {} triangles polygonised over the T-layer", s.fine_triangles)
    };
    say!("{polygonised}, field evaluated at {} points", s.field_evaluations);
    say!("M0: {} vertices, {} triangles, {genus}, error {:.2e}", s.base_vertices, s.base_triangles, s.base_error);
    for (k, level) in s.levels.iter().enumerate() {
        say!(
            "level {}: {} triangles split, {} new vertices, {} displaced by the quadtrees",
            k + 1,
            level.split,
            level.new_vertices,
            level.displaced
        );
    }
    if s.stopped == RefinementStop::TriangleBudget {
        warn!(
            "warning: refinement stopped short of the target: another level would exceed the library's triangle budget"
        );
    }
    say!("refinement stopped: {}", s.stopped.as_str());
    say!("error: RMS {:.2e}, max {:.2e} (sample-to-mesh distance / diagonal)", s.final_error, s.final_max_error);
    let share = 100.0 * s.unsupported_share;
    if s.open {
        say!("open: {share:.0}% of the closed surface is unsupported by the samples; kept: the part they support (--closed closes it)");
    } else {
        say!(
            "closed: {share:.0}% of the closed surface is unsupported by the samples, closed over (--open keeps it open)"
        );
    }
    if s.final_error > SURFACE_LOST_ERROR {
        warn!(
            "warning: the surface is far from the samples (RMS {:.1}% of the diagonal) and does not \
             represent this cloud",
            100.0 * s.final_error
        );
    }
    if s.trimmed_triangles > 0 {
        say!("trimmed: {} triangles far from the samples", s.trimmed_triangles);
    }
    say!("{}: {} vertices, {} triangles", output.display(), s.output_vertices, s.output_triangles);
    say!(
        "time: read {:.3} s, normals {:.3} s, tree {:.3} s, base mesh {:.3} s, refinement {:.3} s, trim {:.3} s, write {:.3} s",
        read_s, s.seconds_normals, s.seconds_tree, s.seconds_base, s.seconds_refine, s.seconds_trim, write_s
    );
    Ok(())
}
