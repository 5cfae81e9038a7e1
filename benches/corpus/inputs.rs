//! The clouds of the corpus bench and the meshes they are measured against: points sampled on
//! the closed meshes of `../shared/data/corpus` and `../shared/data` (exact normals, no normals,
//! noisy positions), and synthetic cases whose answer is known: an open hemisphere, single-view
//! scans of corpus meshes, and one unit sphere at the origin and far from it.

use glam::{DVec3, Vec3};
use rayon::prelude::*;
use std::borrow::Cow;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use vstree::eval::shapes::{add_noise, icosphere, sample_surface};
use vstree::{io, topology, Mesh};

/// The generalisation corpus (`corpus/README.md`): file, components, total genus.
pub const CORPUS: [(&str, usize, u32); 16] = [
    ("bear.off", 1, 0),
    ("bull.off", 1, 0),
    ("camel.off", 1, 0),
    ("cheese.off", 1, 133),
    ("couplingdown.off", 1, 9),
    ("dino.off", 1, 0),
    ("fandisk_large.off", 1, 0),
    ("femur.off", 1, 2),
    ("homer.off", 1, 0),
    ("knot2.off", 2, 2),
    ("man.off", 1, 0),
    ("refined_elephant.off", 1, 3),
    ("retinal.off", 1, 0),
    ("rotor_small.off", 1, 1),
    ("triceratops.off", 1, 0),
    ("turbine.off", 1, 11),
];

/// Meshes of `../shared/data` that may be closed; each is checked with `vstree::topology` and
/// left out (with a note) when it is not.
pub const SHARED: [&str; 8] = [
    "igea.ply",
    "armadillo_43k.obj",
    "lucy_100k.ply",
    "nefertiti.obj",
    "fertility_20k.off",
    "3holes.off",
    "knot1.off",
    "rocker_arm.obj",
];

/// Corpus meshes scanned from one direction.
pub const SINGLE_VIEWS: [&str; 4] = ["bear", "homer", "fandisk_large", "triceratops"];

/// The models of `--quick` (small, with handles, and one of the single views).
pub const QUICK_MODELS: [&str; 3] = ["bull", "femur", "triceratops"];

/// Seeds: every run draws the same points.
const SAMPLE_SEED: u64 = 2006;
const NOISE_SEED: u64 = 7;
const TRUTH_SEED: u64 = 77;
/// Points sampled on the ground truth for its side of the two-sided distances.
pub const TRUTH_SAMPLES: usize = 200_000;
/// Per-axis standard deviation of the position noise, over the bounding-box diagonal: what a
/// good scanner leaves ([`Variant::Noisy`]), and twice that, a poor one ([`Variant::VeryNoisy`]).
pub const NOISE: f32 = 0.0025;
pub const HIGH_NOISE: f32 = 0.005;
/// Direction of the single-view scans (towards the viewer) and the z-buffer's resolution.
pub const VIEW: Vec3 = Vec3::new(1.0, 2.0, 3.0);
pub const ZBUFFER: usize = 1024;
/// Offsets of the far spheres (the centre is at (d, d, d)).
pub const OFFSETS: [f64; 2] = [1e6, 1e8];

/// What a reconstruction is measured against.
pub struct Truth {
    /// The mesh the points were sampled on (for a single view, its visible part).
    pub mesh: Mesh,
    /// `TRUTH_SAMPLES` points on it, measured to each output.
    pub points: Vec<Vec3>,
    pub diagonal: f32,
    /// `None` for an open surface.
    pub genus: Option<u32>,
    pub components: usize,
    pub open: bool,
}

impl Truth {
    fn new(mesh: Mesh, open: bool) -> Truth {
        let report = topology::analyze(&mesh);
        let points = sample_surface(&mesh, TRUTH_SAMPLES, TRUTH_SEED).positions;
        let diagonal = mesh.bounds().map_or(1.0, |b| b.diagonal());
        Truth { genus: report.genus(), components: report.components, mesh, points, diagonal, open }
    }
}

