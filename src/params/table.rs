//! The rows of the parameter table: every parameter, each call's in its C struct's field
//! order, and the choices of the choice parameters.

use super::{Call, Choice, Kind, Param};

const TREE_KINDS: &[Choice] = &[
    Choice {
        value: 0,
        name: "vstree",
        label: "VS-Tree",
        help: "Octree far from the surface, quadtrees in its tangent planes near it (the paper's).",
    },
    Choice {
        value: 1,
        name: "octree",
        label: "Octree",
        help: "A plain octree with the same metric and bound: the baseline to compare with.",
    },
];

const METRICS: &[Choice] = &[
    Choice {
        value: 0,
        name: "l2",
        label: "L2 (quadric)",
        help: "Quadric error: how far the cluster's point is from its samples' tangent planes.",
    },
    Choice {
        value: 1,
        name: "l21",
        label: "L2,1 (normal deviation)",
        help: "Normal deviation: how much the cluster's normals differ from their mean.",
    },
    Choice {
        value: 2,
        name: "density",
        label: "Density (samples)",
        help: "Sample count: at most `error` samples per cluster (cheap, for huge inputs).",
    },
];

const SAMPLINGS: &[Choice] = &[
    Choice {
        value: 0,
        name: "vertices",
        label: "Vertices",
        help: "One sample per vertex (normal: area-weighted face normals).",
    },
    Choice { value: 1, name: "faces", label: "Face centers", help: "One sample per face, at its centre." },
];

const KEEP_TOPOLOGY: &[Choice] = &[
    Choice {
        value: 0,
        name: "auto",
        label: "Auto (edge-manifold inputs)",
        help: "Kept when no edge has more than two triangles (closed, or with borders as scans have); plain \
               clustering on non-manifold input.",
    },
    Choice {
        value: 1,
        name: "on",
        label: "On",
        help: "Clusters merge by edge collapses that keep the genus, the borders manifold and the holes open; a \
               cluster that cannot merge keeps a vertex per piece.",
    },
    Choice {
        value: 2,
        name: "off",
        label: "Off",
        help: "Plain vertex clustering (the paper's): faster, but close sheets may fuse into non-manifold edges.",
    },
];

const ORIENTATIONS: &[Choice] = &[
    Choice {
        value: 0,
        name: "unoriented",
        label: "Unoriented",
        help: "Signs as the estimate gives them: not consistent.",
    },
    Choice {
        value: 1,
        name: "propagate",
        label: "Propagate",
        help: "Consistent by a minimum spanning tree over the neighbours (Hoppe et al. 1992), +z where the \
               highest point's normal points down.",
    },
    Choice {
        value: 2,
        name: "propagate_majority",
        label: "Propagate (majority)",
        help: "Consistent by the spanning tree, each component the sign most given normals have.",
    },
    Choice {
        value: 3,
        name: "propagate_outward",
        label: "Propagate outward",
        help: "Consistent by the spanning tree, each component turned to face outward.",
    },
];

const CLOSURES: &[Choice] = &[
    Choice {
        value: 0,
        name: "auto",
        label: "Auto (open scans stay open)",
        help: "Open where much of the closed surface (30%) has no sample near it, as behind a scan from one \
               side; closed otherwise.",
    },
    Choice {
        value: 1,
        name: "closed",
        label: "Closed",
        help: "Always closed, over holes and the back of an open scan.",
    },
    Choice {
        value: 2,
        name: "open",
        label: "Open",
        help: "Only the part of the surface the samples support: a scan's holes stay open too.",
    },
];

const BASE_MESHES: &[Choice] = &[
    Choice {
        value: 0,
        name: "winding",
        label: "Winding number, grid",
        help: "The points' winding number says inside or outside, polygonised on a grid as fine as the \
               smallest T-node.",
    },
    Choice {
        value: 1,
        name: "paper",
        label: "Paper (T-node planes)",
        help: "The paper's construction: the T-nodes' planes blended near the points (to compare with).",
    },
    Choice {
        value: 2,
        name: "adaptive",
        label: "Winding number, adaptive",
        help: "The winding number's side, polygonised over the tree's octree, each region at its own \
               T-node's size. The default.",
    },
];

