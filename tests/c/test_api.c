/* The C API from C: a table of bad inputs for every export (NULL, empty, NaN, out of range,
 * absurd sizes, cancel at every progress report) with the exact status and a message that
 * names the culprit, and the functions working on good input. Run under valgrind or ASan.
 *
 * usage: test_api TEMP_DIR   (TEMP_DIR/dir.ply a directory; compiled with -DEXPECTED_VERSION="x.y.z" from Cargo.toml)
 */
#include "common.h"

#include <limits.h>
#include <signal.h>
#include <stdint.h>

#ifndef EXPECTED_VERSION
#error "compile with -DEXPECTED_VERSION=\"x.y.z\" (the version in Cargo.toml)"
#endif

static int g_rows = 0; /* rows of the bad-input table */
static char g_dir[4096];

/* Checks a call's status, and that the last error names `needle` on failure and is empty on
 * success. */
static void expect(const char *call, int line, vstree_status got, vstree_status expected,
                   const char *needle) {
  const char *message = vstree_last_error_message();
  g_checks++;
  g_rows++;
  if (got != expected) {
    g_failures++;
    fprintf(stderr, "test_api.c:%d: %s\n  gave %d (%s), expected %d (%s); message: %s\n", line,
            call, (int)got, vstree_status_str(got), (int)expected, vstree_status_str(expected),
            message);
  } else if (expected == VSTREE_STATUS_OK && message[0] != '\0') {
    g_failures++;
    fprintf(stderr, "test_api.c:%d: %s\n  succeeded but left a message: %s\n", line, call,
            message);
  } else if (expected != VSTREE_STATUS_OK &&
             (message[0] == '\0' || (needle != NULL && strstr(message, needle) == NULL))) {
    g_failures++;
    fprintf(stderr, "test_api.c:%d: %s\n  message \"%s\" does not name \"%s\"\n", line, call,
            message, needle ? needle : "(anything)");
  }
}

#define EXPECT(expected, needle, call) expect(#call, __LINE__, (call), (expected), (needle))

/* Output pointers are set to these before failing calls, to check they are left alone. */
#define SENTINEL_MESH ((vstree_mesh *)(uintptr_t)0x10)
#define SENTINEL_RESULT ((vstree_simplify_result *)(uintptr_t)0x10)
#define SENTINEL_TREE ((vstree_tree *)(uintptr_t)0x10)

static char *path_in_dir(char *buffer, size_t size, const char *name) {
  snprintf(buffer, size, "%s/%s", g_dir, name);
  return buffer;
}

static void write_file(const char *name, const char *content) {
  char path[4200];
  FILE *f = fopen(path_in_dir(path, sizeof path, name), "wb");
  if (!f) {
    fprintf(stderr, "cannot write %s\n", path);
    exit(2);
  }
  fputs(content, f);
  fclose(f);
}

/* ---- progress callbacks ---- */

typedef struct stopper {
  int calls;
  int stop_at; /* -1: never */
  float last_fraction;
  int bad_fraction;
  int reentrant_bad;
} stopper;

static int32_t stop_cb(void *user_data, float fraction, const char *stage) {
  stopper *s = (stopper *)user_data;
  int go_on;
  if (!(fraction >= s->last_fraction && fraction <= 1.0f) || stage == NULL || stage[0] == '\0') {
    s->bad_fraction++;
  }
  s->last_fraction = fraction;
  /* Calling back into the library from the callback is allowed. */
  if (vstree_mesh_vertex_count(NULL) != 0 || vstree_last_error_message() == NULL) {
    s->reentrant_bad++;
  }
  go_on = s->calls != s->stop_at;
  s->calls++;
  return go_on;
}

/* Cancels `call` at each of its progress reports in turn: CANCELLED every time, no output, no
 * report after the stop. Returns the number of reports of a full run. */
typedef vstree_status (*cancellable)(const vstree_mesh *, stopper *, void **out);

static vstree_status simplify_call(const vstree_mesh *m, stopper *s, void **out) {
  vstree_simplify_result *r = SENTINEL_RESULT;
  vstree_status status = vstree_simplify(m, NULL, stop_cb, s, &r);
  *out = r;
  return status;
}

static vstree_status tree_call(const vstree_mesh *m, stopper *s, void **out) {
  vstree_tree *t = SENTINEL_TREE;
  vstree_status status = vstree_tree_build(m, NULL, stop_cb, s, &t);
  *out = t;
  return status;
}

static void cancel_at_every_report(const char *name, cancellable call, const vstree_mesh *m,
                                   void (*free_out)(void *)) {
  stopper full = {0, -1, 0.0f, 0, 0};
  void *out = NULL;
  int k;
  EXPECT(VSTREE_STATUS_OK, NULL, call(m, &full, &out));
  free_out(out);
  CHECK(full.calls >= 3);
  CHECK(full.last_fraction == 1.0f);
  CHECK(full.bad_fraction == 0 && full.reentrant_bad == 0);
  for (k = 0; k < full.calls; k++) {
    stopper s = {0, -1, 0.0f, 0, 0};
    s.stop_at = k;
    EXPECT(VSTREE_STATUS_CANCELLED, "cancelled", call(m, &s, &out));
    CHECK(out == (void *)SENTINEL_RESULT); /* same address as SENTINEL_TREE */
    CHECK(s.calls == k + 1);
  }
  fprintf(stderr, "  %s: cancelled at each of its %d progress reports\n", name, full.calls);
}

static void free_result(void *r) { vstree_simplify_result_free((vstree_simplify_result *)r); }
static void free_tree(void *t) { vstree_tree_free((vstree_tree *)t); }

/* ---- the table ---- */

static void version_and_errors(void) {
  char buffer[8];
  size_t n;
  CHECK(strcmp(vstree_version(), EXPECTED_VERSION) == 0);
  CHECK(strcmp(VSTREE_VERSION_STRING, EXPECTED_VERSION) == 0);
  CHECK(vstree_abi_version() == VSTREE_ABI_VERSION);
  CHECK(strcmp(vstree_status_str(VSTREE_STATUS_OK), "success") == 0);
  CHECK(strcmp(vstree_status_str(-1), "unknown status") == 0);
  CHECK(strcmp(vstree_status_str(13), "unknown status") == 0);
  CHECK(strcmp(vstree_status_str(INT_MIN), "unknown status") == 0);
  CHECK(strcmp(vstree_status_str(INT_MAX), "unknown status") == 0);
  {
    int code;
    for (code = VSTREE_STATUS_OK; code <= VSTREE_STATUS_INTERNAL; code++) {
      CHECK(strcmp(vstree_status_str(code), "unknown status") != 0);
    }
  }
  CHECK(strcmp(vstree_refinement_stopped_str(VSTREE_REFINEMENT_STOPPED_TARGET), "target") == 0);
  CHECK(strcmp(vstree_refinement_stopped_str(VSTREE_REFINEMENT_STOPPED_NO_DETAIL), "no_detail") == 0);
  CHECK(strcmp(vstree_refinement_stopped_str(VSTREE_REFINEMENT_STOPPED_MAX_LEVELS), "max_levels") == 0);
  CHECK(strcmp(vstree_refinement_stopped_str(VSTREE_REFINEMENT_STOPPED_TRIANGLE_BUDGET), "triangle_budget") == 0);
  CHECK(strcmp(vstree_refinement_stopped_str(4), "unknown") == 0);
  CHECK(strcmp(vstree_refinement_stopped_str(UINT32_MAX), "unknown") == 0);
  /* The numbers are ABI: they must never change. */
  CHECK(VSTREE_STATUS_NULL_POINTER == 1 && VSTREE_STATUS_INVALID_PARAMETER == 3);
  CHECK(VSTREE_STATUS_CANCELLED == 10 && VSTREE_STATUS_INTERNAL == 12);

  EXPECT(VSTREE_STATUS_NULL_POINTER, "out_mesh", vstree_mesh_load("x.ply", NULL));
  n = vstree_last_error_copy(NULL, 0);
  CHECK(n == strlen(vstree_last_error_message()));
  memset(buffer, 'x', sizeof buffer);
  CHECK(vstree_last_error_copy(buffer, sizeof buffer) == n);
  CHECK(strlen(buffer) == sizeof buffer - 1 && strncmp(buffer, "vstree_", 7) == 0);
  CHECK(vstree_last_error_copy(buffer, 1) == n && buffer[0] == '\0');
  /* Only status-returning calls change the message. */
  CHECK(vstree_mesh_vertex_count(NULL) == 0 && vstree_last_error_copy(NULL, 0) == n);
}

/* vstree_mesh_create_f64 keeps a model far from the origin (georeferenced, at 1e6 or 1e8)
 * to within float rounding of its own size: the positions come back within 1e-6 of its
 * extent, where float coordinates at 1e8 would be 8 apart. */
