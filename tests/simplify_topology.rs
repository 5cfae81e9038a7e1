//! Simplification that keeps topology (`SimplifyParams::keep_topology`): a closed 2-manifold
//! gives a closed 2-manifold of the same genus, where plain vertex clustering fuses sheets.

mod common;

use vstree::topology::analyze;
use vstree::tree::TreeParams;
use vstree::{eval::shapes, simplify, Mesh, Progress, SimplifyParams};

fn simplified(mesh: &Mesh, error: f64, keep_topology: bool) -> Mesh {
    let keep_topology = if keep_topology { vstree::KeepTopology::On } else { vstree::KeepTopology::Off };
    let params =
        SimplifyParams { tree: TreeParams { error, ..Default::default() }, keep_topology, ..Default::default() };
    simplify(mesh, &params, &mut Progress::none()).unwrap().0
}

#[test]
fn closed_shapes_stay_closed_with_their_genus() {
    let mut plain_broke = 0;
    for (name, mesh, genus) in [
        ("sphere", shapes::icosphere(1.0, 5), 0),
        ("torus", shapes::torus(1.0, 0.3, 192, 96), 1),
        ("double torus", shapes::double_torus(), 2),
        ("pretzel", shapes::genus_n_pretzel(3), 3),
    ] {
        for error in [1e-4, 1e-3, 1e-2] {
            let kept = simplified(&mesh, error, true);
            let r = analyze(&kept);
            assert!(r.is_watertight(), "{name} at {error}: {r:?}");
            assert_eq!((r.non_manifold_edges, r.components, r.genus()), (0, 1, Some(genus)), "{name} at {error}");
            assert!(kept.triangles.len() < mesh.triangles.len(), "{name} at {error}: not simplified");
            let plain = analyze(&simplified(&mesh, error, false));
            if !plain.is_watertight() || plain.genus() != Some(genus) {
                plain_broke += 1;
            }
        }
    }
    // The cases are coarse enough that plain clustering breaks some: the test can tell.
    assert!(plain_broke > 0, "plain clustering kept every topology: the cases are too easy");
}

#[test]
fn an_open_sheet_keeps_its_border_manifold() {
    // A sphere with its top cap removed: one border loop.
    let sphere = shapes::icosphere(1.0, 5);
    let triangles: Vec<[u32; 3]> =
        sphere.triangles.iter().filter(|t| t.iter().any(|&v| sphere.positions[v as usize].z < 0.5)).copied().collect();
    let open = Mesh::new(sphere.positions.clone(), None, triangles);
    let before = analyze(&open);
    assert!(before.boundary_edges > 0 && before.non_manifold_edges == 0 && before.non_manifold_vertices == 0);
    for error in [1e-4, 1e-3, 1e-2] {
        let r = analyze(&simplified(&open, error, true));
        assert_eq!((r.non_manifold_edges, r.non_manifold_vertices, r.components), (0, 0, 1), "at {error}: {r:?}");
        assert!(r.boundary_edges > 0, "at {error}: the border closed");
    }
}

/// On the real models, at the paper's bound and a coarse one: zero non-manifold edges and the
/// input's genus for every closed manifold input (skipped without ../shared/data).
#[test]
fn real_closed_models_keep_their_topology() {
    let mut checked = 0;
    for (name, mesh) in common::all_models().into_iter().chain(common::corpus_models()) {
        let input = analyze(&mesh);
        if mesh.is_point_cloud() || !input.is_watertight() || input.non_manifold_vertices > 0 {
            continue;
        }
        for error in [1e-4, 1e-3] {
            let out = simplified(&mesh, error, true);
            let r = analyze(&out);
            eprintln!(
                "{name} at {error}: {} -> {} triangles, genus {:?} -> {:?}, non-manifold edges {}",
                mesh.triangles.len(),
                out.triangles.len(),
                input.genus(),
                r.genus(),
                r.non_manifold_edges
            );
            assert!(r.is_watertight() && r.non_manifold_edges == 0, "{name} at {error}: {r:?}");
            assert_eq!((r.genus(), r.components), (input.genus(), input.components), "{name} at {error}");
        }
        checked += 1;
    }
    if common::data_dir().is_some() {
        assert!(checked >= 10, "only {checked} closed models found");
    }
}