/// The tree's fields, shared by simplification and reconstruction.
const fn tree_kind(call: Call) -> Param {
    Param::new(call, "tree_kind", "Tree", Kind::Choice, "Hierarchy: the VS-Tree, or a plain octree (the baseline).")
        .flag("tree")
        .choices(TREE_KINDS, 0)
}

const fn metric(call: Call) -> Param {
    Param::new(call, "metric", "Metric", Kind::Choice, "Error metric that decides when a cell is split.")
        .flag("metric")
        .choices(METRICS, 0)
}

const fn d_a(call: Call) -> Param {
    Param::new(
        call,
        "d_a",
        "d_a (normal cone)",
        Kind::Real,
        "Height-field test, normal cone: a cell becomes a surface (2D) node only if every normal's dot product \
         with the mean normal exceeds it. Raise it for more adaptivity on curved parts.",
    )
    .flag("da")
    .range(0.0, 1.0)
}

const fn d_d(call: Call) -> Param {
    Param::new(
        call,
        "d_d",
        "d_d (displacement)",
        Kind::Real,
        "Height-field test, displacement: a cell's height range over its radius must stay below it. Lower it \
         for more adaptivity on curved parts.",
    )
    .flag("dd")
    .range(0.0, 1.0)
    .default(1.0 / 6.0)
}

const fn max_depth(call: Call) -> Param {
    Param::new(call, "max_depth", "Max depth", Kind::Integer, "Deepest tree level (octree and quadtree levels).")
        .flag("max-depth")
        .range(1.0, crate::tree::MAX_DEPTH as f64)
        .default(24.0)
        .unit("levels")
}

const fn min_cell_size(call: Call) -> Param {
    Param::new(
        call,
        "min_cell_size",
        "Min cell size",
        Kind::Real,
        "Cells smaller than this are not split: guards against duplicate points.",
    )
    .flag("min-cell-size")
    .range(0.0, 1.0)
    .open(false, true)
    .default(1e-7)
    .unit("bounding-box diagonals")
}

const fn threads(call: Call) -> Param {
    Param::new(call, "threads", "Threads", Kind::Integer, "Worker threads (0 = all cores).")
        .flag("threads")
        .range(0.0, crate::progress::Threads::MAX as f64)
}

const fn orient(call: Call) -> Param {
    Param::new(call, "orient", "Orient", Kind::Choice, "How the signs of estimated normals are chosen.")
        .choices(ORIENTATIONS, 3)
}

const fn neighbours(call: Call) -> Param {
    Param::new(call, "neighbours", "Neighbours", Kind::Integer, "Neighbours used to estimate each normal.")
        .flag("neighbours")
        .range(crate::normals::MIN_NEIGHBOURS as f64, crate::normals::MAX_NEIGHBOURS as f64)
        .default(crate::normals::DEFAULT_NEIGHBOURS as f64)
        .unit("points")
}

const fn reorient_given(call: Call) -> Param {
    Param::new(
        call,
        "reorient_given",
        "Re-orient given normals",
        Kind::Flag,
        "Re-orient the normals the cloud already has: made consistent over the neighbours, then signed by \
         `orient`. Clouds without normals always get them estimated.",
    )
    .flag("reorient")
    .range(0.0, 1.0)
}

/// The L2 bound's description, for both calls.
const L2_UNIT: &str = "squared bounding-box diagonals";

pub const SIMPLIFY_ERROR: Param = Param::new(
    Call::Simplify,
    "error",
    "Error bound",
    Kind::Real,
    "Error bound per cluster. L2: sum of squared sample-plane distances over the squared bounding-box diagonal \
     (every sample's tangent plane then passes within sqrt(error) x diagonal of its cluster's point); l21: mean \
     squared normal deviation, in (0, 4]; density: samples per cluster, at least 1 (each metric has its own \
     default). Larger = coarser. Not used when a size is asked.",
)
.flag("error")
.open(true, false)
.default(1e-3)
.unit(L2_UNIT);