static void far_mesh_creation(const torus *t) {
  const double offsets[2] = {1e6, 1e8};
  size_t n = 3 * t->vertex_count, i, k;
  double *moved = malloc(n * sizeof *moved), *back = malloc(n * sizeof *back);
  CHECK(moved != NULL && back != NULL);
  for (k = 0; k < 2; k++) {
    vstree_mesh *m = NULL;
    double worst = 0.0;
    for (i = 0; i < n; i++) moved[i] = (double)t->positions[i] + offsets[k];
    EXPECT(VSTREE_STATUS_OK, NULL,
           vstree_mesh_create_f64(moved, t->vertex_count, t->normals, t->triangles,
                                  t->triangle_count, &m));
    CHECK(m != NULL && vstree_mesh_triangle_count(m) == t->triangle_count &&
          vstree_mesh_has_normals(m) == 1);
    EXPECT(VSTREE_STATUS_OK, NULL, vstree_mesh_copy_positions_f64(m, back, n));
    for (i = 0; i < n; i++) {
      double d = fabs(back[i] - moved[i]);
      if (d > worst) worst = d;
    }
    /* The torus is about 2.7 across. */
    CHECK(worst < 2.7e-6);
    vstree_mesh_free(m);
  }
  free(moved);
  free(back);
}

static void mesh_creation(const torus *t) {
  float bad[12];
  uint32_t tri[3] = {0, 1, 2};
  float aligned[7];
  const float *misaligned = (const float *)(const void *)((const char *)aligned + 1);
  vstree_mesh *m = SENTINEL_MESH;

  memcpy(bad, t->positions, sizeof bad);
  EXPECT(VSTREE_STATUS_NULL_POINTER, "out_mesh",
         vstree_mesh_create(t->positions, t->vertex_count, NULL, t->triangles, t->triangle_count,
                            NULL));
  EXPECT(VSTREE_STATUS_NULL_POINTER, "`positions`",
         vstree_mesh_create(NULL, 3, NULL, tri, 1, &m));
  EXPECT(VSTREE_STATUS_NULL_POINTER, "`triangles`",
         vstree_mesh_create(bad, 4, NULL, NULL, 1, &m));
  EXPECT(VSTREE_STATUS_INVALID_INPUT, "vertex_count", vstree_mesh_create(bad, 0, NULL, tri, 0, &m));
  EXPECT(VSTREE_STATUS_INVALID_INPUT, "vertex_count",
         vstree_mesh_create(NULL, 0, NULL, NULL, 0, &m));
#if SIZE_MAX > UINT32_MAX
  EXPECT(VSTREE_STATUS_TOO_LARGE, "vertex_count",
         vstree_mesh_create(bad, (size_t)UINT32_MAX + 1, NULL, tri, 1, &m));
  EXPECT(VSTREE_STATUS_TOO_LARGE, "triangle_count",
         vstree_mesh_create(bad, 4, NULL, tri, (size_t)UINT32_MAX + 1, &m));
#endif
  EXPECT(VSTREE_STATUS_TOO_LARGE, "vertex_count",
         vstree_mesh_create(bad, SIZE_MAX, NULL, tri, 1, &m));
  EXPECT(VSTREE_STATUS_TOO_LARGE, "vertex_count",
         vstree_mesh_create(bad, SIZE_MAX / 3 + 1, NULL, tri, 1, &m));
  EXPECT(VSTREE_STATUS_TOO_LARGE, "triangle_count",
         vstree_mesh_create(bad, 4, NULL, tri, SIZE_MAX, &m));
  EXPECT(VSTREE_STATUS_INVALID_ARGUMENT, "positions",
         vstree_mesh_create(misaligned, 1, NULL, NULL, 0, &m));
  bad[4] = NAN;
  EXPECT(VSTREE_STATUS_INVALID_INPUT, "vertex 1", vstree_mesh_create(bad, 4, NULL, tri, 1, &m));
  bad[4] = INFINITY;
  EXPECT(VSTREE_STATUS_INVALID_INPUT, "vertex 1", vstree_mesh_create(bad, 4, NULL, tri, 1, &m));
  bad[4] = -INFINITY;
  EXPECT(VSTREE_STATUS_INVALID_INPUT, "vertex 1", vstree_mesh_create(bad, 4, NULL, tri, 1, &m));
  memcpy(bad, t->positions, sizeof bad);
  {
    float normals[12];
    memcpy(normals, t->normals, sizeof normals);
    normals[11] = NAN;
    EXPECT(VSTREE_STATUS_INVALID_INPUT, "normal 3",
           vstree_mesh_create(bad, 4, normals, tri, 1, &m));
  }
  tri[2] = 4;
  EXPECT(VSTREE_STATUS_INVALID_INPUT, "triangle 0 uses vertex 4",
         vstree_mesh_create(bad, 4, NULL, tri, 1, &m));
  tri[2] = UINT32_MAX;
  EXPECT(VSTREE_STATUS_INVALID_INPUT, "vertex 4294967295",
         vstree_mesh_create(bad, 4, NULL, tri, 1, &m));
  CHECK(m == SENTINEL_MESH);

  /* Good input: a point cloud (no triangles; NULL allowed), with and without normals. */
  m = NULL;
  EXPECT(VSTREE_STATUS_OK, NULL, vstree_mesh_create(bad, 4, NULL, NULL, 0, &m));
  CHECK(m != NULL && vstree_mesh_vertex_count(m) == 4 && vstree_mesh_triangle_count(m) == 0);
  CHECK(vstree_mesh_has_normals(m) == 0);
  vstree_mesh_free(m);
  vstree_mesh_free(NULL);
}

static void mesh_files(const vstree_mesh *mesh) {
  char path[4200];
  vstree_mesh *m = SENTINEL_MESH;
  static const char truncated[] = "ply\nformat ascii 1.0\nelement vertex 3\n"
                                  "property float x\nproperty float y\nproperty float z\n"
                                  "end_header\n0 0 0\n1 0 0\n";
  static const char off_out_of_range[] = "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n";
  static const char off_nan[] = "OFF\n3 1 0\n0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n";

  EXPECT(VSTREE_STATUS_NULL_POINTER, "`path`", vstree_mesh_load(NULL, &m));
  EXPECT(VSTREE_STATUS_INVALID_ARGUMENT, "empty", vstree_mesh_load("", &m));
  EXPECT(VSTREE_STATUS_IO, "missing.ply",
         vstree_mesh_load(path_in_dir(path, sizeof path, "missing.ply"), &m));
  /* run.sh makes TEMP_DIR/dir.ply a directory */
  EXPECT(VSTREE_STATUS_IO, "dir.ply",
         vstree_mesh_load(path_in_dir(path, sizeof path, "dir.ply"), &m));
  write_file("mesh.stl", "solid x\n");
  EXPECT(VSTREE_STATUS_UNSUPPORTED_FORMAT, "mesh.stl",
         vstree_mesh_load(path_in_dir(path, sizeof path, "mesh.stl"), &m));
  write_file("truncated.ply", truncated);
  EXPECT(VSTREE_STATUS_PARSE, "truncated.ply",
         vstree_mesh_load(path_in_dir(path, sizeof path, "truncated.ply"), &m));
  write_file("range.off", off_out_of_range);
  EXPECT(VSTREE_STATUS_PARSE, "range.off",
         vstree_mesh_load(path_in_dir(path, sizeof path, "range.off"), &m));
  write_file("nan.off", off_nan);
  EXPECT(VSTREE_STATUS_PARSE, "nan.off",
         vstree_mesh_load(path_in_dir(path, sizeof path, "nan.off"), &m));
  CHECK(m == SENTINEL_MESH);

  EXPECT(VSTREE_STATUS_NULL_POINTER, "out_mesh",
         vstree_mesh_load_memory(truncated, sizeof truncated - 1, "ply", NULL));
  EXPECT(VSTREE_STATUS_NULL_POINTER, "`data`", vstree_mesh_load_memory(NULL, 10, "ply", &m));
  EXPECT(VSTREE_STATUS_NULL_POINTER, "`name`",
         vstree_mesh_load_memory(truncated, sizeof truncated - 1, NULL, &m));
  EXPECT(VSTREE_STATUS_INVALID_ARGUMENT, "`name`",
         vstree_mesh_load_memory(truncated, sizeof truncated - 1, "", &m));
  EXPECT(VSTREE_STATUS_UNSUPPORTED_FORMAT, "stl",
         vstree_mesh_load_memory(truncated, sizeof truncated - 1, "stl", &m));
  EXPECT(VSTREE_STATUS_TOO_LARGE, "size", vstree_mesh_load_memory(truncated, SIZE_MAX, "ply", &m));
  EXPECT(VSTREE_STATUS_PARSE, "memory.ply", vstree_mesh_load_memory(NULL, 0, "ply", &m));
  EXPECT(VSTREE_STATUS_PARSE, "scan.ply",
         vstree_mesh_load_memory(truncated, sizeof truncated - 1, "scan.ply", &m));
  EXPECT(VSTREE_STATUS_PARSE, "off",
         vstree_mesh_load_memory(off_out_of_range, sizeof off_out_of_range - 1, "off", &m));
  CHECK(m == SENTINEL_MESH);

  EXPECT(VSTREE_STATUS_NULL_POINTER, "`mesh`",
         vstree_mesh_save(NULL, path_in_dir(path, sizeof path, "a.ply"), 0));
  EXPECT(VSTREE_STATUS_NULL_POINTER, "`path`", vstree_mesh_save(mesh, NULL, 0));
  EXPECT(VSTREE_STATUS_INVALID_ARGUMENT, "empty", vstree_mesh_save(mesh, "", 0));
  EXPECT(VSTREE_STATUS_INVALID_ARGUMENT, "flags",
         vstree_mesh_save(mesh, path_in_dir(path, sizeof path, "a.ply"), 2));
  EXPECT(VSTREE_STATUS_INVALID_ARGUMENT, "flags",
         vstree_mesh_save(mesh, path_in_dir(path, sizeof path, "a.ply"), 0xFFFFFFFFu));
  EXPECT(VSTREE_STATUS_UNSUPPORTED_FORMAT, "a.stl",
         vstree_mesh_save(mesh, path_in_dir(path, sizeof path, "a.stl"), 0));
  EXPECT(VSTREE_STATUS_IO, "no/such/dir",
         vstree_mesh_save(mesh, path_in_dir(path, sizeof path, "no/such/dir/a.ply"), 0));

  /* Good input: every format round-trips its counts; memory parsing equals file parsing. */
  {
    static const char *names[] = {"out.ply", "out.obj", "out.off", "out.xyz"};
    size_t i;
    for (i = 0; i < sizeof names / sizeof names[0]; i++) {
      vstree_mesh *back = NULL;
      unsigned flags = i == 0 ? VSTREE_SAVE_ASCII : 0u;
      int cloud = strstr(names[i], ".xyz") != NULL;
      EXPECT(VSTREE_STATUS_OK, NULL,
             vstree_mesh_save(mesh, path_in_dir(path, sizeof path, names[i]), flags));
      EXPECT(VSTREE_STATUS_OK, NULL, vstree_mesh_load(path, &back));
      CHECK(vstree_mesh_vertex_count(back) == vstree_mesh_vertex_count(mesh));
      CHECK(vstree_mesh_triangle_count(back) ==
            (cloud ? 0 : vstree_mesh_triangle_count(mesh)));
      vstree_mesh_free(back);
    }
  }
}

