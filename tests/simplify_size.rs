//! Simplification to a triangle count (`SimplifyParams::target_faces`): the output has the
//! count asked for, within 1% or 2 triangles, and keeps the topology of closed inputs.

mod common;

use glam::Vec3;
use vstree::topology::{analyze, TopologyReport};
use vstree::{eval::shapes, simplify, KeepTopology, Mesh, Progress, SimplifyParams, SimplifyStats};

fn to_size(mesh: &Mesh, target: usize, keep_topology: KeepTopology) -> (Mesh, SimplifyStats) {
    let params = SimplifyParams { target_faces: target, keep_topology, ..Default::default() };
    simplify(mesh, &params, &mut Progress::none()).unwrap_or_else(|e| panic!("target {target}: {e}"))
}

/// Within 1% of the target, or 2 triangles for small targets.
fn close_enough(got: usize, target: usize) -> bool {
    got.abs_diff(target) <= (target / 100).max(2)
}

/// The fewest triangles a closed surface with these figures can have under the collapses: a
/// tetrahedron per genus-0 component, and a handle costs more (a torus needs 14 triangles).
fn floor(r: &TopologyReport) -> usize {
    let g = r.genus().unwrap_or(0) as usize;
    4 * r.components + 10 * g
}

#[test]
fn synthetic_shapes_reach_the_count_with_their_topology() {
    for (name, mesh, genus) in [
        ("sphere", shapes::icosphere(1.0, 5), 0),
        ("torus", shapes::torus(1.0, 0.3, 192, 96), 1),
        ("double torus", shapes::double_torus(), 2),
        ("pretzel", shapes::genus_n_pretzel(3), 3),
    ] {
        let n = mesh.triangles.len();
        for target in [n / 10, n / 50, n / 200, 500, 100] {
            let (out, stats) = to_size(&mesh, target, KeepTopology::Auto);
            let r = analyze(&out);
            assert!(stats.kept_topology, "{name}: closed input, topology not kept by default");
            assert!(close_enough(out.triangles.len(), target), "{name}: {} for {target}", out.triangles.len());
            assert!(r.is_watertight(), "{name} at {target}: {r:?}");
            assert_eq!((r.non_manifold_edges, r.components, r.genus()), (0, 1, Some(genus)), "{name} at {target}");
        }
    }
}

#[test]
fn without_topology_the_count_is_met_too() {
    let mesh = shapes::genus_n_pretzel(3);
    for target in [5000, 1000, 200] {
        let (out, stats) = to_size(&mesh, target, KeepTopology::Off);
        assert!(!stats.kept_topology);
        assert!(close_enough(out.triangles.len(), target), "{} for {target}", out.triangles.len());
    }
}

#[test]
fn a_target_below_the_topology_gives_the_smallest_closed_mesh() {
    // A torus cannot go below 14 triangles without losing its hole (7 vertices, Császár).
    let torus = shapes::torus(1.0, 0.3, 64, 32);
    let (out, _) = to_size(&torus, 1, KeepTopology::On);
    let r = analyze(&out);
    assert!(r.is_watertight() && r.genus() == Some(1), "{r:?}");
    assert!((14..=40).contains(&out.triangles.len()), "{} triangles", out.triangles.len());
    // A sphere stops at a tetrahedron.
    let (out, _) = to_size(&shapes::icosphere(1.0, 4), 2, KeepTopology::On);
    assert_eq!(out.triangles.len(), 4);
    assert!(analyze(&out).is_watertight());
}

#[test]
fn an_open_sheet_keeps_its_border_manifold_at_a_count() {
    let sphere = shapes::icosphere(1.0, 5);
    let triangles: Vec<[u32; 3]> =
        sphere.triangles.iter().filter(|t| t.iter().any(|&v| sphere.positions[v as usize].z < 0.5)).copied().collect();
    let open = Mesh::new(sphere.positions.clone(), None, triangles);
    for target in [2000, 500, 100] {
        let (out, stats) = to_size(&open, target, KeepTopology::On);
        let r = analyze(&out);
        assert!(stats.kept_topology);
        assert_eq!((r.non_manifold_edges, r.non_manifold_vertices, r.components), (0, 0, 1), "at {target}: {r:?}");
        assert!(r.boundary_edges > 0, "at {target}: the border closed");
        assert!(close_enough(out.triangles.len(), target), "{} for {target}", out.triangles.len());
    }
}

/// The loops of border edges (edges with one face): a hole or an outer border each.
fn border_loops(mesh: &Mesh) -> usize {
    let mut parent: Vec<usize> = (0..mesh.positions.len()).collect();
    fn root(parent: &mut [usize], mut v: usize) -> usize {
        while parent[v] != v {
            parent[v] = parent[parent[v]];
            v = parent[v];
        }
        v
    }
    let mut on_border = vec![false; mesh.positions.len()];
    for ((a, b), faces) in vstree::topology::edges_and_face_counts(&mesh.triangles) {
        if faces == 1 {
            let (ra, rb) = (root(&mut parent, a as usize), root(&mut parent, b as usize));
            parent[ra] = rb;
            on_border[a as usize] = true;
            on_border[b as usize] = true;
        }
    }
    (0..parent.len()).filter(|&v| on_border[v] && root(&mut parent, v) == v).count()
}