pub const SIMPLIFY_SAMPLING: Param =
    Param::new(Call::Simplify, "sampling", "Sampling", Kind::Choice, "Which mesh elements become samples.")
        .flag("sampling")
        .choices(SAMPLINGS, 0);

pub const SIMPLIFY_KEEP_TOPOLOGY: Param = Param::new(
    Call::Simplify,
    "keep_topology",
    "Keep topology",
    Kind::Choice,
    "Whether the topology is kept: genus, components, borders and holes.",
)
.choices(KEEP_TOPOLOGY, 0);

pub const SIMPLIFY_TARGET_FACES: Param = Param::new(
    Call::Simplify,
    "target_faces",
    "Target number of faces",
    Kind::Integer,
    "Triangles wanted (instead of the error bound): the tree is grown or cut and quadric edge collapses bring \
     the mesh to this count (within one triangle). Below what the topology allows, the smallest mesh \
     reachable. 0 = use the error bound.",
)
.flag("faces")
.range(0.0, u32::MAX as f64)
.unit("triangles");

pub const RECONSTRUCT_ERROR: Param = Param::new(
    Call::Reconstruct,
    "error",
    "Error bound",
    Kind::Real,
    "The tree's L2 bound per cluster: sum of squared sample-plane distances over the squared bounding-box \
     diagonal. The de-noising control: larger = smoother, fewer details.",
)
.flag("error")
.open(true, false)
.default(1e-5)
.unit(L2_UNIT);

pub const RECONSTRUCT_TARGET_DISTANCE: Param = Param::new(
    Call::Reconstruct,
    "target_distance",
    "Target distance",
    Kind::Real,
    "Stop refining once the RMS distance from the samples to the mesh is at most this, splitting only the \
     regions whose samples are farther (0 = refine everywhere while the tree has detail left).",
)
.flag("target")
.unit("bounding-box diagonals");

pub const RECONSTRUCT_MAX_LEVELS: Param = Param::new(
    Call::Reconstruct,
    "max_levels",
    "Refinement levels",
    Kind::Integer,
    "Most refinement levels after the base mesh (each one multiplies the triangles by 4).",
)
.flag("levels")
.range(0.0, 12.0)
.default(6.0)
.unit("levels");

pub const RECONSTRUCT_MIN_DISPLACED: Param = Param::new(
    Call::Reconstruct,
    "min_displaced",
    "Min displaced",
    Kind::Real,
    "A level that displaces fewer than this share of its new vertices ends refinement: the quadtrees have no \
     detail left.",
)
.range(0.0, 1.0)
.default(0.02)
.unit("share of a level's new vertices");

pub const RECONSTRUCT_MAX_TRIANGLES: Param = Param::new(
    Call::Reconstruct,
    "max_triangles",
    "Max triangles",
    Kind::Integer,
    "No refinement level is started that would exceed this many triangles.",
)
.range(1.0, u32::MAX as f64)
.default(20_000_000.0)
.unit("triangles");

pub const RECONSTRUCT_MAX_GRID_DEPTH: Param = Param::new(
    Call::Reconstruct,
    "max_grid_depth",
    "Grid depth",
    Kind::Integer,
    "The polygonisation grid is as fine as the deepest T-node, but never finer than 2^this cells across.",
)
.range(4.0, 20.0)
.default(10.0)
.unit("levels");

pub const RECONSTRUCT_TRIM: Param = Param::new(
    Call::Reconstruct,
    "trim",
    "Trim",
    Kind::Real,
    "Remove every face farther than this from every sample, and make the output open (0 = no such trimming: \
     open scans are found and cut at their border without it).",
)
.flag("trim")
.unit("grid cells");

pub const RECONSTRUCT_CLOSURE: Param =
    Param::new(Call::Reconstruct, "closure", "Surface", Kind::Choice, "Open or closed output.").choices(CLOSURES, 0);