static void mesh_copies(const vstree_mesh *mesh, const vstree_mesh *cloud_no_normals) {
  size_t n = vstree_mesh_vertex_count(mesh);
  size_t t = vstree_mesh_triangle_count(mesh);
  float *p = (float *)calloc(3 * n + 1, sizeof(float));
  uint32_t *i = (uint32_t *)calloc(3 * t, sizeof(uint32_t));
  float *misaligned = (float *)(void *)((char *)p + 1);

  CHECK(vstree_mesh_vertex_count(NULL) == 0 && vstree_mesh_triangle_count(NULL) == 0);
  CHECK(vstree_mesh_has_normals(NULL) == 0 && vstree_mesh_has_normals(mesh) == 1);
  EXPECT(VSTREE_STATUS_NULL_POINTER, "`mesh`", vstree_mesh_copy_positions(NULL, p, 3 * n));
  EXPECT(VSTREE_STATUS_NULL_POINTER, "`out`", vstree_mesh_copy_positions(mesh, NULL, 3 * n));
  EXPECT(VSTREE_STATUS_BUFFER_TOO_SMALL, "capacity", vstree_mesh_copy_positions(mesh, p, 3 * n - 1));
  EXPECT(VSTREE_STATUS_BUFFER_TOO_SMALL, "capacity", vstree_mesh_copy_positions(mesh, NULL, 0));
  CHECK(p[0] == 0.0f); /* nothing written on failure */
  EXPECT(VSTREE_STATUS_INVALID_ARGUMENT, "`out`", vstree_mesh_copy_positions(mesh, misaligned, 3 * n));
  EXPECT(VSTREE_STATUS_OK, NULL, vstree_mesh_copy_positions(mesh, p, 3 * n + 1));
  CHECK(p[0] != 0.0f && p[3 * n] == 0.0f); /* only the needed prefix is written */
  EXPECT(VSTREE_STATUS_NULL_POINTER, "`mesh`", vstree_mesh_copy_normals(NULL, p, 3 * n));
  EXPECT(VSTREE_STATUS_INVALID_ARGUMENT, "no normals",
         vstree_mesh_copy_normals(cloud_no_normals, p, 3 * n));
  EXPECT(VSTREE_STATUS_BUFFER_TOO_SMALL, "capacity", vstree_mesh_copy_normals(mesh, p, 1));
  EXPECT(VSTREE_STATUS_OK, NULL, vstree_mesh_copy_normals(mesh, p, 3 * n));
  EXPECT(VSTREE_STATUS_NULL_POINTER, "`mesh`", vstree_mesh_copy_triangles(NULL, i, 3 * t));
  EXPECT(VSTREE_STATUS_NULL_POINTER, "`out`", vstree_mesh_copy_triangles(mesh, NULL, 3 * t));
  EXPECT(VSTREE_STATUS_BUFFER_TOO_SMALL, "capacity", vstree_mesh_copy_triangles(mesh, i, 2));
  EXPECT(VSTREE_STATUS_OK, NULL, vstree_mesh_copy_triangles(mesh, i, 3 * t));
  EXPECT(VSTREE_STATUS_OK, NULL, vstree_mesh_copy_triangles(cloud_no_normals, NULL, 0));
  {
    size_t k, in_range = 1;
    for (k = 0; k < 3 * t; k++) {
      in_range &= i[k] < n;
    }
    CHECK(in_range);
  }
  free(p);
  free(i);
}

/* The defaults are in range and say their size. */
static void default_parameters(void) {
  vstree_simplify_params p = vstree_simplify_params_default();
  CHECK(p.struct_size == sizeof(vstree_simplify_params));
  CHECK(p.tree_kind == VSTREE_TREE_KIND_VS_TREE && p.metric == VSTREE_METRIC_L2);
  CHECK(p.sampling == VSTREE_SAMPLING_VERTICES && p.threads == 0);
  CHECK(p.error > 0 && p.d_a >= 0 && p.d_d > 0 && p.max_depth >= 1 && p.min_cell_size >= 0);
  CHECK(p.keep_topology == VSTREE_KEEP_TOPOLOGY_AUTO && p.target_faces == 0);
}

/* Every parameter field, each out of range in each way, is refused by name. */
#define SPOILER(name, field, value)                                                            \
  static void name(vstree_simplify_params *q) { q->field = value; }
SPOILER(kind_neg, tree_kind, -1)
SPOILER(kind_big, tree_kind, 2)
SPOILER(metric_big, metric, 3)
SPOILER(sampling_big, sampling, 2)
SPOILER(error_zero, error, 0.0)
SPOILER(error_neg, error, -1e-3)
SPOILER(error_nan, error, NAN)
SPOILER(error_inf, error, INFINITY)
SPOILER(d_a_neg, d_a, -0.1f)
SPOILER(d_a_big, d_a, 1.5f)
SPOILER(d_a_nan, d_a, NAN)
SPOILER(d_d_neg, d_d, -0.1f)
SPOILER(d_d_nan, d_d, NAN)
SPOILER(depth_zero, max_depth, 0)
SPOILER(depth_big, max_depth, 31)
SPOILER(depth_huge, max_depth, UINT32_MAX)
SPOILER(threads_big, threads, 1025)
SPOILER(threads_huge, threads, UINT32_MAX)
SPOILER(cell_neg, min_cell_size, -1e-9)
SPOILER(cell_one, min_cell_size, 1.0)
SPOILER(cell_nan, min_cell_size, NAN)
SPOILER(keep_big, keep_topology, 3)
SPOILER(keep_neg, keep_topology, -1)
static void density_half(vstree_simplify_params *q) {
  q->metric = VSTREE_METRIC_DENSITY;
  q->error = 0.5;
}
SPOILER(size_zero, struct_size, 0)
SPOILER(size_short, struct_size, 4)
SPOILER(size_long, struct_size, 4096)

/* The library's parameter table: every row found by its name, its default the _default()
 * functions' value, its default within its range, choices numbered 0..n-1; the host rules. */
