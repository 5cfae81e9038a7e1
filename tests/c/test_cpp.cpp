// The C++ wrapper (vstree.hpp): RAII frees everything on every path, errors become
// vstree::error with the status and message, progress lambdas can cancel, and an exception
// thrown inside a progress callback comes out of the call unchanged.
#include <vstree.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

static int g_checks = 0;
static int g_failures = 0;

#define CHECK(cond)                                                                            \
  do {                                                                                         \
    g_checks++;                                                                                \
    if (!(cond)) {                                                                             \
      g_failures++;                                                                            \
      std::fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #cond);            \
    }                                                                                          \
  } while (0)

// Runs `f`, which must throw vstree::error with `status` and a message containing `needle`.
template <typename F> static void expect_error(vstree_status status, const char *needle, F f) {
  try {
    f();
    g_checks++;
    g_failures++;
    std::fprintf(stderr, "expected vstree::error %d (%s), nothing was thrown\n", (int)status,
                 needle);
  } catch (const vstree::error &e) {
    CHECK(e.status() == status);
    CHECK(std::strstr(e.what(), needle) != nullptr);
    if (e.status() != status) {
      std::fprintf(stderr, "  got %d: %s\n", (int)e.status(), e.what());
    }
  }
}

// A UV sphere: rings x segments quads between the poles.
static void sphere(unsigned rings, unsigned segments, std::vector<float> &p,
                   std::vector<uint32_t> &t) {
  const float pi = 3.14159265358979f;
  p.clear();
  t.clear();
  p.insert(p.end(), {0.0f, 0.0f, 1.0f});
  for (unsigned i = 1; i < rings; i++) {
    float th = pi * float(i) / float(rings);
    for (unsigned j = 0; j < segments; j++) {
      float ph = 2 * pi * float(j) / float(segments);
      p.insert(p.end(), {std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)});
    }
  }
  p.insert(p.end(), {0.0f, 0.0f, -1.0f});
  const uint32_t south = uint32_t(p.size() / 3 - 1);
  auto at = [&](unsigned ring, unsigned j) { return uint32_t(1 + (ring - 1) * segments + j % segments); };
  for (unsigned j = 0; j < segments; j++) {
    t.insert(t.end(), {0u, at(1, j), at(1, j + 1)});
    for (unsigned i = 1; i + 1 < rings; i++) {
      t.insert(t.end(), {at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      t.insert(t.end(), {at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
    t.insert(t.end(), {at(rings - 1, j), south, at(rings - 1, j + 1)});
  }
}

int main(int argc, char **argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s TEMP_DIR\n", argv[0]);
    return 2;
  }
  const std::string dir = argv[1];
  std::vector<float> p;
  std::vector<uint32_t> t;
  sphere(40, 80, p, t);

  CHECK(vstree::version() == vstree_version());
  vstree::mesh m = vstree::mesh::create(p, t);
  CHECK(m.vertex_count() == p.size() / 3 && m.triangle_count() == t.size() / 3);
  CHECK(m.positions() == p && m.triangles() == t && !m.has_normals() && m.normals().empty());

  // Simplify with a progress lambda; the result's mesh is a view, take_mesh() moves it out.
  int reports = 0;
  float last = 0.0f;
  vstree_simplify_params params = vstree::default_params();
  params.error = 1e-3;
  vstree::simplify_result r = vstree::simplify(m, params, [&](float f, const char *stage) {
    reports++;
    CHECK(f >= last && stage != nullptr);
    last = f;
    return true;
  });
  CHECK(reports >= 3 && last == 1.0f);
  const vstree_simplify_stats &s = r.stats();
  CHECK(s.output_vertices == r.mesh().vertex_count() && s.output_vertices > 10);
  CHECK(s.output_triangles < s.input_triangles && s.clusters >= s.output_vertices);
  r.mesh().save(dir + "/cpp.ply");
  vstree::mesh back = vstree::mesh::load(dir + "/cpp.ply");
  CHECK(back.positions() == r.mesh().positions() && back.triangles() == r.mesh().triangles());
  vstree::mesh owned = r.take_mesh();
  CHECK(owned.triangle_count() == back.triangle_count());

  // Move semantics: the moved-from handle is empty (and frees nothing).
  vstree::mesh moved = std::move(owned);
  CHECK(owned.get() == nullptr && moved.get() != nullptr);
  moved = vstree::mesh::create({0, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 1, 2});
  CHECK(moved.vertex_count() == 3);

  // Doubles far from the origin keep their detail: the unit sphere at 1e8 comes back within
  // float rounding of its own size, where float coordinates there are 8 apart.
  {
    std::vector<double> far(p.begin(), p.end());
    for (double &x : far) x += 1e8;
    vstree::mesh f = vstree::mesh::create_f64(far, t);
    std::vector<double> back = f.positions_f64();
    double worst = 0.0;
    CHECK(back.size() == far.size() && f.triangles() == t);
    for (std::size_t i = 0; i < back.size(); i++) worst = std::max(worst, std::fabs(back[i] - far[i]));
    CHECK(worst < 2e-6);
  }

  // Errors carry the status and the library's message.
  expect_error(VSTREE_STATUS_INVALID_PARAMETER, "`d_a`", [&] {
    vstree_simplify_params bad = vstree::default_params();
    bad.d_a = 2.0f;
    vstree::simplify(m, bad);
  });
  expect_error(VSTREE_STATUS_INVALID_INPUT, "vertex 0", [&] {
    vstree::mesh::create({NAN, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 1, 2});
  });
  expect_error(VSTREE_STATUS_INVALID_ARGUMENT, "multiples of 3", [&] {
    vstree::mesh::create({0, 0}, {});
  });
  expect_error(VSTREE_STATUS_IO, "missing.obj", [&] { vstree::mesh::load(dir + "/missing.obj"); });
  expect_error(VSTREE_STATUS_PARSE, "x.off", [&] {
    const char text[] = "OFF\n1 0 0\n";
    vstree::mesh::load_memory(text, sizeof text - 1, "x.off");
  });
  expect_error(VSTREE_STATUS_CANCELLED, "cancelled", [&] {
    vstree::simplify(m, vstree::default_params(), [](float, const char *) { return false; });
  });

  // An exception from the callback stops the call and comes out as itself.
  bool caught = false;
  try {
    vstree::tree::build(m, vstree::default_params(), [](float f, const char *) -> bool {
      if (f > 0.5f) {
        throw std::runtime_error("the host gave up");
      }
      return true;
    });
  } catch (const vstree::error &) {
    caught = false;
  } catch (const std::runtime_error &e) {
    caught = std::string(e.what()) == "the host gave up";
  }
  CHECK(caught);

  // The tree, for viewers.
  vstree::tree tree = vstree::tree::build(m);
  const vstree_tree_stats &ts = tree.stats();
  std::vector<vstree_node> nodes = tree.nodes();
  std::vector<vstree_t_node> layer = tree.t_nodes();
  std::vector<vstree_tree_level> levels = tree.levels();
  std::vector<uint32_t> clusters = tree.vertex_labels();
  std::vector<uint32_t> t_labels = tree.vertex_labels(VSTREE_LABEL_KIND_T_NODE);
  CHECK(nodes.size() == ts.nodes && layer.size() == ts.t_nodes && ts.t_nodes > 0);
  CHECK(levels.size() == ts.max_depth + 1u && clusters.size() == m.vertex_count());
  for (uint32_t c : clusters) {
    CHECK(c < ts.clusters);
  }
  for (uint32_t l : t_labels) {
    CHECK(l < ts.t_nodes || l == VSTREE_NO_INDEX);
  }

  // Normals and reconstruction from a bare point cloud: 2000 evenly spread points of the unit
  // sphere (a Fibonacci lattice).
  {
    p.clear();
    for (int i = 0; i < 2000; i++) {
      float z = 1.0f - (2.0f * float(i) + 1.0f) / 2000.0f, r = std::sqrt(1.0f - z * z);
      float phi = 2.39996323f * float(i);
      p.insert(p.end(), {r * std::cos(phi), r * std::sin(phi), z});
    }
    vstree::mesh cloud = vstree::mesh::create(p);
    vstree_normals_report report;
    std::memset(&report, 0, sizeof report);
    vstree::mesh with_normals =
        vstree::estimate_normals(cloud, vstree::default_normal_params(), vstree::progress_fn(), &report);
    CHECK(with_normals.has_normals() && !cloud.has_normals());
    CHECK(report.estimated == cloud.vertex_count() && report.oriented == 1);
    std::vector<float> n = with_normals.normals();
    std::size_t outward = 0;
    for (std::size_t i = 0; i < n.size(); i += 3) {
      outward += n[i] * p[i] + n[i + 1] * p[i + 1] + n[i + 2] * p[i + 2] > 0.0f;
    }
    CHECK(outward == cloud.vertex_count());

    vstree_reconstruct_params rp = vstree::default_reconstruct_params();
    rp.max_levels = 2;
    rp.max_grid_depth = 6;
    int calls = 0;
    vstree::reconstruct_result rr = vstree::reconstruct(cloud, rp, [&](float, const char *) {
      calls++;
      return true;
    });
    const vstree_reconstruct_stats rs = rr.stats(); // a copy: take_mesh() frees the result
    CHECK(calls >= 3 && rs.base_genus == 0 && rs.normals_estimated == cloud.vertex_count());
    CHECK(rs.output_vertices == rr.mesh().vertex_count() && rr.mesh().triangle_count() > 0);
    CHECK(rs.output_triangles == 2 * rs.output_vertices - 4); // a closed genus-0 mesh
    vstree::mesh surface = rr.take_mesh();
    CHECK(surface.has_normals() && surface.vertex_count() == rs.output_vertices);

    expect_error(VSTREE_STATUS_INVALID_PARAMETER, "`max_levels`", [&] {
      vstree_reconstruct_params bad = vstree::default_reconstruct_params();
      bad.max_levels = 99;
      vstree::reconstruct(cloud, bad);
    });
    expect_error(VSTREE_STATUS_INVALID_PARAMETER, "`neighbours`", [&] {
      vstree_normal_params bad = vstree::default_normal_params();
      bad.neighbours = 1;
      vstree::estimate_normals(cloud, bad);
    });
    expect_error(VSTREE_STATUS_CANCELLED, "cancelled", [&] {
      vstree::reconstruct(cloud, rp, [](float, const char *) { return false; });
    });
    expect_error(VSTREE_STATUS_INVALID_INPUT, "points", [&] {
      vstree::reconstruct(vstree::mesh::create({0, 0, 0, 1, 0, 0, 0, 1, 0}));
    });
  }

  std::fprintf(stderr, "test_cpp: %d checks, %d failures\n", g_checks, g_failures);
  return g_failures == 0 ? 0 : 1;
}