/// How a cloud was made from its surface.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Variant {
    /// Exact normals: the normal of the triangle each point lies on.
    Clean,
    /// No normals: vstree estimates them.
    NoNormals,
    /// Gaussian noise of [`NOISE`] of the diagonal on the positions, exact normals kept.
    Noisy,
    /// The same with [`HIGH_NOISE`].
    VeryNoisy,
    /// Exact normals, open (hemisphere) or seen from one side (single view).
    Open,
    /// Exact normals, read back from a text file in f64 (spheres near and far from the origin).
    Text,
}

impl Variant {
    pub const SAMPLED: [Variant; 4] = [Variant::Clean, Variant::NoNormals, Variant::Noisy, Variant::VeryNoisy];

    pub fn name(self) -> &'static str {
        match self {
            Variant::Clean => "clean",
            Variant::NoNormals => "no normals",
            Variant::Noisy => "noise 0.25%",
            Variant::VeryNoisy => "noise 0.5%",
            Variant::Open => "open",
            Variant::Text => "f64 text",
        }
    }

    /// The name in output files and on the command line (`--variants`).
    pub fn file_name(self) -> &'static str {
        match self {
            Variant::Clean => "clean",
            Variant::NoNormals => "nonormals",
            Variant::Noisy => "noisy",
            Variant::VeryNoisy => "noisy05",
            Variant::Open => "open",
            Variant::Text => "text",
        }
    }
}

/// A mesh model and where it comes from.
pub struct Model {
    pub name: String,
    pub path: PathBuf,
    /// In the corpus (the genus count is over these).
    pub corpus: bool,
    /// The README's genus and components, for the corpus.
    pub listed: Option<(usize, u32)>,
}

/// Every model, corpus first; `stem` names them.
pub fn models(data: &Path) -> Vec<Model> {
    let corpus = CORPUS.iter().map(|&(file, components, genus)| Model {
        name: stem(file).to_string(),
        path: data.join("corpus").join(file),
        corpus: true,
        listed: Some((components, genus)),
    });
    let shared = SHARED.iter().map(|file| Model {
        name: stem(file).to_string(),
        path: data.join(file),
        corpus: false,
        listed: None,
    });
    corpus.chain(shared).collect()
}

pub fn stem(file: &str) -> &str {
    file.rsplit_once('.').map_or(file, |(s, _)| s)
}

/// A model's mesh as ground truth, or why it cannot be one (unreadable, not closed, or not as
/// the README says).
pub fn load(model: &Model) -> Result<Truth, String> {
    let mut mesh = io::read(&model.path).map_err(|e| e.to_string())?;
    // Exact normals are the triangles' own: vertex normals (some files have them) are dropped.
    mesh.normals = None;
    let report = topology::analyze(&mesh);
    if !report.is_watertight() {
        return Err(format!(
            "not closed ({} boundary edges, {} non-manifold edges, {} inconsistently oriented)",
            report.boundary_edges, report.non_manifold_edges, report.inconsistently_oriented_edges
        ));
    }
    if let Some((components, genus)) = model.listed {
        if report.components != components || report.genus() != Some(genus) {
            return Err(format!(
                "README says genus {genus}, {components} components; topology finds {:?}, {}",
                report.genus(),
                report.components
            ));
        }
    }
    Ok(Truth::new(mesh, false))
}

/// The cloud of `count` points of `variant` on `truth`.
pub fn sampled(truth: &Truth, count: usize, variant: Variant) -> Mesh {
    let mut cloud = sample_surface(&truth.mesh, count, SAMPLE_SEED);
    match variant {
        Variant::NoNormals => cloud.normals = None,
        Variant::Noisy => add_noise(&mut cloud, NOISE * truth.diagonal, 0.0, NOISE_SEED),
        Variant::VeryNoisy => add_noise(&mut cloud, HIGH_NOISE * truth.diagonal, 0.0, NOISE_SEED),
        _ => {}
    }
    cloud
}