static void library_parameter_table(void) {
  uint32_t i, k, count = vstree_param_count(), faces = 0;
  vstree_simplify_params s = vstree_simplify_params_default();
  vstree_reconstruct_params r = vstree_reconstruct_params_default();
  vstree_normal_params n = vstree_normal_params_default();
  CHECK(count >= 30);
  for (i = 0; i < count; i++) {
    const vstree_param_info *p = vstree_param_get(i);
    CHECK(p != NULL && p->struct_size >= sizeof *p);
    CHECK(p->name && p->flag && p->label && p->unit && p->help && p->label[0] && p->help[0]);
    CHECK(vstree_param_find(p->call, p->name) == (int32_t)i);
    CHECK(p->default_value >= p->min && p->default_value <= p->max);
    CHECK((p->kind == VSTREE_PARAM_CHOICE) == (p->choice_count > 0));
    for (k = 0; k < p->choice_count; k++) {
      const vstree_param_choice *c = vstree_param_choice_get(i, k);
      CHECK(c != NULL && c->value == (int32_t)k && c->name[0] && c->label[0]);
    }
    CHECK(vstree_param_choice_get(i, p->choice_count) == NULL);
  }
  CHECK(vstree_param_get(count) == NULL);
  CHECK(vstree_param_find(VSTREE_CALL_NORMALS, "error") == -1);
  CHECK(vstree_param_find(VSTREE_CALL_SIMPLIFY, NULL) == -1);
#define DEFAULT(call, name) (vstree_param_get((uint32_t)vstree_param_find(call, name))->default_value)
  CHECK(DEFAULT(VSTREE_CALL_SIMPLIFY, "error") == s.error);
  CHECK(DEFAULT(VSTREE_CALL_SIMPLIFY, "max_depth") == s.max_depth);
  CHECK(DEFAULT(VSTREE_CALL_SIMPLIFY, "keep_topology") == s.keep_topology);
  CHECK(DEFAULT(VSTREE_CALL_RECONSTRUCT, "error") == r.error);
  CHECK(DEFAULT(VSTREE_CALL_RECONSTRUCT, "max_levels") == r.max_levels);
  CHECK(DEFAULT(VSTREE_CALL_RECONSTRUCT, "base_mesh") == r.base_mesh);
  CHECK(DEFAULT(VSTREE_CALL_NORMALS, "neighbours") == n.neighbours);
  CHECK(DEFAULT(VSTREE_CALL_NORMALS, "orient") == n.orient);
#undef DEFAULT
  CHECK(vstree_faces_for_ratio(0.25, 1000, &faces) == VSTREE_STATUS_OK && faces == 250);
  CHECK(vstree_faces_for_ratio(1.5, 1000, &faces) == VSTREE_STATUS_INVALID_PARAMETER);
  CHECK(strstr(vstree_last_error_message(), "`ratio`") != NULL);
  CHECK(vstree_faces_for_ratio(0.5, 1000, NULL) == VSTREE_STATUS_NULL_POINTER);
  CHECK(fabs(vstree_l2_error_for_distance(0.5, 10.0) - 0.0025) < 1e-15);
  CHECK(vstree_simplify_size_missed(NULL) == NULL);
}

static void parameter_table(const vstree_mesh *mesh) {
  struct bad {
    const char *needle;
    vstree_status expected;
    void (*spoil)(vstree_simplify_params *);
  } table[] = {
      {"`tree_kind`", VSTREE_STATUS_INVALID_PARAMETER, kind_neg},
      {"`tree_kind`", VSTREE_STATUS_INVALID_PARAMETER, kind_big},
      {"`metric`", VSTREE_STATUS_INVALID_PARAMETER, metric_big},
      {"`sampling`", VSTREE_STATUS_INVALID_PARAMETER, sampling_big},
      {"`error`", VSTREE_STATUS_INVALID_PARAMETER, error_zero},
      {"`error`", VSTREE_STATUS_INVALID_PARAMETER, error_neg},
      {"`error`", VSTREE_STATUS_INVALID_PARAMETER, error_nan},
      {"`error`", VSTREE_STATUS_INVALID_PARAMETER, error_inf},
      {"`error`", VSTREE_STATUS_INVALID_PARAMETER, density_half},
      {"`d_a`", VSTREE_STATUS_INVALID_PARAMETER, d_a_neg},
      {"`d_a`", VSTREE_STATUS_INVALID_PARAMETER, d_a_big},
      {"`d_a`", VSTREE_STATUS_INVALID_PARAMETER, d_a_nan},
      {"`d_d`", VSTREE_STATUS_INVALID_PARAMETER, d_d_neg},
      {"`d_d`", VSTREE_STATUS_INVALID_PARAMETER, d_d_nan},
      {"`max_depth`", VSTREE_STATUS_INVALID_PARAMETER, depth_zero},
      {"`max_depth`", VSTREE_STATUS_INVALID_PARAMETER, depth_big},
      {"`max_depth`", VSTREE_STATUS_INVALID_PARAMETER, depth_huge},
      {"`threads`", VSTREE_STATUS_INVALID_PARAMETER, threads_big},
      {"`threads`", VSTREE_STATUS_INVALID_PARAMETER, threads_huge},
      {"`min_cell_size`", VSTREE_STATUS_INVALID_PARAMETER, cell_neg},
      {"`min_cell_size`", VSTREE_STATUS_INVALID_PARAMETER, cell_one},
      {"`min_cell_size`", VSTREE_STATUS_INVALID_PARAMETER, cell_nan},
      {"`keep_topology`", VSTREE_STATUS_INVALID_PARAMETER, keep_big},
      {"`keep_topology`", VSTREE_STATUS_INVALID_PARAMETER, keep_neg},
      {"params->struct_size", VSTREE_STATUS_INVALID_ARGUMENT, size_zero},
      {"params->struct_size", VSTREE_STATUS_INVALID_ARGUMENT, size_short},
      {"newer vstree.h", VSTREE_STATUS_INVALID_ARGUMENT, size_long},
  };
  size_t k;
  default_parameters();
  for (k = 0; k < sizeof table / sizeof table[0]; k++) {
    vstree_simplify_params p = vstree_simplify_params_default();
    vstree_simplify_result *r = SENTINEL_RESULT;
    vstree_tree *t = SENTINEL_TREE;
    table[k].spoil(&p);
    EXPECT(table[k].expected, table[k].needle, vstree_simplify(mesh, &p, NULL, NULL, &r));
    EXPECT(table[k].expected, table[k].needle, vstree_tree_build(mesh, &p, NULL, NULL, &t));
    CHECK(r == SENTINEL_RESULT && t == SENTINEL_TREE);
  }
}

static void simplification(const vstree_mesh *mesh, const vstree_mesh *cloud,
                           const vstree_mesh *cloud_no_normals) {
  vstree_simplify_result *r = SENTINEL_RESULT;
  vstree_simplify_params p = vstree_simplify_params_default();
  const vstree_simplify_stats *s;
  const vstree_mesh *out;
  vstree_mesh *taken = SENTINEL_MESH;
  float degenerate[9] = {0, 0, 0, 1, 0, 0, 2, 0, 0};
  uint32_t tri[3] = {0, 1, 2};
  vstree_mesh *flat = NULL;

  EXPECT(VSTREE_STATUS_NULL_POINTER, "`out_result`", vstree_simplify(mesh, NULL, NULL, NULL, NULL));
  EXPECT(VSTREE_STATUS_NULL_POINTER, "`mesh`", vstree_simplify(NULL, NULL, NULL, NULL, &r));
  EXPECT(VSTREE_STATUS_INVALID_INPUT, "normals",
         vstree_simplify(cloud_no_normals, NULL, NULL, NULL, &r));
  EXPECT(VSTREE_STATUS_OK, NULL, vstree_mesh_create(degenerate, 3, NULL, tri, 1, &flat));
  EXPECT(VSTREE_STATUS_INVALID_INPUT, "degenerate", vstree_simplify(flat, NULL, NULL, NULL, &r));
  EXPECT(VSTREE_STATUS_INVALID_INPUT, "degenerate", vstree_simplify(flat, &p, NULL, NULL, &r));
  CHECK(r == SENTINEL_RESULT);

  CHECK(vstree_simplify_result_get_mesh(NULL) == NULL);
  CHECK(vstree_simplify_result_get_stats(NULL) == NULL);
  vstree_simplify_result_free(NULL);
  EXPECT(VSTREE_STATUS_NULL_POINTER, "`result`", vstree_simplify_result_take_mesh(NULL, &taken));
  CHECK(taken == SENTINEL_MESH);

  /* Good input. */
  p.error = 2e-3;
  EXPECT(VSTREE_STATUS_OK, NULL, vstree_simplify(mesh, &p, NULL, NULL, &r));
  s = vstree_simplify_result_get_stats(r);
  out = vstree_simplify_result_get_mesh(r);
  CHECK(s != NULL && out != NULL);
  CHECK(s->struct_size == sizeof(vstree_simplify_stats));
  CHECK(s->input_vertices == vstree_mesh_vertex_count(mesh));
  CHECK(s->input_triangles == vstree_mesh_triangle_count(mesh));
  CHECK(s->output_vertices == vstree_mesh_vertex_count(out));
  CHECK(s->output_triangles == vstree_mesh_triangle_count(out));
  CHECK(s->output_vertices > 10 && s->output_vertices < s->input_vertices);
  CHECK(s->output_vertices <= s->clusters && s->samples == s->input_vertices);
  CHECK(s->nodes == s->v_nodes + s->t_nodes + s->s_nodes && s->t_nodes > 0);
  CHECK(s->t_depth_min <= s->t_depth_max && s->t_depth_max <= s->max_depth);
  CHECK(s->seconds_total >= s->seconds_tree && s->seconds_tree >= 0);
  EXPECT(VSTREE_STATUS_NULL_POINTER, "`out_mesh`", vstree_simplify_result_take_mesh(r, NULL));
  /* The result's mesh is an ordinary const mesh: simplify it again. */
  {
    vstree_simplify_result *again = NULL;
    EXPECT(VSTREE_STATUS_OK, NULL, vstree_simplify(out, NULL, NULL, NULL, &again));
    vstree_simplify_result_free(again);
  }
  EXPECT(VSTREE_STATUS_OK, NULL, vstree_simplify_result_take_mesh(r, &taken));
  CHECK(taken != SENTINEL_MESH && vstree_mesh_triangle_count(taken) > 0);
  vstree_mesh_free(taken);

  /* A point cloud gives one point with a normal per cluster. */
  EXPECT(VSTREE_STATUS_OK, NULL, vstree_simplify(cloud, NULL, NULL, NULL, &r));
  s = vstree_simplify_result_get_stats(r);
  out = vstree_simplify_result_get_mesh(r);
  CHECK(s->output_vertices == s->clusters && vstree_mesh_triangle_count(out) == 0);
  CHECK(vstree_mesh_has_normals(out) == 1);
  vstree_simplify_result_free(r);
  vstree_mesh_free(flat);

  cancel_at_every_report("vstree_simplify", simplify_call, mesh, free_result);
}