pub const RECONSTRUCT_BASE_MESH: Param = Param::new(
    Call::Reconstruct,
    "base_mesh",
    "Base mesh",
    Kind::Choice,
    "What decides the base mesh's inside and outside, and how it is polygonised.",
)
.flag("base-mesh")
.choices(BASE_MESHES, 2);

pub const SIMPLIFY_TREE_KIND: Param = tree_kind(Call::Simplify);
pub const SIMPLIFY_METRIC: Param = metric(Call::Simplify);
pub const SIMPLIFY_D_A: Param = d_a(Call::Simplify);
pub const SIMPLIFY_D_D: Param = d_d(Call::Simplify);
pub const SIMPLIFY_MAX_DEPTH: Param = max_depth(Call::Simplify);
pub const SIMPLIFY_MIN_CELL_SIZE: Param = min_cell_size(Call::Simplify);
pub const SIMPLIFY_THREADS: Param = threads(Call::Simplify);
pub const RECONSTRUCT_ORIENT: Param = orient(Call::Reconstruct);
// The reconstruction needs T-nodes: at d_a 1 or d_d 0 the height-field test never holds.
pub const RECONSTRUCT_D_A: Param = d_a(Call::Reconstruct).open(false, true);
pub const RECONSTRUCT_D_D: Param = d_d(Call::Reconstruct).open(true, false);
pub const RECONSTRUCT_MAX_DEPTH: Param = max_depth(Call::Reconstruct);
pub const RECONSTRUCT_MIN_CELL_SIZE: Param = min_cell_size(Call::Reconstruct);
pub const RECONSTRUCT_NEIGHBOURS: Param = neighbours(Call::Reconstruct);
pub const RECONSTRUCT_REORIENT_GIVEN: Param = reorient_given(Call::Reconstruct);
pub const RECONSTRUCT_THREADS: Param = threads(Call::Reconstruct);
pub const NORMALS_ORIENT: Param = orient(Call::Normals);
pub const NORMALS_NEIGHBOURS: Param = neighbours(Call::Normals);
pub const NORMALS_REORIENT_GIVEN: Param = reorient_given(Call::Normals);
pub const NORMALS_THREADS: Param = threads(Call::Normals);

/// Every parameter, each call's in its C struct's field order.
pub const PARAMS: &[Param] = &[
    SIMPLIFY_TREE_KIND,
    SIMPLIFY_METRIC,
    SIMPLIFY_SAMPLING,
    SIMPLIFY_ERROR,
    SIMPLIFY_D_A,
    SIMPLIFY_D_D,
    SIMPLIFY_MAX_DEPTH,
    SIMPLIFY_THREADS,
    SIMPLIFY_MIN_CELL_SIZE,
    SIMPLIFY_KEEP_TOPOLOGY,
    SIMPLIFY_TARGET_FACES,
    RECONSTRUCT_ORIENT,
    RECONSTRUCT_ERROR,
    RECONSTRUCT_D_A,
    RECONSTRUCT_D_D,
    RECONSTRUCT_MAX_DEPTH,
    RECONSTRUCT_MAX_LEVELS,
    RECONSTRUCT_MIN_CELL_SIZE,
    RECONSTRUCT_TARGET_DISTANCE,
    RECONSTRUCT_MIN_DISPLACED,
    RECONSTRUCT_MAX_TRIANGLES,
    RECONSTRUCT_MAX_GRID_DEPTH,
    RECONSTRUCT_TRIM,
    RECONSTRUCT_NEIGHBOURS,
    RECONSTRUCT_REORIENT_GIVEN,
    RECONSTRUCT_THREADS,
    RECONSTRUCT_CLOSURE,
    RECONSTRUCT_BASE_MESH,
    NORMALS_ORIENT,
    NORMALS_NEIGHBOURS,
    NORMALS_REORIENT_GIVEN,
    NORMALS_THREADS,
];
