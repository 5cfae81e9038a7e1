//! Every real model in `../shared/data` loads with the counts its README gives.
//! The folder is not part of the repository; without it these tests pass with a message (and
//! fail under CI).

mod common;

use common::data_dir;
use vstree::io;

/// `(file, vertices, faces, has normals)` from the README; `None` where it gives no exact count.
const EXPECTED: &[(&str, Option<usize>, usize, bool)] = &[
    ("bunny_zipper.ply", Some(35_947), 69_451, false),
    ("bunny_raw_bun000.ply", None, 0, false),
    ("bunny_scans_merged.ply", Some(362_272), 0, false),
    ("igea.ply", Some(134_345), 268_686, false),
    ("armadillo_43k.obj", Some(43_243), 86_482, false),
    ("armadillo_points_normals.ply", Some(38_294), 0, true),
    ("happy_buddha_100k.obj", Some(49_950), 100_000, false),
    ("lucy_100k.ply", Some(49_987), 99_970, false),
    ("horse.ply", Some(48_485), 96_966, false),
    ("nefertiti.obj", Some(49_971), 99_938, false),
    ("turbine_blade.ply", Some(99_519), 199_034, false),
    ("fertility_20k.off", Some(9_994), 20_000, false),
    ("rocker_arm.obj", Some(10_044), 20_088, false),
    ("3holes.off", Some(3_596), 7_200, false),
    ("lion_takanawa.ply", Some(341_989), 0, true),
    ("kitten.xyz", Some(5_210), 0, true),
    ("oni.pwn", Some(1_435), 0, true),
    ("cube.pwn", Some(50_000), 0, true),
    ("ball.ply", Some(31_374), 0, true),
    ("fandisk.off", Some(6_475), 12_946, false),
    ("knot1.off", Some(3_200), 6_400, false),
    ("eight.off", Some(315), 634, false),
];

#[test]
fn real_models_load_with_readme_counts() {
    let Some(dir) = data_dir() else { return };
    for &(name, vertices, faces, normals) in EXPECTED {
        let mesh = io::read(&dir.join(name)).unwrap_or_else(|e| panic!("{e}"));
        match vertices {
            Some(n) => assert_eq!(mesh.positions.len(), n, "{name} vertices"),
            // "~40,000" in the README.
            None => assert!((38_000..42_000).contains(&mesh.positions.len()), "{name}"),
        }
        assert_eq!(mesh.triangles.len(), faces, "{name} faces");
        assert_eq!(mesh.normals.is_some(), normals, "{name} normals");
        mesh.check().unwrap_or_else(|e| panic!("{name}: {e}"));
    }
}

#[test]
fn every_readable_file_in_the_folder_loads() {
    let Some(dir) = data_dir() else { return };
    let mut seen = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if io::Format::from_path(&path).is_none() {
            continue;
        }
        let mesh = io::read(&path).unwrap_or_else(|e| panic!("{e}"));
        assert!(!mesh.positions.is_empty(), "{}", path.display());
        seen += 1;
    }
    assert!(seen >= EXPECTED.len());
}

#[test]
fn real_models_survive_a_binary_ply_cycle() {
    let Some(dir) = data_dir() else { return };
    let out = std::env::temp_dir().join(format!("vstree-io-real-{}", std::process::id()));
    std::fs::create_dir_all(&out).unwrap();
    for name in ["horse.ply", "kitten.xyz", "eight.off", "lion_takanawa.ply"] {
        let mesh = io::read(&dir.join(name)).unwrap();
        let copy = out.join("copy.ply");
        io::write(&copy, &mesh).unwrap();
        assert_eq!(io::read(&copy).unwrap(), mesh, "{name}");
    }
    std::fs::remove_dir_all(&out).unwrap();
}