static void trees(const vstree_mesh *mesh) {
  vstree_tree *t = SENTINEL_TREE;
  const vstree_tree_stats *s;
  vstree_node *nodes;
  vstree_t_node *t_nodes;
  vstree_tree_level *levels;
  uint32_t *labels;
  size_t n, tn, ln, vn, k;
  vstree_simplify_params octree = vstree_simplify_params_default();

  EXPECT(VSTREE_STATUS_NULL_POINTER, "`out_tree`", vstree_tree_build(mesh, NULL, NULL, NULL, NULL));
  EXPECT(VSTREE_STATUS_NULL_POINTER, "`mesh`", vstree_tree_build(NULL, NULL, NULL, NULL, &t));
  CHECK(t == SENTINEL_TREE);
  CHECK(vstree_tree_get_stats(NULL) == NULL && vstree_tree_node_count(NULL) == 0);
  CHECK(vstree_tree_t_node_count(NULL) == 0 && vstree_tree_level_count(NULL) == 0);
  CHECK(vstree_tree_vertex_count(NULL) == 0);
  vstree_tree_free(NULL);
  EXPECT(VSTREE_STATUS_NULL_POINTER, "`tree`", vstree_tree_copy_nodes(NULL, NULL, 0));
  EXPECT(VSTREE_STATUS_NULL_POINTER, "`tree`", vstree_tree_copy_t_nodes(NULL, NULL, 0));
  EXPECT(VSTREE_STATUS_NULL_POINTER, "`tree`", vstree_tree_copy_levels(NULL, NULL, 0));
  EXPECT(VSTREE_STATUS_NULL_POINTER, "`tree`", vstree_tree_copy_vertex_labels(NULL, 0, NULL, 0));

  EXPECT(VSTREE_STATUS_OK, NULL, vstree_tree_build(mesh, NULL, NULL, NULL, &t));
  s = vstree_tree_get_stats(t);
  n = vstree_tree_node_count(t);
  tn = vstree_tree_t_node_count(t);
  ln = vstree_tree_level_count(t);
  vn = vstree_tree_vertex_count(t);
  CHECK(s->struct_size == sizeof(vstree_tree_stats));
  CHECK(n == s->nodes && tn == s->t_nodes && ln == s->max_depth + 1u && vn == s->vertices);
  CHECK(vn == vstree_mesh_vertex_count(mesh) && tn > 0);
  CHECK(s->max_cluster_error <= vstree_simplify_params_default().error * 1.0001);
  CHECK(s->mean_cluster_error <= s->max_cluster_error && s->diagonal > 0);
  nodes = (vstree_node *)calloc(n, sizeof *nodes);
  t_nodes = (vstree_t_node *)calloc(tn, sizeof *t_nodes);
  levels = (vstree_tree_level *)calloc(ln, sizeof *levels);
  labels = (uint32_t *)calloc(vn, sizeof *labels);

  EXPECT(VSTREE_STATUS_NULL_POINTER, "`out`", vstree_tree_copy_nodes(t, NULL, n));
  EXPECT(VSTREE_STATUS_BUFFER_TOO_SMALL, "capacity", vstree_tree_copy_nodes(t, nodes, n - 1));
  EXPECT(VSTREE_STATUS_BUFFER_TOO_SMALL, "capacity", vstree_tree_copy_t_nodes(t, t_nodes, 0));
  EXPECT(VSTREE_STATUS_BUFFER_TOO_SMALL, "capacity", vstree_tree_copy_levels(t, levels, ln - 1));
  EXPECT(VSTREE_STATUS_BUFFER_TOO_SMALL, "capacity",
         vstree_tree_copy_vertex_labels(t, VSTREE_LABEL_KIND_CLUSTER, labels, vn - 1));
  EXPECT(VSTREE_STATUS_INVALID_ARGUMENT, "`kind`", vstree_tree_copy_vertex_labels(t, 2, labels, vn));
  EXPECT(VSTREE_STATUS_INVALID_ARGUMENT, "`kind`", vstree_tree_copy_vertex_labels(t, -1, labels, vn));

  EXPECT(VSTREE_STATUS_OK, NULL, vstree_tree_copy_nodes(t, nodes, n));
  EXPECT(VSTREE_STATUS_OK, NULL, vstree_tree_copy_t_nodes(t, t_nodes, tn));
  EXPECT(VSTREE_STATUS_OK, NULL, vstree_tree_copy_levels(t, levels, ln));
  {
    uint64_t v = 0, tt = 0, ss = 0, leaves = 0;
    for (k = 0; k < ln; k++) {
      v += levels[k].v_nodes;
      tt += levels[k].t_nodes;
      ss += levels[k].s_nodes;
      leaves += levels[k].leaves;
    }
    CHECK(v == s->v_nodes && tt == s->t_nodes && ss == s->s_nodes && leaves == s->clusters);
  }
  CHECK(nodes[0].parent == 0 && nodes[0].depth == 0 && nodes[0].kind == VSTREE_NODE_KIND_VOLUME);
  for (k = 0; k < tn; k++) {
    const vstree_t_node *x = &t_nodes[k];
    float len = x->normal[0] * x->normal[0] + x->normal[1] * x->normal[1] +
                x->normal[2] * x->normal[2];
    CHECK(x->node < n && nodes[x->node].kind == VSTREE_NODE_KIND_TRANSITION);
    CHECK(nodes[x->node].t_node == k && x->cluster_count >= 1);
    CHECK(fabsf(len - 1.0f) < 1e-4f && x->square_half > 0);
  }
  EXPECT(VSTREE_STATUS_OK, NULL,
         vstree_tree_copy_vertex_labels(t, VSTREE_LABEL_KIND_CLUSTER, labels, vn));
  for (k = 0; k < vn; k++) {
    CHECK(labels[k] < s->clusters);
  }
  EXPECT(VSTREE_STATUS_OK, NULL,
         vstree_tree_copy_vertex_labels(t, VSTREE_LABEL_KIND_T_NODE, labels, vn));
  for (k = 0; k < vn; k++) {
    CHECK(labels[k] < tn || labels[k] == VSTREE_NO_INDEX);
  }
  vstree_tree_free(t);

  /* An octree has no T-layer: nothing to copy, a NULL buffer is fine. */
  octree.tree_kind = VSTREE_TREE_KIND_OCTREE;
  t = NULL;
  EXPECT(VSTREE_STATUS_OK, NULL, vstree_tree_build(mesh, &octree, NULL, NULL, &t));
  CHECK(vstree_tree_t_node_count(t) == 0 && vstree_tree_get_stats(t)->s_nodes == 0);
  EXPECT(VSTREE_STATUS_OK, NULL, vstree_tree_copy_t_nodes(t, NULL, 0));
  vstree_tree_free(t);

  free(nodes);
  free(t_nodes);
  free(levels);
  free(labels);
  cancel_at_every_report("vstree_tree_build", tree_call, mesh, free_tree);
}

/* ---- reconstruction and normal estimation ---- */