/// The unit hemisphere z >= 0 as a fine latitude-longitude mesh (open along the equator).
pub fn hemisphere_mesh() -> Mesh {
    let (rings, segments) = (128u32, 512u32);
    let mut positions = vec![Vec3::Z];
    for i in 1..=rings {
        let theta = std::f32::consts::FRAC_PI_2 * i as f32 / rings as f32;
        for j in 0..segments {
            let phi = std::f32::consts::TAU * j as f32 / segments as f32;
            positions.push(Vec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()));
        }
    }
    let v = |i: u32, j: u32| 1 + (i - 1) * segments + j % segments;
    let mut triangles = Vec::new();
    for j in 0..segments {
        triangles.push([0, v(1, j), v(1, j + 1)]);
    }
    for i in 1..rings {
        for j in 0..segments {
            triangles.push([v(i, j), v(i + 1, j), v(i + 1, j + 1)]);
            triangles.push([v(i, j), v(i + 1, j + 1), v(i, j + 1)]);
        }
    }
    Mesh::new(positions, None, triangles)
}

/// Points on the unit sphere (or hemisphere) drawn on `mesh`, moved onto the true surface,
/// with its exact normals.
fn on_unit_sphere(mesh: &Mesh, count: usize) -> Mesh {
    let mut cloud = sample_surface(mesh, count, SAMPLE_SEED);
    let positions: Vec<Vec3> = cloud.positions.iter().map(|p| p.normalize()).collect();
    cloud.normals = Some(positions.clone());
    cloud.positions = positions;
    cloud
}

/// The hemisphere's truth and `count` points on it.
pub fn hemisphere(count: usize) -> (Truth, Mesh) {
    let mesh = hemisphere_mesh();
    let cloud = on_unit_sphere(&mesh, count);
    (Truth::new(mesh, true), cloud)
}

/// The unit sphere (truth) and `count` points on it.
pub fn sphere(count: usize) -> (Truth, Mesh) {
    let mesh = icosphere(1.0, 6);
    let cloud = on_unit_sphere(&mesh, count);
    (Truth::new(mesh, false), cloud)
}

/// `cloud` moved by `offset` in f64, written as text (`x y z nx ny nz`, every coordinate in
/// f64's shortest round-trip form) to `path` and read back with `vstree::io::read`: the f64
/// reading path, with the origin the reader picks.
pub fn through_text(cloud: &Mesh, offset: DVec3, path: &Path) -> Result<Mesh, String> {
    let normals = cloud.normals.as_deref().unwrap_or(&[]);
    let mut text = String::with_capacity(cloud.positions.len() * 120);
    for (i, p) in cloud.positions.iter().enumerate() {
        let a = offset + p.as_dvec3();
        let n = normals.get(i).copied().unwrap_or(Vec3::Z);
        let _ = writeln!(text, "{} {} {} {} {} {}", a.x, a.y, a.z, n.x, n.y, n.z);
    }
    std::fs::write(path, text).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    io::read(path).map_err(|e| e.to_string())
}

/// A mesh's positions relative to `offset` (where its truth is at the origin), computed in
/// f64 from its own origin: what is measured against the truth. A mesh already there is
/// borrowed, not copied.
pub fn local(mesh: &Mesh, offset: DVec3) -> Cow<'_, Mesh> {
    let shift = mesh.origin - offset;
    if shift == DVec3::ZERO && mesh.origin == DVec3::ZERO {
        return Cow::Borrowed(mesh);
    }
    if shift == DVec3::ZERO {
        return Cow::Owned(Mesh { origin: DVec3::ZERO, ..mesh.clone() });
    }
    let positions = mesh.positions.par_iter().map(|p| (shift + p.as_dvec3()).as_vec3()).collect();
    Cow::Owned(Mesh {
        positions,
        normals: mesh.normals.clone(),
        triangles: mesh.triangles.clone(),
        origin: DVec3::ZERO,
    })
}

/// An orthographic depth buffer of a mesh seen along [`VIEW`]: depth = position · view (larger
/// is nearer the viewer), the largest per pixel.
struct DepthBuffer {
    u: Vec3,
    v: Vec3,
    w: Vec3,
    min: [f32; 2],
    pixel: f32,
    depth: Vec<f32>,
}