#[test]
fn scans_with_holes_keep_them_by_default_and_non_manifold_input_is_clustered_plainly() {
    // A sphere with three holes, as a scan has where the scanner saw nothing: edge-manifold,
    // so the default keeps its topology; each hole spans a few hundred input triangles, far
    // more than the smallest targets' clusters.
    let sphere = shapes::icosphere(1.0, 5);
    let holes = [Vec3::X, Vec3::Y, -Vec3::Z];
    let near_a_hole = |t: &[u32; 3]| {
        let c = t.iter().map(|&v| sphere.positions[v as usize]).sum::<Vec3>() / 3.0;
        holes.iter().any(|h| c.distance(*h) < 0.25)
    };
    let holey = Mesh::new(
        sphere.positions.clone(),
        None,
        sphere.triangles.iter().filter(|t| !near_a_hole(t)).copied().collect(),
    );
    assert_eq!(border_loops(&holey), 3);
    for target in [2000, 500, 100] {
        let (out, stats) = to_size(&holey, target, KeepTopology::Auto);
        let r = analyze(&out);
        assert!(stats.kept_topology, "at {target}: an edge-manifold input, topology not kept by default");
        assert_eq!((r.non_manifold_edges, r.non_manifold_vertices, r.components), (0, 0, 1), "at {target}: {r:?}");
        assert_eq!(border_loops(&out), 3, "at {target}: a hole closed or split");
        assert!(close_enough(out.triangles.len(), target), "{} for {target}", out.triangles.len());
    }
    // A fin on one of the sphere's edges: three faces there, non-manifold, plain clustering.
    let [a, b, _] = sphere.triangles[0];
    let mut positions = sphere.positions.clone();
    positions.push(0.75 * (positions[a as usize] + positions[b as usize]));
    let mut triangles = sphere.triangles.clone();
    triangles.push([a, b, positions.len() as u32 - 1]);
    let finned = Mesh::new(positions, None, triangles);
    assert!(!to_size(&finned, 500, KeepTopology::Auto).1.kept_topology);
}

/// Every shared and corpus mesh at 2% and 0.5% of its triangles: the count; for edge-manifold
/// inputs (the default keeps their topology) zero non-manifold edges, the components and the
/// border loops kept, and for closed ones watertightness and genus; where the topology needs
/// more triangles than asked, the smallest mesh. Skipped without ../shared/data.
#[test]
fn real_models_reach_two_and_a_half_percent() {
    let mut closed = 0;
    for (name, mesh) in common::all_models().into_iter().chain(common::corpus_models()) {
        if mesh.is_point_cloud() {
            continue;
        }
        let input = analyze(&mesh);
        for percent in [2.0, 0.5] {
            let target = ((mesh.triangles.len() as f64 * percent / 100.0).round() as usize).max(1);
            let (out, stats) = to_size(&mesh, target, KeepTopology::Auto);
            let r = analyze(&out);
            eprintln!(
                "{name} at {percent}%: {} -> {} triangles (target {target}), kept {}, genus {:?} -> {:?}, non-manifold edges {}",
                mesh.triangles.len(),
                out.triangles.len(),
                stats.kept_topology,
                input.genus(),
                r.genus(),
                r.non_manifold_edges
            );
            if input.non_manifold_edges == 0 {
                assert!(stats.kept_topology, "{name}: edge-manifold, topology not kept by default");
                assert_eq!(r.non_manifold_edges, 0, "{name} at {percent}%");
                assert_eq!(r.components, input.components, "{name} at {percent}%");
                assert_eq!(border_loops(&out), border_loops(&mesh), "{name} at {percent}%: holes");
            }
            if input.is_watertight() {
                assert!(r.is_watertight() && r.non_manifold_edges == 0, "{name} at {percent}%: {r:?}");
                assert_eq!((r.genus(), r.components), (input.genus(), input.components), "{name} at {percent}%");
                let reachable = target.max(floor(&input));
                assert!(
                    close_enough(out.triangles.len(), target) || out.triangles.len() <= 2 * reachable,
                    "{name} at {percent}%: {} for {target}",
                    out.triangles.len()
                );
            } else {
                assert!(close_enough(out.triangles.len(), target), "{name} at {percent}%: {}", out.triangles.len());
            }
        }
        closed += usize::from(input.is_watertight());
    }
    if common::data_dir().is_some() {
        assert!(closed >= 20, "only {closed} closed models found");
    }
}