#define SENTINEL_RECONSTRUCT ((vstree_reconstruct_result *)(uintptr_t)0x10)

/* Small enough to run quickly under valgrind. */
static vstree_reconstruct_params quick_reconstruct_params(void) {
  vstree_reconstruct_params p = vstree_reconstruct_params_default();
  p.max_levels = 2;
  p.max_grid_depth = 6;
  return p;
}

static vstree_status reconstruct_call(const vstree_mesh *m, stopper *s, void **out) {
  vstree_reconstruct_result *r = SENTINEL_RECONSTRUCT;
  vstree_reconstruct_params p = quick_reconstruct_params();
  vstree_status status = vstree_reconstruct(m, &p, stop_cb, s, &r);
  *out = r;
  return status;
}

static vstree_status normals_call(const vstree_mesh *m, stopper *s, void **out) {
  vstree_mesh *n = SENTINEL_MESH;
  vstree_normals_report report;
  vstree_status status;
  memset(&report, 0x5a, sizeof report);
  report.struct_size = sizeof report;
  status = vstree_estimate_normals(m, NULL, stop_cb, s, &n, &report);
  if (status != VSTREE_STATUS_OK) {
    CHECK(report.struct_size == sizeof report && report.estimated == 0x5a5a5a5a5a5a5a5aULL);
  }
  *out = n;
  return status;
}

static void free_reconstruct(void *r) {
  vstree_reconstruct_result_free((vstree_reconstruct_result *)r);
}
static void free_mesh(void *m) { vstree_mesh_free((vstree_mesh *)m); }

#define RSPOILER(name, field, value)                                                           \
  static void name(vstree_reconstruct_params *q) { q->field = value; }
RSPOILER(r_orient_neg, orient, -1)
RSPOILER(r_orient_big, orient, 4)
RSPOILER(r_error_zero, error, 0.0)
RSPOILER(r_error_nan, error, NAN)
RSPOILER(r_error_inf, error, INFINITY)
RSPOILER(r_d_a_big, d_a, 1.5f)
RSPOILER(r_d_a_nan, d_a, NAN)
RSPOILER(r_d_d_neg, d_d, -0.5f)
RSPOILER(r_depth_zero, max_depth, 0)
RSPOILER(r_depth_big, max_depth, 31)
RSPOILER(r_levels_big, max_levels, 13)
RSPOILER(r_levels_huge, max_levels, UINT32_MAX)
RSPOILER(r_cell_one, min_cell_size, 1.0)
RSPOILER(r_cell_nan, min_cell_size, NAN)
RSPOILER(r_target_neg, target_distance, -1e-3)
RSPOILER(r_target_nan, target_distance, NAN)
RSPOILER(r_target_inf, target_distance, INFINITY)
RSPOILER(r_displaced_big, min_displaced, 1.5)
RSPOILER(r_displaced_nan, min_displaced, NAN)
RSPOILER(r_triangles_zero, max_triangles, 0)
RSPOILER(r_grid_small, max_grid_depth, 3)
RSPOILER(r_grid_big, max_grid_depth, 21)
RSPOILER(r_trim_neg, trim, -1.0f)
RSPOILER(r_trim_nan, trim, NAN)
RSPOILER(r_neighbours_small, neighbours, 2)
RSPOILER(r_neighbours_big, neighbours, 257)
RSPOILER(r_reorient_two, reorient_given, 2)
RSPOILER(r_threads_big, threads, 1025)
RSPOILER(r_threads_huge, threads, UINT32_MAX)
RSPOILER(r_size_zero, struct_size, 0)
RSPOILER(r_size_short, struct_size, 8)
RSPOILER(r_size_long, struct_size, 4096)

#define NSPOILER(name, field, value)                                                           \
  static void name(vstree_normal_params *q) { q->field = value; }
NSPOILER(n_orient_neg, orient, -1)
NSPOILER(n_orient_big, orient, 4)
NSPOILER(n_neighbours_zero, neighbours, 0)
NSPOILER(n_neighbours_big, neighbours, 257)
NSPOILER(n_neighbours_huge, neighbours, UINT32_MAX)
NSPOILER(n_reorient_two, reorient_given, 2)
NSPOILER(n_threads_big, threads, 1025)
NSPOILER(n_size_zero, struct_size, 0)
NSPOILER(n_size_short, struct_size, 19)
NSPOILER(n_size_long, struct_size, 4096)

/* Every directed edge (a, b) has its twin (b, a) exactly once: closed, consistently oriented. */
static int compare_u64(const void *a, const void *b) {
  uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
  return x < y ? -1 : x > y;
}

static int watertight(const uint32_t *tri, size_t t, size_t n) {
  uint64_t *edges = (uint64_t *)malloc(3 * t * sizeof *edges);
  size_t k, ok = 1;
  for (k = 0; k < 3 * t; k++) {
    uint32_t a = tri[k], b = tri[k % 3 == 2 ? k - 2 : k + 1];
    ok &= a < n && b < n && a != b;
    edges[k] = ((uint64_t)a << 32) | b;
  }
  qsort(edges, 3 * t, sizeof *edges, compare_u64);
  for (k = 0; ok && k < 3 * t; k++) {
    uint64_t twin = (edges[k] << 32) | (edges[k] >> 32);
    ok &= (k + 1 == 3 * t || edges[k + 1] != edges[k]) &&
          bsearch(&twin, edges, 3 * t, sizeof *edges, compare_u64) != NULL;
  }
  free(edges);
  return (int)ok;
}

