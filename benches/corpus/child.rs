//! vstree's reconstruction of one input in a child process (this bench run again with
//! `--vstree-child`), which holds nothing but the program and the cloud: its times, figures
//! and peak memory (`common::memory`) are the call's own, not the bench's. The child reads the
//! cloud from the PLY file the bench wrote, writes the output mesh to a PLY file, and prints
//! one `vstree` record (or `failed <why>`) besides the memory report.

use crate::common::memory::{run_child_output, Peak, Probe};
use crate::common::reconstruction::{reconstruction, Stages};
use std::path::Path;
use vstree::io;
use vstree::reconstruct::ReconstructParams;

/// What the child measured of one reconstruction.
pub struct VstreeRun {
    pub seconds: Stages,
    pub levels: usize,
    pub t_nodes: usize,
    /// Points where the base mesh's implicit function was evaluated.
    pub field_evaluations: usize,
    pub open: bool,
    pub unsupported_share: f64,
    /// Resident sizes of the child: before the first run (program and cloud) and the peak
    /// over the runs.
    pub memory: Peak,
}

/// What the child is asked: timed runs, threads, the base mesh's name, the target distance.
pub struct Asked<'a> {
    pub runs: usize,
    pub threads: usize,
    pub base_mesh: &'a str,
    pub target: f64,
}

/// Runs the child on the cloud in `cloud` as `asked`, and writes its output to `output`.
pub fn run(cloud: &Path, output: &Path, asked: &Asked) -> Result<VstreeRun, String> {
    let args = [
        "--vstree-child".to_string(),
        cloud.display().to_string(),
        output.display().to_string(),
        asked.runs.to_string(),
        asked.threads.to_string(),
        asked.base_mesh.to_string(),
        asked.target.to_string(),
    ];
    let (memory, stdout) = run_child_output(&args, false)?;
    if let Some(why) = stdout.lines().find_map(|l| l.strip_prefix("failed\t")) {
        return Err(why.to_string());
    }
    let record = stdout.lines().find_map(|l| l.strip_prefix("vstree\t")).ok_or("no record from the child")?;
    let f: Vec<&str> = record.split('\t').collect();
    let real = |i: usize| f.get(i).and_then(|s| s.parse::<f64>().ok()).ok_or(format!("bad record: {record}"));
    let count = |i: usize| real(i).map(|x| x as usize);
    Ok(VstreeRun {
        seconds: Stages {
            normals: real(0)?,
            tree: real(1)?,
            base: real(2)?,
            refine: real(3)?,
            trim: real(4)?,
            total: real(5)?,
        },
        levels: count(6)?,
        t_nodes: count(7)?,
        field_evaluations: count(8)?,
        open: real(9)? != 0.0,
        unsupported_share: real(10)?,
        memory,
    })
}

/// The child's side: `<cloud> <output> <runs> <threads> <base mesh> <target distance>`. Prints the memory report
/// and the record, or why it failed (on stderr too, for a failure before the memory report).
pub fn child(args: &[String]) {
    match reconstruct_file(args) {
        Ok(record) => println!("vstree\t{record}"),
        Err(e) => {
            eprintln!("{e}");
            println!("failed\t{e}");
        }
    }
}

fn reconstruct_file(args: &[String]) -> Result<String, String> {
    let bad = || format!("the child's arguments: {}", args.join(" "));
    let [cloud, output, runs, threads, base, target] = args else { return Err(bad()) };
    let (Ok(runs), Ok(threads), Some(base_mesh), Ok(target_distance)) =
        (runs.parse(), threads.parse(), crate::base_mesh(base), target.parse())
    else {
        return Err(bad());
    };
    let cloud = io::read(Path::new(cloud)).map_err(|e| format!("cannot read the cloud: {e}"))?;
    // Defaults on every input: open or closed is found, not told.
    let params = ReconstructParams { threads, base_mesh, target_distance, ..ReconstructParams::default() };
    let probe = Probe::start();
    let result = reconstruction(&cloud, &params, runs);
    probe.report();
    let rec = result.map_err(|e| e.to_string())?;
    io::write(Path::new(output), &rec.mesh).map_err(|e| format!("cannot write the output: {e}"))?;
    let (s, st) = (&rec.seconds, &rec.stats);
    Ok(format!(
        "{}\t{}\t{}\t{}\t{}\t{}\t{}\t{}\t{}\t{}\t{}",
        s.normals,
        s.tree,
        s.base,
        s.refine,
        s.trim,
        s.total,
        st.levels.len(),
        st.tree.t_nodes,
        st.field_evaluations,
        u8::from(st.open),
        st.unsupported_share
    ))
}