impl DepthBuffer {
    fn new(mesh: &Mesh) -> DepthBuffer {
        let w = VIEW.normalize();
        let (u, v) = w.any_orthonormal_pair();
        let projected: Vec<[f32; 2]> = mesh.positions.iter().map(|p| [p.dot(u), p.dot(v)]).collect();
        let (mut lo, mut hi) = ([f32::MAX; 2], [f32::MIN; 2]);
        for q in &projected {
            for k in 0..2 {
                lo[k] = lo[k].min(q[k]);
                hi[k] = hi[k].max(q[k]);
            }
        }
        let pixel = (hi[0] - lo[0]).max(hi[1] - lo[1]) / (ZBUFFER - 1) as f32;
        let mut buffer = DepthBuffer { u, v, w, min: lo, pixel, depth: vec![f32::NEG_INFINITY; ZBUFFER * ZBUFFER] };
        for t in &mesh.triangles {
            let [a, b, c] = t.map(|i| buffer.to_pixels(projected[i as usize]));
            let [za, zb, zc] = t.map(|i| mesh.positions[i as usize].dot(w));
            let area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
            if area.abs() < 1e-12 {
                continue;
            }
            let x0 = a[0].min(b[0]).min(c[0]).ceil().max(0.0) as usize;
            let x1 = (a[0].max(b[0]).max(c[0]).floor() as usize).min(ZBUFFER - 1);
            let y0 = a[1].min(b[1]).min(c[1]).ceil().max(0.0) as usize;
            let y1 = (a[1].max(b[1]).max(c[1]).floor() as usize).min(ZBUFFER - 1);
            for y in y0..=y1 {
                for x in x0..=x1 {
                    let (px, py) = (x as f32, y as f32);
                    let edge = |p: [f32; 2], q: [f32; 2]| (q[0] - p[0]) * (py - p[1]) - (q[1] - p[1]) * (px - p[0]);
                    let (l0, l1, l2) = (edge(b, c) / area, edge(c, a) / area, edge(a, b) / area);
                    if l0 < -1e-6 || l1 < -1e-6 || l2 < -1e-6 {
                        continue;
                    }
                    let z = l0 * za + l1 * zb + l2 * zc;
                    let d = &mut buffer.depth[y * ZBUFFER + x];
                    *d = d.max(z);
                }
            }
        }
        buffer
    }

    fn to_pixels(&self, q: [f32; 2]) -> [f32; 2] {
        [(q[0] - self.min[0]) / self.pixel, (q[1] - self.min[1]) / self.pixel]
    }

    /// Whether `p` on a surface of normal `n` is seen: facing the viewer, and no nearer than
    /// two pixels behind the depth at its pixel (its own surface, within the slope of a
    /// surface up to about 63 degrees from facing).
    fn sees(&self, p: Vec3, n: Vec3) -> bool {
        if n.dot(self.w) <= 0.0 {
            return false;
        }
        let [x, y] = self.to_pixels([p.dot(self.u), p.dot(self.v)]);
        let (x, y) = ((x.round() as usize).min(ZBUFFER - 1), (y.round() as usize).min(ZBUFFER - 1));
        p.dot(self.w) >= self.depth[y * ZBUFFER + x] - 2.0 * self.pixel
    }
}

/// A single-view scan of `truth`: the points of a `count`-point sampling that the viewer (far
/// along [`VIEW`]) sees, found with a z-buffer of [`ZBUFFER`]² pixels, with exact normals; and
/// the truth it is measured against: the triangles whose centroid is seen.
pub fn single_view(truth: &Truth, count: usize) -> (Truth, Mesh) {
    let buffer = DepthBuffer::new(&truth.mesh);
    let all = sample_surface(&truth.mesh, count, SAMPLE_SEED);
    let normals = all.normals.as_deref().unwrap_or(&[]);
    let (positions, normals): (Vec<Vec3>, Vec<Vec3>) =
        all.positions.iter().zip(normals).filter(|(p, n)| buffer.sees(**p, **n)).map(|(p, n)| (*p, *n)).unzip();
    let p = &truth.mesh.positions;
    let triangles: Vec<[u32; 3]> = truth
        .mesh
        .triangles
        .iter()
        .filter(|t| {
            let [a, b, c] = t.map(|i| p[i as usize]);
            buffer.sees((a + b + c) / 3.0, (b - a).cross(c - a).normalize_or_zero())
        })
        .copied()
        .collect();
    let visible = Mesh::new(truth.mesh.positions.clone(), None, triangles);
    (Truth::new(visible, true), Mesh::from_points(positions, Some(normals)))
}