static void reconstruction(const vstree_mesh *cloud, const vstree_mesh *cloud_no_normals) {
  struct bad {
    const char *needle;
    vstree_status expected;
    void (*spoil)(vstree_reconstruct_params *);
  } table[] = {
      {"`orient`", VSTREE_STATUS_INVALID_PARAMETER, r_orient_neg},
      {"`orient`", VSTREE_STATUS_INVALID_PARAMETER, r_orient_big},
      {"`error`", VSTREE_STATUS_INVALID_PARAMETER, r_error_zero},
      {"`error`", VSTREE_STATUS_INVALID_PARAMETER, r_error_nan},
      {"`error`", VSTREE_STATUS_INVALID_PARAMETER, r_error_inf},
      {"`d_a`", VSTREE_STATUS_INVALID_PARAMETER, r_d_a_big},
      {"`d_a`", VSTREE_STATUS_INVALID_PARAMETER, r_d_a_nan},
      {"`d_d`", VSTREE_STATUS_INVALID_PARAMETER, r_d_d_neg},
      {"`max_depth`", VSTREE_STATUS_INVALID_PARAMETER, r_depth_zero},
      {"`max_depth`", VSTREE_STATUS_INVALID_PARAMETER, r_depth_big},
      {"`max_levels`", VSTREE_STATUS_INVALID_PARAMETER, r_levels_big},
      {"`max_levels`", VSTREE_STATUS_INVALID_PARAMETER, r_levels_huge},
      {"`min_cell_size`", VSTREE_STATUS_INVALID_PARAMETER, r_cell_one},
      {"`min_cell_size`", VSTREE_STATUS_INVALID_PARAMETER, r_cell_nan},
      {"`target_distance`", VSTREE_STATUS_INVALID_PARAMETER, r_target_neg},
      {"`target_distance`", VSTREE_STATUS_INVALID_PARAMETER, r_target_nan},
      {"`target_distance`", VSTREE_STATUS_INVALID_PARAMETER, r_target_inf},
      {"`min_displaced`", VSTREE_STATUS_INVALID_PARAMETER, r_displaced_big},
      {"`min_displaced`", VSTREE_STATUS_INVALID_PARAMETER, r_displaced_nan},
      {"`max_triangles`", VSTREE_STATUS_INVALID_PARAMETER, r_triangles_zero},
      {"`max_grid_depth`", VSTREE_STATUS_INVALID_PARAMETER, r_grid_small},
      {"`max_grid_depth`", VSTREE_STATUS_INVALID_PARAMETER, r_grid_big},
      {"`trim`", VSTREE_STATUS_INVALID_PARAMETER, r_trim_neg},
      {"`trim`", VSTREE_STATUS_INVALID_PARAMETER, r_trim_nan},
      {"`neighbours`", VSTREE_STATUS_INVALID_PARAMETER, r_neighbours_small},
      {"`neighbours`", VSTREE_STATUS_INVALID_PARAMETER, r_neighbours_big},
      {"`reorient_given`", VSTREE_STATUS_INVALID_PARAMETER, r_reorient_two},
      {"`threads`", VSTREE_STATUS_INVALID_PARAMETER, r_threads_big},
      {"`threads`", VSTREE_STATUS_INVALID_PARAMETER, r_threads_huge},
      {"params->struct_size", VSTREE_STATUS_INVALID_ARGUMENT, r_size_zero},
      {"params->struct_size", VSTREE_STATUS_INVALID_ARGUMENT, r_size_short},
      {"newer vstree.h", VSTREE_STATUS_INVALID_ARGUMENT, r_size_long},
  };
  vstree_reconstruct_params d = vstree_reconstruct_params_default();
  vstree_reconstruct_params p = quick_reconstruct_params();
  vstree_reconstruct_result *r = SENTINEL_RECONSTRUCT;
  vstree_mesh *taken = SENTINEL_MESH, *few = NULL;
  const vstree_reconstruct_stats *s;
  const vstree_mesh *out;
  float points[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1};
  size_t k;

  CHECK(d.struct_size == sizeof(vstree_reconstruct_params));
  CHECK(d.orient == VSTREE_ORIENTATION_PROPAGATE_OUTWARD && d.reorient_given == 0);
  CHECK(d.error > 0 && d.max_levels <= 12 && d.max_grid_depth >= 4 && d.max_grid_depth <= 20);
  CHECK(d.neighbours >= 3 && d.threads == 0 && d.trim == 0 && d.max_triangles > 0);

  EXPECT(VSTREE_STATUS_NULL_POINTER, "`out_result`",
         vstree_reconstruct(cloud, NULL, NULL, NULL, NULL));
  EXPECT(VSTREE_STATUS_NULL_POINTER, "`cloud`", vstree_reconstruct(NULL, NULL, NULL, NULL, &r));
  EXPECT(VSTREE_STATUS_OK, NULL, vstree_mesh_create(points, 5, NULL, NULL, 0, &few));
  EXPECT(VSTREE_STATUS_INVALID_INPUT, "5 points", vstree_reconstruct(few, NULL, NULL, NULL, &r));
  EXPECT(VSTREE_STATUS_INVALID_INPUT, "5 points", vstree_reconstruct(few, &p, NULL, NULL, &r));
  vstree_mesh_free(few);
  for (k = 0; k < sizeof table / sizeof table[0]; k++) {
    vstree_reconstruct_params q = quick_reconstruct_params();
    table[k].spoil(&q);
    EXPECT(table[k].expected, table[k].needle, vstree_reconstruct(cloud, &q, NULL, NULL, &r));
  }
  CHECK(r == SENTINEL_RECONSTRUCT);
  CHECK(vstree_reconstruct_result_get_mesh(NULL) == NULL);
  CHECK(vstree_reconstruct_result_get_stats(NULL) == NULL);
  vstree_reconstruct_result_free(NULL);
  EXPECT(VSTREE_STATUS_NULL_POINTER, "`result`",
         vstree_reconstruct_result_take_mesh(NULL, &taken));
  CHECK(taken == SENTINEL_MESH);

  /* Good input: a torus cloud without normals gives a closed genus-1 surface. */
  EXPECT(VSTREE_STATUS_OK, NULL, vstree_reconstruct(cloud_no_normals, &p, NULL, NULL, &r));
  s = vstree_reconstruct_result_get_stats(r);
  out = vstree_reconstruct_result_get_mesh(r);
  CHECK(s != NULL && out != NULL);
  if (s != NULL && out != NULL) {
    size_t n = vstree_mesh_vertex_count(out), t = vstree_mesh_triangle_count(out);
    uint32_t *tri = (uint32_t *)malloc(3 * t * sizeof *tri + 1);
    CHECK(s->struct_size == sizeof(vstree_reconstruct_stats));
    CHECK(n > 0 && t > 0 && vstree_mesh_has_normals(out) == 1);
    CHECK(s->output_vertices == n && s->output_triangles == t);
    CHECK(s->input_points == vstree_mesh_vertex_count(cloud_no_normals));
    CHECK(s->normals_estimated == s->input_points && s->normals_neighbours == d.neighbours);
    CHECK(s->samples == s->input_points && s->t_nodes > 0 && s->nodes > s->t_nodes);
    CHECK(s->base_genus == 1 && s->base_vertices > 0 && s->base_triangles == 2 * s->base_vertices);
    CHECK(s->levels <= p.max_levels && s->grid_cells >= 2 && s->grid_cells <= 64u);
    CHECK(t == 2 * n); /* Euler: a closed genus-1 surface */
    CHECK(s->final_error > 0 && s->final_error <= s->final_max_error && s->final_error < 1e-2);
    CHECK(s->trimmed_triangles == 0);
    CHECK(s->seconds_total >= s->seconds_tree && s->seconds_tree >= 0 && s->seconds_refine >= 0);
    /* On this coarse grid (64 cells) the winding number's plain polygonisation of the
       estimated-normal torus has extra handles that thickening removes; either way M0 has the
       torus's one handle (checked above). */
    CHECK(s->thickened == 0 || s->thickened == 1);
    CHECK(s->stopped <= VSTREE_REFINEMENT_STOPPED_TRIANGLE_BUDGET);
    CHECK(s->stopped != VSTREE_REFINEMENT_STOPPED_MAX_LEVELS || s->levels == p.max_levels);
    EXPECT(VSTREE_STATUS_OK, NULL, vstree_mesh_copy_triangles(out, tri, 3 * t));
    CHECK(watertight(tri, t, n));
    free(tri);
  }
  EXPECT(VSTREE_STATUS_NULL_POINTER, "`out_mesh`", vstree_reconstruct_result_take_mesh(r, NULL));
  EXPECT(VSTREE_STATUS_OK, NULL, vstree_reconstruct_result_take_mesh(r, &taken));
  CHECK(taken != SENTINEL_MESH && vstree_mesh_triangle_count(taken) > 0);
  vstree_mesh_free(taken);

  /* The cloud's own normals are kept; trimming runs. */
  p.trim = 1.5f;
  r = NULL;
  EXPECT(VSTREE_STATUS_OK, NULL, vstree_reconstruct(cloud, &p, NULL, NULL, &r));
  CHECK(r != NULL && vstree_reconstruct_result_get_stats(r)->normals_estimated == 0);
  CHECK(r != NULL && vstree_reconstruct_result_get_stats(r)->output_triangles > 0);
  vstree_reconstruct_result_free(r);

  cancel_at_every_report("vstree_reconstruct", reconstruct_call, cloud_no_normals,
                         free_reconstruct);
}

static void normal_estimation(const torus *tor, const vstree_mesh *cloud_no_normals,
                              const vstree_mesh *mesh_no_normals) {
  struct bad {
    const char *needle;
    vstree_status expected;
    void (*spoil)(vstree_normal_params *);
  } table[] = {
      {"`orient`", VSTREE_STATUS_INVALID_PARAMETER, n_orient_neg},
      {"`orient`", VSTREE_STATUS_INVALID_PARAMETER, n_orient_big},
      {"`neighbours`", VSTREE_STATUS_INVALID_PARAMETER, n_neighbours_zero},
      {"`neighbours`", VSTREE_STATUS_INVALID_PARAMETER, n_neighbours_big},
      {"`neighbours`", VSTREE_STATUS_INVALID_PARAMETER, n_neighbours_huge},
      {"`reorient_given`", VSTREE_STATUS_INVALID_PARAMETER, n_reorient_two},
      {"`threads`", VSTREE_STATUS_INVALID_PARAMETER, n_threads_big},
      {"params->struct_size", VSTREE_STATUS_INVALID_ARGUMENT, n_size_zero},
      {"params->struct_size", VSTREE_STATUS_INVALID_ARGUMENT, n_size_short},
      {"newer vstree.h", VSTREE_STATUS_INVALID_ARGUMENT, n_size_long},
  };
  vstree_normal_params d = vstree_normal_params_default();
  vstree_normals_report report;
  vstree_mesh *out = SENTINEL_MESH, *two = NULL, *line = NULL;
  float points[30];
  size_t k, n = vstree_mesh_vertex_count(cloud_no_normals);

  CHECK(d.struct_size == sizeof(vstree_normal_params));
  CHECK(d.orient == VSTREE_ORIENTATION_PROPAGATE_OUTWARD && d.neighbours >= 3);
  CHECK(d.reorient_given == 0 && d.threads == 0);

  memset(&report, 0, sizeof report);
  report.struct_size = sizeof report;
  EXPECT(VSTREE_STATUS_NULL_POINTER, "`out_mesh`",
         vstree_estimate_normals(cloud_no_normals, NULL, NULL, NULL, NULL, &report));
  EXPECT(VSTREE_STATUS_NULL_POINTER, "`mesh`",
         vstree_estimate_normals(NULL, NULL, NULL, NULL, &out, &report));
  for (k = 0; k < 10; k++) {
    points[3 * k] = (float)k;
    points[3 * k + 1] = 2.0f * (float)k;
    points[3 * k + 2] = -(float)k;
  }
  EXPECT(VSTREE_STATUS_OK, NULL, vstree_mesh_create(points, 2, NULL, NULL, 0, &two));
  EXPECT(VSTREE_STATUS_INVALID_INPUT, "2 points",
         vstree_estimate_normals(two, NULL, NULL, NULL, &out, NULL));
  EXPECT(VSTREE_STATUS_OK, NULL, vstree_mesh_create(points, 10, NULL, NULL, 0, &line));
  EXPECT(VSTREE_STATUS_INVALID_INPUT, NULL,
         vstree_estimate_normals(line, NULL, NULL, NULL, &out, NULL));
  vstree_mesh_free(two);
  vstree_mesh_free(line);
  for (k = 0; k < sizeof table / sizeof table[0]; k++) {
    vstree_normal_params q = vstree_normal_params_default();
    table[k].spoil(&q);
    EXPECT(table[k].expected, table[k].needle,
           vstree_estimate_normals(cloud_no_normals, &q, NULL, NULL, &out, NULL));
  }
  report.struct_size = 0;
  EXPECT(VSTREE_STATUS_INVALID_ARGUMENT, "out_report->struct_size",
         vstree_estimate_normals(cloud_no_normals, NULL, NULL, NULL, &out, &report));
  report.struct_size = 12;
  EXPECT(VSTREE_STATUS_INVALID_ARGUMENT, "out_report->struct_size",
         vstree_estimate_normals(cloud_no_normals, NULL, NULL, NULL, &out, &report));
  CHECK(out == SENTINEL_MESH && report.struct_size == 12 && report.estimated == 0);

  /* Good input: a new cloud with outward normals; the input is unchanged. */
  report.struct_size = sizeof report;
  EXPECT(VSTREE_STATUS_OK, NULL,
         vstree_estimate_normals(cloud_no_normals, NULL, NULL, NULL, &out, &report));
  CHECK(out != SENTINEL_MESH && vstree_mesh_has_normals(out) == 1);
  CHECK(vstree_mesh_has_normals(cloud_no_normals) == 0 && vstree_mesh_vertex_count(out) == n);
  CHECK(report.struct_size == sizeof report && report.estimated == n && report.oriented == 1);
  CHECK(report.neighbours == d.neighbours && report.components >= 1 && report.largest_component <= n);
  {
    float *normals = (float *)malloc(3 * n * sizeof(float));
    size_t outward = 0;
    EXPECT(VSTREE_STATUS_OK, NULL, vstree_mesh_copy_normals(out, normals, 3 * n));
    for (k = 0; k < n; k++) {
      const float *truth = tor->normals + 3 * k, *got = normals + 3 * k;
      outward += truth[0] * got[0] + truth[1] * got[1] + truth[2] * got[2] > 0.0f;
    }
    CHECK(outward == n);
    free(normals);
  }
  vstree_mesh_free(out);

  /* A triangle mesh keeps its triangles; NULL report and unoriented are fine. */
  d.orient = VSTREE_ORIENTATION_UNORIENTED;
  out = NULL;
  EXPECT(VSTREE_STATUS_OK, NULL, vstree_estimate_normals(mesh_no_normals, &d, NULL, NULL, &out, NULL));
  CHECK(vstree_mesh_triangle_count(out) == vstree_mesh_triangle_count(mesh_no_normals));
  CHECK(vstree_mesh_has_normals(out) == 1);
  vstree_mesh_free(out);

  cancel_at_every_report("vstree_estimate_normals", normals_call, cloud_no_normals, free_mesh);
}

/* Simplification to a size: the count within 1% (or 2 triangles), the torus closed with its
 * genus (V = F / 2) unless plain clustering is asked for; a target the topology cannot reach
 * gives the smallest closed mesh, not an empty one; a caller with the 0.1 struct (48 bytes)
 * gets the error bound whatever lies after it. */
static void sized_simplification(const vstree_mesh *mesh) {
  const uint32_t targets[] = {1000, 230, 50, 1};
  const int32_t modes[] = {VSTREE_KEEP_TOPOLOGY_AUTO, VSTREE_KEEP_TOPOLOGY_ON,
                           VSTREE_KEEP_TOPOLOGY_OFF};
  size_t i, m;
  for (m = 0; m < sizeof modes / sizeof modes[0]; m++) {
    for (i = 0; i < sizeof targets / sizeof targets[0]; i++) {
      vstree_simplify_params p = vstree_simplify_params_default();
      vstree_simplify_result *r = NULL;
      const vstree_simplify_stats *s;
      const vstree_mesh *out;
      size_t f, v, slack = targets[i] / 100 > 2 ? targets[i] / 100 : 2;
      uint32_t *tri;
      p.target_faces = targets[i];
      p.keep_topology = modes[m];
      EXPECT(VSTREE_STATUS_OK, NULL, vstree_simplify(mesh, &p, NULL, NULL, &r));
      if (r == NULL) continue;
      s = vstree_simplify_result_get_stats(r);
      out = vstree_simplify_result_get_mesh(r);
      f = vstree_mesh_triangle_count(out);
      v = vstree_mesh_vertex_count(out);
      CHECK(s->target_faces == targets[i] && s->output_triangles == f);
      CHECK(s->kept_topology == (modes[m] != VSTREE_KEEP_TOPOLOGY_OFF));
      if (targets[i] == 1 && modes[m] != VSTREE_KEEP_TOPOLOGY_OFF) {
        CHECK(f >= 14 && f <= 60); /* a torus needs 14 triangles at least */
      } else if (targets[i] > 1) {
        CHECK(f + slack >= targets[i] && f <= targets[i] + slack);
      }
      CHECK(f > 0);
      if (modes[m] != VSTREE_KEEP_TOPOLOGY_OFF) {
        tri = (uint32_t *)malloc(3 * f * sizeof *tri);
        EXPECT(VSTREE_STATUS_OK, NULL, vstree_mesh_copy_triangles(out, tri, 3 * f));
        CHECK(watertight(tri, f, v));
        CHECK(2 * v == f);
        free(tri);
      }
      vstree_simplify_result_free(r);
    }
  }
  {
    vstree_simplify_params p = vstree_simplify_params_default();
    vstree_simplify_result *r = NULL;
    p.struct_size = 48;
    p.target_faces = 50;
    p.keep_topology = 99;
    EXPECT(VSTREE_STATUS_OK, NULL, vstree_simplify(mesh, &p, NULL, NULL, &r));
    if (r != NULL) {
      const vstree_simplify_stats *s = vstree_simplify_result_get_stats(r);
      CHECK(s->target_faces == 0 && s->kept_topology == 1 && s->output_triangles > 100);
      vstree_simplify_result_free(r);
    }
  }
}

/* The library inside a host installs no signal handler of its own (only the vstree program
 * does, to remove its temporary output): writing a file and simplifying leave SIGINT and
 * SIGTERM as the host set them. */
static void host_signals_untouched(const vstree_mesh *mesh) {
  char path[4096];
  vstree_simplify_result *r = NULL;
  void (*before_int)(int) = signal(SIGINT, SIG_DFL);
  void (*before_term)(int) = signal(SIGTERM, SIG_DFL);
  signal(SIGINT, before_int);
  signal(SIGTERM, before_term);
  EXPECT(VSTREE_STATUS_OK, NULL, vstree_mesh_save(mesh, path_in_dir(path, sizeof path, "signals.ply"), 0));
  EXPECT(VSTREE_STATUS_OK, NULL, vstree_simplify(mesh, NULL, NULL, NULL, &r));
  vstree_simplify_result_free(r);
  remove(path);
  CHECK(signal(SIGINT, before_int) == before_int);
  CHECK(signal(SIGTERM, before_term) == before_term);
}

int main(int argc, char **argv) {
  torus t = make_torus(48, 24, 0.2f);
  vstree_mesh *mesh, *cloud, *cloud_no_normals, *mesh_no_normals;
  if (argc != 2) {
    fprintf(stderr, "usage: %s TEMP_DIR\n", argv[0]);
    return 2;
  }
  snprintf(g_dir, sizeof g_dir, "%s", argv[1]);
  mesh = torus_mesh(&t, 1, 1);
  cloud = torus_mesh(&t, 1, 0);
  cloud_no_normals = torus_mesh(&t, 0, 0);
  mesh_no_normals = torus_mesh(&t, 0, 1);

  version_and_errors();
  mesh_creation(&t);
  far_mesh_creation(&t);
  mesh_files(mesh);
  mesh_copies(mesh, cloud_no_normals);
  library_parameter_table();
  parameter_table(mesh);
  simplification(mesh, cloud, cloud_no_normals);
  trees(mesh);
  reconstruction(cloud, cloud_no_normals);
  normal_estimation(&t, cloud_no_normals, mesh_no_normals);
  sized_simplification(mesh);
  host_signals_untouched(mesh);

  vstree_mesh_free(mesh);
  vstree_mesh_free(cloud);
  vstree_mesh_free(cloud_no_normals);
  vstree_mesh_free(mesh_no_normals);
  free_torus(&t);
  fprintf(stderr, "test_api: %d bad-input/status rows\n", g_rows);
  return finish("test_api");
}
