/* The C API's answer to bad input, as a table: every row is one call with one thing wrong, the
 * exact status it must return and the exact message vstree_last_error_message() must give
 * (naming the function, the argument or field, the value, the file and line). The messages are
 * pinned as the library words them today, so a change of wording or of the culprit named
 * shows up here. Output pointers are preset to a sentinel and must be left alone.
 *
 * Expected messages: "{dir}" stands for TEMP_DIR, '*' matches any run of characters (used only
 * for pointer values and the like); everything else must match exactly. On Windows (built with
 * mingw-w64 and run under Wine by tests/platforms/run.sh) the operating system's own text for
 * a missing file differs, so "No such file or directory (os error 2)" matches any OS message
 * and code there, and the rows that need FIFOs, devices or symbolic links are left out.
 *
 * usage: test_bad_input TEMP_DIR   (a writable directory; run under valgrind by run.sh)
 */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#ifdef _WIN32
#include <direct.h>
#define mkdir(path, mode) _mkdir(path)
#else
#include <unistd.h>
#endif

#include <vstree.h>

#include "common.h"

/* ---- fixtures, made once in main ---- */

static char g_dir[2048];
static vstree_mesh *g_mesh;     /* a small torus: triangles and normals */
static vstree_mesh *g_cloud;    /* its vertices with normals, no triangles */
static vstree_mesh *g_cloud_nn; /* its vertices without normals */
static vstree_tree *g_tree;     /* vstree_tree_build(g_mesh, defaults) */
static float *g_positions;      /* the torus arrays */
static float *g_normals;
static uint32_t *g_triangles;
static size_t g_vertex_count, g_triangle_count;

/* Set by a call when something other than status and message is wrong (an output written on
 * failure, a buffer changed); reported with the case. */
static char g_problem[512];

#define SENTINEL ((void *)(uintptr_t)0x10)

static void problem(const char *what) {
  if (g_problem[0] == '\0') {
    snprintf(g_problem, sizeof g_problem, "%s", what);
  }
}

/* Called after every call with an output handle: a failing call must leave it at SENTINEL; a
 * call that wrongly succeeds has its output freed so that valgrind still sees no leak. */
static void mesh_out(vstree_status s, vstree_mesh *m) {
  if (s == VSTREE_STATUS_OK) {
    if (m != SENTINEL) vstree_mesh_free(m);
  } else if (m != SENTINEL) {
    problem("the output mesh was written by a failing call");
  }
}

static void simplify_out(vstree_status s, vstree_simplify_result *r) {
  if (s == VSTREE_STATUS_OK) {
    if (r != SENTINEL) vstree_simplify_result_free(r);
  } else if (r != SENTINEL) {
    problem("the output result was written by a failing call");
  }
}

static void tree_out(vstree_status s, vstree_tree *t) {
  if (s == VSTREE_STATUS_OK) {
    if (t != SENTINEL) vstree_tree_free(t);
  } else if (t != SENTINEL) {
    problem("the output tree was written by a failing call");
  }
}

static void reconstruct_out(vstree_status s, vstree_reconstruct_result *r) {
  if (s == VSTREE_STATUS_OK) {
    if (r != SENTINEL) vstree_reconstruct_result_free(r);
  } else if (r != SENTINEL) {
    problem("the output result was written by a failing call");
  }
}

/* ---- helpers the calls share ---- */

static vstree_status create(const float *p, size_t n, const float *normals, const uint32_t *t,
                            size_t m) {
  vstree_mesh *out = (vstree_mesh *)SENTINEL;
  vstree_status s = vstree_mesh_create(p, n, normals, t, m, &out);
  mesh_out(s, out);
  return s;
}

/* Four vertices of a tetrahedron and one triangle, with one value changed by the caller. */
static float g_quad[12];
static float g_quad_normals[12];
static uint32_t g_tri[3];
static void reset_small(void) {
  static const float p[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  static const float n[12] = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
  memcpy(g_quad, p, sizeof p);
  memcpy(g_quad_normals, n, sizeof n);
  g_tri[0] = 0;
  g_tri[1] = 1;
  g_tri[2] = 2;
}

static void write_file(const char *name, const char *content, size_t size) {
  char path[4096];
  FILE *f;
  snprintf(path, sizeof path, "%s/%s", g_dir, name);
  f = fopen(path, "wb");
  if (!f || fwrite(content, 1, size, f) != size || fclose(f) != 0) {
    fprintf(stderr, "cannot write %s\n", path);
    exit(2);
  }
}

static vstree_status load(const char *name) {
  char path[4096];
  vstree_mesh *m = (vstree_mesh *)SENTINEL;
  vstree_status s;
  snprintf(path, sizeof path, "%s/%s", g_dir, name);
  s = vstree_mesh_load(path, &m);
  mesh_out(s, m);
  return s;
}

/* Writes `content` (a string) to TEMP_DIR/name and loads it. */
static vstree_status load_text(const char *name, const char *content) {
  write_file(name, content, strlen(content));
  return load(name);
}

static vstree_status load_memory(const void *data, size_t size, const char *name) {
  vstree_mesh *m = (vstree_mesh *)SENTINEL;
  vstree_status s = vstree_mesh_load_memory(data, size, name, &m);
  mesh_out(s, m);
  return s;
}

static vstree_status save(const vstree_mesh *mesh, const char *name, uint32_t flags) {
  char path[4096];
  snprintf(path, sizeof path, "%s/%s", g_dir, name);
  return vstree_mesh_save(mesh, path, flags);
}

static vstree_status simplify_with(const vstree_mesh *mesh, const vstree_simplify_params *p) {
  vstree_simplify_result *r = (vstree_simplify_result *)SENTINEL;
  vstree_status s = vstree_simplify(mesh, p, NULL, NULL, &r);
  simplify_out(s, r);
  return s;
}

static vstree_status tree_with(const vstree_mesh *mesh, const vstree_simplify_params *p) {
  vstree_tree *t = (vstree_tree *)SENTINEL;
  vstree_status s = vstree_tree_build(mesh, p, NULL, NULL, &t);
  tree_out(s, t);
  return s;
}

/* Quick settings so that a wrongly accepted parameter does not run for minutes. */
static vstree_reconstruct_params quick_reconstruct(void) {
  vstree_reconstruct_params p = vstree_reconstruct_params_default();
  p.max_levels = 1;
  p.max_grid_depth = 5;
  return p;
}

static vstree_status reconstruct_with(const vstree_mesh *cloud,
                                      const vstree_reconstruct_params *p) {
  vstree_reconstruct_result *r = (vstree_reconstruct_result *)SENTINEL;
  vstree_status s = vstree_reconstruct(cloud, p, NULL, NULL, &r);
  reconstruct_out(s, r);
  return s;
}

static vstree_status normals_with(const vstree_mesh *mesh, const vstree_normal_params *p,
                                  vstree_normals_report *report) {
  vstree_mesh *m = (vstree_mesh *)SENTINEL;
  vstree_status s = vstree_estimate_normals(mesh, p, NULL, NULL, &m, report);
  mesh_out(s, m);
  return s;
}

/* Caller buffers, preset to 42 and checked to still hold 42 after a failing copy. */
static float g_floats[4096];
static uint32_t g_indices[4096];
static void fill_buffers(void) {
  size_t k;
  for (k = 0; k < sizeof g_floats / sizeof g_floats[0]; k++) g_floats[k] = 42.0f;
  for (k = 0; k < sizeof g_indices / sizeof g_indices[0]; k++) g_indices[k] = 42u;
}
static void buffers_untouched(void) {
  size_t k;
  for (k = 0; k < sizeof g_floats / sizeof g_floats[0]; k++) {
    if (g_floats[k] != 42.0f) {
      problem("a failing copy wrote into the float buffer");
      return;
    }
  }
  for (k = 0; k < sizeof g_indices / sizeof g_indices[0]; k++) {
    if (g_indices[k] != 42u) {
      problem("a failing copy wrote into the index buffer");
      return;
    }
  }
}

/* A pointer one byte past an aligned one: misaligned for every type wider than a byte. */
static void *misaligned(void *p) { return (void *)((char *)p + 1); }

/* ---- the calls, one per case ---- */

#define CALL(name) static vstree_status name(void)

/* vstree_mesh_create */
CALL(create_out_null) {
  reset_small();
  return vstree_mesh_create(g_quad, 4, NULL, g_tri, 1, NULL);
}
CALL(create_positions_null) { reset_small(); return create(NULL, 4, NULL, g_tri, 1); }
CALL(create_triangles_null) { reset_small(); return create(g_quad, 4, NULL, NULL, 1); }
CALL(create_zero_vertices) { reset_small(); return create(g_quad, 0, NULL, g_tri, 0); }
CALL(create_zero_vertices_all_null) { return create(NULL, 0, NULL, NULL, 0); }
CALL(create_zero_vertices_with_triangles) {
  reset_small();
  return create(g_quad, 0, NULL, g_tri, 1);
}
CALL(create_vertices_above_u32) {
  reset_small();
  return create(g_quad, (size_t)UINT32_MAX + 1u, NULL, g_tri, 1);
}
CALL(create_vertices_size_max) { reset_small(); return create(g_quad, SIZE_MAX, NULL, g_tri, 1); }
CALL(create_vertices_times_3_overflows) {
  reset_small();
  return create(g_quad, SIZE_MAX / 3 + 1, NULL, g_tri, 1);
}
CALL(create_triangles_above_u32) {
  reset_small();
  return create(g_quad, 4, NULL, g_tri, (size_t)UINT32_MAX + 1u);
}
CALL(create_triangles_size_max) { reset_small(); return create(g_quad, 4, NULL, g_tri, SIZE_MAX); }
CALL(create_positions_misaligned) {
  reset_small();
  return create((const float *)misaligned(g_floats), 1, NULL, NULL, 0);
}
CALL(create_normals_misaligned) {
  reset_small();
  return create(g_quad, 1, (const float *)misaligned(g_floats), NULL, 0);
}
CALL(create_triangles_misaligned) {
  reset_small();
  return create(g_quad, 4, NULL, (const uint32_t *)misaligned(g_indices), 1);
}
CALL(create_position_nan) {
  reset_small();
  g_quad[4] = NAN;
  return create(g_quad, 4, NULL, g_tri, 1);
}
CALL(create_position_inf) {
  reset_small();
  g_quad[5] = INFINITY;
  return create(g_quad, 4, NULL, g_tri, 1);
}
CALL(create_position_minus_inf) {
  reset_small();
  g_quad[9] = -INFINITY;
  return create(g_quad, 4, NULL, NULL, 0);
}
CALL(create_position_above_1e18) {
  reset_small();
  g_quad[6] = 2e18f;
  return create(g_quad, 4, NULL, g_tri, 1);
}
CALL(create_position_below_minus_1e18) {
  reset_small();
  g_quad[11] = -1e19f;
  return create(g_quad, 4, NULL, NULL, 0);
}
CALL(create_position_float_max) {
  reset_small();
  g_quad[0] = 3.4e38f;
  return create(g_quad, 4, NULL, NULL, 0);
}
CALL(create_normal_nan) {
  reset_small();
  g_quad_normals[11] = NAN;
  return create(g_quad, 4, g_quad_normals, g_tri, 1);
}
CALL(create_normal_inf) {
  reset_small();
  g_quad_normals[3] = -INFINITY;
  return create(g_quad, 4, g_quad_normals, NULL, 0);
}
CALL(create_index_equal_count) {
  reset_small();
  g_tri[2] = 4;
  return create(g_quad, 4, NULL, g_tri, 1);
}
CALL(create_index_u32_max) {
  reset_small();
  g_tri[0] = UINT32_MAX;
  return create(g_quad, 4, NULL, g_tri, 1);
}
CALL(create_index_in_second_triangle) {
  uint32_t tris[6] = {0, 1, 2, 1, 2, 1000};
  reset_small();
  return create(g_quad, 4, NULL, tris, 2);
}

/* vstree_mesh_create_f64: the same tetrahedron in doubles */
static double g_quad_d[12];
static vstree_status create_f64(const double *p, size_t n, const float *normals,
                                const uint32_t *t, size_t m) {
  vstree_mesh *out = (vstree_mesh *)SENTINEL;
  vstree_status s = vstree_mesh_create_f64(p, n, normals, t, m, &out);
  mesh_out(s, out);
  return s;
}
static void reset_small_d(void) {
  size_t k;
  reset_small();
  for (k = 0; k < 12; k++) g_quad_d[k] = g_quad[k];
}
CALL(create_f64_out_null) {
  reset_small_d();
  return vstree_mesh_create_f64(g_quad_d, 4, NULL, g_tri, 1, NULL);
}
CALL(create_f64_positions_null) { reset_small_d(); return create_f64(NULL, 4, NULL, g_tri, 1); }
CALL(create_f64_triangles_null) { reset_small_d(); return create_f64(g_quad_d, 4, NULL, NULL, 1); }
CALL(create_f64_zero_vertices) { reset_small_d(); return create_f64(g_quad_d, 0, NULL, g_tri, 0); }
CALL(create_f64_vertices_above_u32) {
  reset_small_d();
  return create_f64(g_quad_d, (size_t)UINT32_MAX + 1u, NULL, g_tri, 1);
}
CALL(create_f64_vertices_times_3_overflows) {
  reset_small_d();
  return create_f64(g_quad_d, SIZE_MAX / 3 + 1, NULL, g_tri, 1);
}
CALL(create_f64_triangles_size_max) {
  reset_small_d();
  return create_f64(g_quad_d, 4, NULL, g_tri, SIZE_MAX);
}
CALL(create_f64_positions_aligned_to_4_only) {
  reset_small_d();
  return create_f64((const double *)(void *)((char *)g_quad_d + 4), 1, NULL, NULL, 0);
}
CALL(create_f64_normals_misaligned) {
  reset_small_d();
  return create_f64(g_quad_d, 1, (const float *)misaligned(g_floats), NULL, 0);
}
CALL(create_f64_position_nan) {
  reset_small_d();
  g_quad_d[4] = NAN;
  return create_f64(g_quad_d, 4, NULL, g_tri, 1);
}
CALL(create_f64_position_minus_inf) {
  reset_small_d();
  g_quad_d[9] = -INFINITY;
  return create_f64(g_quad_d, 4, NULL, NULL, 0);
}
CALL(create_f64_position_above_1e18) {
  reset_small_d();
  g_quad_d[6] = 2e18;
  return create_f64(g_quad_d, 4, NULL, g_tri, 1);
}
CALL(create_f64_position_below_minus_1e18) {
  reset_small_d();
  g_quad_d[11] = -1e19;
  return create_f64(g_quad_d, 4, NULL, NULL, 0);
}
CALL(create_f64_position_beyond_float) {
  reset_small_d();
  g_quad_d[0] = 1e300;
  return create_f64(g_quad_d, 4, NULL, NULL, 0);
}
CALL(create_f64_normal_nan) {
  reset_small_d();
  g_quad_normals[11] = NAN;
  return create_f64(g_quad_d, 4, g_quad_normals, g_tri, 1);
}
CALL(create_f64_index_equal_count) {
  reset_small_d();
  g_tri[2] = 4;
  return create_f64(g_quad_d, 4, NULL, g_tri, 1);
}

/* vstree_mesh_load */
CALL(load_out_null) { return vstree_mesh_load("x.ply", NULL); }
CALL(load_path_null) {
  vstree_mesh *m = (vstree_mesh *)SENTINEL;
  vstree_status s = vstree_mesh_load(NULL, &m);
  mesh_out(s, m);
  return s;
}
CALL(load_path_empty) {
  vstree_mesh *m = (vstree_mesh *)SENTINEL;
  vstree_status s = vstree_mesh_load("", &m);
  mesh_out(s, m);
  return s;
}
CALL(load_missing) { return load("missing.ply"); }
CALL(load_directory) { return load("sub.ply"); }
CALL(load_unsupported_extension) { return load_text("mesh.stl", "solid x\nendsolid x\n"); }
CALL(load_no_extension) { return load_text("mesh", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"); }
CALL(load_ply_empty) { return load_text("empty.ply", ""); }
CALL(load_ply_not_ply) { return load_text("magic.ply", "OFF\n3 1 0\n"); }
CALL(load_ply_bad_format) {
  return load_text("format.ply", "ply\nformat ascii 2.0\nelement vertex 1\nproperty float x\n"
                                 "property float y\nproperty float z\nend_header\n0 0 0\n");
}
CALL(load_ply_no_end_header) {
  return load_text("noend.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                                "property float y\nproperty float z\n");
}
CALL(load_ply_truncated) {
  return load_text("truncated.ply", "ply\nformat ascii 1.0\nelement vertex 3\n"
                                    "property float x\nproperty float y\nproperty float z\n"
                                    "end_header\n0 0 0\n1 0 0\n");
}
CALL(load_ply_bad_number) {
  return load_text("number.ply", "ply\nformat ascii 1.0\nelement vertex 3\n"
                                 "property float x\nproperty float y\nproperty float z\n"
                                 "end_header\n0 0 0\n1 zero 0\n0 1 0\n");
}
CALL(load_ply_face_out_of_range) {
  return load_text("range.ply", "ply\nformat ascii 1.0\nelement vertex 3\n"
                                "property float x\nproperty float y\nproperty float z\n"
                                "element face 1\nproperty list uchar int vertex_indices\n"
                                "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n");
}
CALL(load_ply_no_xyz) {
  return load_text("noxyz.ply", "ply\nformat ascii 1.0\nelement vertex 1\n"
                                "property float x\nproperty float y\nend_header\n0 0\n");
}
CALL(load_ply_binary_truncated) {
  static const char header[] = "ply\nformat binary_little_endian 1.0\nelement vertex 2\n"
                               "property float x\nproperty float y\nproperty float z\n"
                               "end_header\n";
  char bytes[sizeof header - 1 + 12];
  memcpy(bytes, header, sizeof header - 1);
  memset(bytes + sizeof header - 1, 0, 12); /* one vertex of the two */
  write_file("binary.ply", bytes, sizeof bytes);
  return load("binary.ply");
}
CALL(load_off_bad_header) {
  return load_text("header.off", "OFX\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
}
CALL(load_off_bad_counts) { return load_text("counts.off", "OFF\n3 x 0\n0 0 0\n1 0 0\n0 1 0\n"); }
CALL(load_off_truncated) { return load_text("short.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n"); }
CALL(load_off_out_of_range) {
  return load_text("range.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n");
}
CALL(load_off_nan) { return load_text("nan.off", "OFF\n3 1 0\n0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n"); }
CALL(load_off_huge_coordinate) {
  return load_text("huge.off", "OFF\n3 1 0\n0 0 0\n1e19 0 0\n0 1 0\n3 0 1 2\n");
}
CALL(load_obj_short_vertex) { return load_text("short.obj", "v 0 0 0\nv 1 0\nv 0 1 0\nf 1 2 3\n"); }
CALL(load_obj_bad_number) {
  return load_text("number.obj", "# comment\nv 0 0 0\nv 1 0 x\nv 0 1 0\nf 1 2 3\n");
}
CALL(load_obj_face_out_of_range) {
  return load_text("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");
}
CALL(load_obj_face_zero_index) {
  return load_text("zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n");
}
CALL(load_obj_faces_without_vertices) { return load_text("faces.obj", "# no v lines\nf 1 2 3\n"); }
CALL(load_xyz_two_numbers) { return load_text("two.xyz", "0 0 0\n1 0 0\n1 2\n"); }
CALL(load_xyz_bad_number) { return load_text("number.xyz", "0 0 0\n1 0 0\n1 two 3\n"); }
CALL(load_xyz_inf) { return load_text("inf.xyz", "0 0 0\ninf 0 0\n"); }
CALL(load_pwn_bad_count) { return load_text("count.pwn", "many\n0 0 0\n"); }

/* vstree_mesh_load_memory */
static const char g_off[] = "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
CALL(memory_out_null) { return vstree_mesh_load_memory(g_off, sizeof g_off - 1, "off", NULL); }
CALL(memory_data_null) { return load_memory(NULL, 10, "off"); }
CALL(memory_name_null) { return load_memory(g_off, sizeof g_off - 1, NULL); }
CALL(memory_name_empty) { return load_memory(g_off, sizeof g_off - 1, ""); }
CALL(memory_name_unsupported) { return load_memory(g_off, sizeof g_off - 1, "stl"); }
CALL(memory_name_unsupported_file) { return load_memory(g_off, sizeof g_off - 1, "part.step"); }
CALL(memory_size_huge) { return load_memory(g_off, SIZE_MAX, "off"); }
CALL(memory_empty) { return load_memory(NULL, 0, "ply"); }
CALL(memory_garbage_ply) {
  static const unsigned char bytes[] = {0xde, 0xad, 0xbe, 0xef, 0x00, 0xff, 0x13, 0x37};
  return load_memory(bytes, sizeof bytes, "scan.ply");
}
CALL(memory_nul_in_off) {
  static const char bytes[] = "OFF\n3 1 0\n0 0 0\n1 0\0 0\n0 1 0\n3 0 1 2\n";
  return load_memory(bytes, sizeof bytes - 1, "off");
}
CALL(memory_invalid_utf8_obj) {
  static const char bytes[] = "v 0 0 0\nv 1 0 0\nv 0 \xff\xfe 0\nf 1 2 3\n";
  return load_memory(bytes, sizeof bytes - 1, "obj");
}
CALL(memory_off_prefix_only) { return load_memory(g_off, 12, "off"); }
CALL(memory_xyz_nan) {
  static const char bytes[] = "0 0 0\n1 1 nan\n";
  return load_memory(bytes, sizeof bytes - 1, "points.xyz");
}

/* vstree_mesh_save (errors that do not depend on permissions) */
CALL(save_mesh_null) { return save(NULL, "a.ply", 0); }
CALL(save_path_null) { return vstree_mesh_save(g_mesh, NULL, 0); }
CALL(save_path_empty) { return vstree_mesh_save(g_mesh, "", 0); }
CALL(save_flags_unknown) { return save(g_mesh, "a.ply", 2); }
CALL(save_flags_all) { return save(g_mesh, "a.ply", UINT32_MAX); }
CALL(save_unsupported) { return save(g_mesh, "a.stl", 0); }
CALL(save_missing_directory) { return save(g_mesh, "no/such/dir/a.ply", 0); }

/* Copies out */
CALL(copy_positions_mesh_null) {
  fill_buffers();
  return vstree_mesh_copy_positions(NULL, g_floats, 4096);
}
CALL(copy_positions_out_null) {
  return vstree_mesh_copy_positions(g_mesh, NULL, 3 * g_vertex_count);
}
CALL(copy_positions_null_and_zero) { return vstree_mesh_copy_positions(g_mesh, NULL, 0); }
CALL(copy_positions_one_short) {
  vstree_status s;
  fill_buffers();
  s = vstree_mesh_copy_positions(g_mesh, g_floats, 3 * g_vertex_count - 1);
  buffers_untouched();
  return s;
}
CALL(copy_positions_misaligned) {
  vstree_status s;
  fill_buffers();
  s = vstree_mesh_copy_positions(g_mesh, (float *)misaligned(g_floats), 3 * g_vertex_count);
  buffers_untouched();
  return s;
}
CALL(copy_normals_mesh_null) { return vstree_mesh_copy_normals(NULL, g_floats, 4096); }
CALL(copy_normals_none) {
  vstree_status s;
  fill_buffers();
  s = vstree_mesh_copy_normals(g_cloud_nn, g_floats, 4096);
  buffers_untouched();
  return s;
}
CALL(copy_normals_out_null) { return vstree_mesh_copy_normals(g_mesh, NULL, 3 * g_vertex_count); }
CALL(copy_normals_small) {
  vstree_status s;
  fill_buffers();
  s = vstree_mesh_copy_normals(g_mesh, g_floats, 3);
  buffers_untouched();
  return s;
}
CALL(copy_triangles_mesh_null) { return vstree_mesh_copy_triangles(NULL, g_indices, 4096); }
CALL(copy_triangles_out_null) {
  return vstree_mesh_copy_triangles(g_mesh, NULL, 3 * g_triangle_count);
}
CALL(copy_triangles_one_short) {
  vstree_status s;
  fill_buffers();
  s = vstree_mesh_copy_triangles(g_mesh, g_indices, 3 * g_triangle_count - 1);
  buffers_untouched();
  return s;
}
CALL(copy_triangles_misaligned) {
  vstree_status s;
  fill_buffers();
  s = vstree_mesh_copy_triangles(g_mesh, (uint32_t *)misaligned(g_indices), 3 * g_triangle_count);
  buffers_untouched();
  return s;
}

/* vstree_simplify and its parameters */
CALL(simplify_mesh_null) { return simplify_with(NULL, NULL); }
CALL(simplify_out_null) { return vstree_simplify(g_mesh, NULL, NULL, NULL, NULL); }
CALL(simplify_cloud_without_normals) { return simplify_with(g_cloud_nn, NULL); }
CALL(simplify_only_degenerate) {
  static const float line[9] = {0, 0, 0, 1, 0, 0, 2, 0, 0};
  static const uint32_t tri[3] = {0, 1, 2};
  vstree_mesh *m = NULL;
  vstree_status s;
  if (vstree_mesh_create(line, 3, NULL, tri, 1, &m) != VSTREE_STATUS_OK) {
    problem("cannot make the degenerate mesh");
    return VSTREE_STATUS_OK;
  }
  s = simplify_with(m, NULL);
  vstree_mesh_free(m);
  return s;
}
CALL(simplify_cloud_zero_normal) {
  /* Zero-length normals are accepted by vstree_mesh_create (vstree_estimate_normals fills
   * them in) but cannot be clustered. */
  vstree_mesh *m = NULL;
  vstree_status s;
  reset_small();
  memset(g_quad_normals + 6, 0, 3 * sizeof(float));
  if (vstree_mesh_create(g_quad, 4, g_quad_normals, NULL, 0, &m) != VSTREE_STATUS_OK) {
    problem("cannot make the cloud with a zero normal");
    return VSTREE_STATUS_OK;
  }
  s = simplify_with(m, NULL);
  vstree_mesh_free(m);
  return s;
}
CALL(simplify_params_misaligned) {
  static vstree_simplify_params two[2];
  two[0] = vstree_simplify_params_default();
  two[1] = two[0];
  return simplify_with(g_mesh, (const vstree_simplify_params *)misaligned(&two[0]));
}

#define SIMPLIFY_PARAM(name, field, value)                                                     \
  CALL(name) {                                                                                 \
    vstree_simplify_params p = vstree_simplify_params_default();                               \
    p.field = value;                                                                           \
    return simplify_with(g_mesh, &p);                                                          \
  }
#define TREE_PARAM(name, field, value)                                                         \
  CALL(name) {                                                                                 \
    vstree_simplify_params p = vstree_simplify_params_default();                               \
    p.field = value;                                                                           \
    return tree_with(g_mesh, &p);                                                              \
  }
SIMPLIFY_PARAM(simplify_size_zero, struct_size, 0)
SIMPLIFY_PARAM(simplify_size_short, struct_size, 4)
SIMPLIFY_PARAM(simplify_size_one_more, struct_size, (uint32_t)sizeof(vstree_simplify_params) + 1)
SIMPLIFY_PARAM(simplify_size_huge, struct_size, UINT32_MAX)
SIMPLIFY_PARAM(simplify_tree_kind_99, tree_kind, 99)
SIMPLIFY_PARAM(simplify_tree_kind_neg, tree_kind, -1)
SIMPLIFY_PARAM(simplify_metric_99, metric, 99)
SIMPLIFY_PARAM(simplify_metric_neg, metric, -1)
SIMPLIFY_PARAM(simplify_sampling_99, sampling, 99)
SIMPLIFY_PARAM(simplify_sampling_neg, sampling, -1)
SIMPLIFY_PARAM(simplify_error_zero, error, 0.0)
SIMPLIFY_PARAM(simplify_error_neg, error, -1e-3)
SIMPLIFY_PARAM(simplify_error_nan, error, NAN)
SIMPLIFY_PARAM(simplify_error_inf, error, INFINITY)
SIMPLIFY_PARAM(simplify_error_minus_inf, error, -INFINITY)
SIMPLIFY_PARAM(simplify_d_a_neg, d_a, -0.1f)
SIMPLIFY_PARAM(simplify_d_a_big, d_a, 1.5f)
SIMPLIFY_PARAM(simplify_d_a_nan, d_a, NAN)
SIMPLIFY_PARAM(simplify_d_a_inf, d_a, INFINITY)
SIMPLIFY_PARAM(simplify_d_d_neg, d_d, -0.25f)
SIMPLIFY_PARAM(simplify_d_d_big, d_d, 2.0f)
SIMPLIFY_PARAM(simplify_d_d_nan, d_d, NAN)
SIMPLIFY_PARAM(simplify_max_depth_zero, max_depth, 0)
SIMPLIFY_PARAM(simplify_max_depth_31, max_depth, 31)
SIMPLIFY_PARAM(simplify_max_depth_huge, max_depth, UINT32_MAX)
SIMPLIFY_PARAM(simplify_threads_1025, threads, 1025)
SIMPLIFY_PARAM(simplify_threads_huge, threads, UINT32_MAX)
SIMPLIFY_PARAM(simplify_min_cell_neg, min_cell_size, -1e-9)
SIMPLIFY_PARAM(simplify_min_cell_one, min_cell_size, 1.0)
SIMPLIFY_PARAM(simplify_min_cell_nan, min_cell_size, NAN)
SIMPLIFY_PARAM(simplify_min_cell_inf, min_cell_size, INFINITY)
SIMPLIFY_PARAM(simplify_keep_topology_3, keep_topology, 3)
SIMPLIFY_PARAM(simplify_keep_topology_neg, keep_topology, -1)
SIMPLIFY_PARAM(simplify_target_above_input, target_faces, 577)
SIMPLIFY_PARAM(simplify_target_huge, target_faces, UINT32_MAX)
CALL(simplify_target_on_cloud) {
  vstree_simplify_params p = vstree_simplify_params_default();
  p.target_faces = 10;
  return simplify_with(g_cloud, &p);
}
CALL(simplify_density_half) {
  vstree_simplify_params p = vstree_simplify_params_default();
  p.metric = VSTREE_METRIC_DENSITY;
  p.error = 0.5;
  return simplify_with(g_mesh, &p);
}
CALL(simplify_l21_zero) {
  vstree_simplify_params p = vstree_simplify_params_default();
  p.metric = VSTREE_METRIC_L21;
  p.error = 0.0;
  return simplify_with(g_mesh, &p);
}

/* vstree_tree_build: same checks as vstree_simplify, its own function name */
CALL(tree_mesh_null) { return tree_with(NULL, NULL); }
CALL(tree_out_null) { return vstree_tree_build(g_mesh, NULL, NULL, NULL, NULL); }
CALL(tree_cloud_without_normals) { return tree_with(g_cloud_nn, NULL); }
TREE_PARAM(tree_size_zero, struct_size, 0)
TREE_PARAM(tree_size_long, struct_size, 4096)
TREE_PARAM(tree_tree_kind_99, tree_kind, 99)
TREE_PARAM(tree_metric_neg, metric, -1)
TREE_PARAM(tree_sampling_99, sampling, 99)
TREE_PARAM(tree_error_nan, error, NAN)
TREE_PARAM(tree_d_a_big, d_a, 1.01f)
TREE_PARAM(tree_d_d_neg, d_d, -1.0f)
TREE_PARAM(tree_max_depth_zero, max_depth, 0)
TREE_PARAM(tree_threads_1025, threads, 1025)
TREE_PARAM(tree_min_cell_one, min_cell_size, 1.0)

/* Results and trees */
CALL(take_mesh_result_null) {
  vstree_mesh *m = (vstree_mesh *)SENTINEL;
  vstree_status s = vstree_simplify_result_take_mesh(NULL, &m);
  mesh_out(s, m);
  return s;
}
CALL(take_mesh_out_null) {
  /* The result is left alone when out_mesh is NULL: it is freed here. */
  vstree_simplify_result *r = NULL;
  vstree_status s;
  if (vstree_simplify(g_mesh, NULL, NULL, NULL, &r) != VSTREE_STATUS_OK) {
    problem("cannot simplify the fixture");
    return VSTREE_STATUS_OK;
  }
  s = vstree_simplify_result_take_mesh(r, NULL);
  if (vstree_simplify_result_get_mesh(r) == NULL) problem("the result lost its mesh");
  vstree_simplify_result_free(r);
  return s;
}
CALL(copy_nodes_tree_null) { return vstree_tree_copy_nodes(NULL, NULL, 0); }
CALL(copy_nodes_out_null) {
  return vstree_tree_copy_nodes(g_tree, NULL, vstree_tree_node_count(g_tree));
}
CALL(copy_nodes_one_short) {
  size_t n = vstree_tree_node_count(g_tree);
  vstree_node *nodes = (vstree_node *)calloc(n, sizeof *nodes);
  vstree_status s = vstree_tree_copy_nodes(g_tree, nodes, n - 1);
  if (nodes[0].half != 0.0f || nodes[0].child_count != 0) problem("nodes written on failure");
  free(nodes);
  return s;
}
CALL(copy_nodes_misaligned) {
  size_t n = vstree_tree_node_count(g_tree);
  vstree_node *nodes = (vstree_node *)calloc(n + 1, sizeof *nodes);
  vstree_status s = vstree_tree_copy_nodes(g_tree, (vstree_node *)misaligned(nodes), n);
  free(nodes);
  return s;
}
CALL(copy_t_nodes_tree_null) { return vstree_tree_copy_t_nodes(NULL, NULL, 0); }
CALL(copy_t_nodes_zero) { return vstree_tree_copy_t_nodes(g_tree, NULL, 0); }
CALL(copy_t_nodes_out_null) {
  return vstree_tree_copy_t_nodes(g_tree, NULL, vstree_tree_t_node_count(g_tree));
}
CALL(copy_levels_tree_null) { return vstree_tree_copy_levels(NULL, NULL, 0); }
CALL(copy_levels_one_short) {
  vstree_tree_level levels[64];
  return vstree_tree_copy_levels(g_tree, levels, vstree_tree_level_count(g_tree) - 1);
}
CALL(copy_levels_out_null) {
  return vstree_tree_copy_levels(g_tree, NULL, vstree_tree_level_count(g_tree));
}
CALL(labels_tree_null) {
  return vstree_tree_copy_vertex_labels(NULL, VSTREE_LABEL_KIND_CLUSTER, g_indices, 4096);
}
CALL(labels_kind_2) { return vstree_tree_copy_vertex_labels(g_tree, 2, g_indices, 4096); }
CALL(labels_kind_neg) { return vstree_tree_copy_vertex_labels(g_tree, -1, g_indices, 4096); }
CALL(labels_kind_99) { return vstree_tree_copy_vertex_labels(g_tree, 99, g_indices, 4096); }
CALL(labels_out_null) {
  return vstree_tree_copy_vertex_labels(g_tree, VSTREE_LABEL_KIND_T_NODE, NULL,
                                        vstree_tree_vertex_count(g_tree));
}
CALL(labels_one_short) {
  vstree_status s;
  fill_buffers();
  s = vstree_tree_copy_vertex_labels(g_tree, VSTREE_LABEL_KIND_CLUSTER, g_indices,
                                     vstree_tree_vertex_count(g_tree) - 1);
  buffers_untouched();
  return s;
}

/* vstree_reconstruct and its parameters */
static float g_points[3 * 12];
static void make_points(size_t n, int collinear) {
  size_t k;
  for (k = 0; k < n; k++) {
    g_points[3 * k] = (float)k;
    g_points[3 * k + 1] = collinear ? 2.0f * (float)k : (float)((k * 7) % 5);
    g_points[3 * k + 2] = collinear ? -(float)k : (float)((k * 3) % 4);
  }
}
static vstree_status on_points(size_t n, int collinear, int reconstruct) {
  vstree_mesh *m = NULL;
  vstree_status s;
  make_points(n, collinear);
  if (vstree_mesh_create(g_points, n, NULL, NULL, 0, &m) != VSTREE_STATUS_OK) {
    problem("cannot make the point fixture");
    return VSTREE_STATUS_OK;
  }
  if (reconstruct) {
    vstree_reconstruct_params p = quick_reconstruct();
    s = reconstruct_with(m, &p);
  } else {
    s = normals_with(m, NULL, NULL);
  }
  vstree_mesh_free(m);
  return s;
}
CALL(reconstruct_cloud_null) { return reconstruct_with(NULL, NULL); }
CALL(reconstruct_out_null) { return vstree_reconstruct(g_cloud, NULL, NULL, NULL, NULL); }
CALL(reconstruct_nine_points) { return on_points(9, 0, 1); }
CALL(reconstruct_collinear) { return on_points(12, 1, 1); }
CALL(reconstruct_take_mesh_null) {
  vstree_mesh *m = (vstree_mesh *)SENTINEL;
  vstree_status s = vstree_reconstruct_result_take_mesh(NULL, &m);
  mesh_out(s, m);
  return s;
}

#define RECONSTRUCT_PARAM(name, field, value)                                                  \
  CALL(name) {                                                                                 \
    vstree_reconstruct_params p = quick_reconstruct();                                         \
    p.field = value;                                                                           \
    return reconstruct_with(g_cloud, &p);                                                      \
  }
RECONSTRUCT_PARAM(reconstruct_size_zero, struct_size, 0)
RECONSTRUCT_PARAM(reconstruct_size_short, struct_size, 8)
RECONSTRUCT_PARAM(reconstruct_size_long, struct_size, 4096)
RECONSTRUCT_PARAM(reconstruct_orient_99, orient, 99)
RECONSTRUCT_PARAM(reconstruct_orient_neg, orient, -1)
RECONSTRUCT_PARAM(reconstruct_error_zero, error, 0.0)
RECONSTRUCT_PARAM(reconstruct_error_neg, error, -1.0)
RECONSTRUCT_PARAM(reconstruct_error_nan, error, NAN)
RECONSTRUCT_PARAM(reconstruct_error_inf, error, INFINITY)
RECONSTRUCT_PARAM(reconstruct_d_a_neg, d_a, -0.5f)
RECONSTRUCT_PARAM(reconstruct_d_a_nan, d_a, NAN)
RECONSTRUCT_PARAM(reconstruct_d_d_big, d_d, 1.5f)
RECONSTRUCT_PARAM(reconstruct_d_d_inf, d_d, INFINITY)
RECONSTRUCT_PARAM(reconstruct_d_a_one, d_a, 1.0f)
RECONSTRUCT_PARAM(reconstruct_d_d_zero, d_d, 0.0f)
RECONSTRUCT_PARAM(reconstruct_max_depth_zero, max_depth, 0)
RECONSTRUCT_PARAM(reconstruct_max_depth_31, max_depth, 31)
RECONSTRUCT_PARAM(reconstruct_max_levels_13, max_levels, 13)
RECONSTRUCT_PARAM(reconstruct_max_levels_huge, max_levels, UINT32_MAX)
RECONSTRUCT_PARAM(reconstruct_min_cell_neg, min_cell_size, -1e-7)
RECONSTRUCT_PARAM(reconstruct_min_cell_one, min_cell_size, 1.0)
RECONSTRUCT_PARAM(reconstruct_min_cell_nan, min_cell_size, NAN)
RECONSTRUCT_PARAM(reconstruct_target_neg, target_distance, -1e-3)
RECONSTRUCT_PARAM(reconstruct_target_nan, target_distance, NAN)
RECONSTRUCT_PARAM(reconstruct_target_inf, target_distance, INFINITY)
RECONSTRUCT_PARAM(reconstruct_displaced_neg, min_displaced, -0.1)
RECONSTRUCT_PARAM(reconstruct_displaced_big, min_displaced, 1.5)
RECONSTRUCT_PARAM(reconstruct_displaced_nan, min_displaced, NAN)
RECONSTRUCT_PARAM(reconstruct_max_triangles_zero, max_triangles, 0)
RECONSTRUCT_PARAM(reconstruct_grid_3, max_grid_depth, 3)
RECONSTRUCT_PARAM(reconstruct_grid_21, max_grid_depth, 21)
RECONSTRUCT_PARAM(reconstruct_grid_zero, max_grid_depth, 0)
RECONSTRUCT_PARAM(reconstruct_trim_neg, trim, -1.0f)
RECONSTRUCT_PARAM(reconstruct_trim_nan, trim, NAN)
RECONSTRUCT_PARAM(reconstruct_trim_inf, trim, INFINITY)
RECONSTRUCT_PARAM(reconstruct_neighbours_2, neighbours, 2)
RECONSTRUCT_PARAM(reconstruct_neighbours_257, neighbours, 257)
RECONSTRUCT_PARAM(reconstruct_reorient_2, reorient_given, 2)
RECONSTRUCT_PARAM(reconstruct_threads_1025, threads, 1025)
RECONSTRUCT_PARAM(reconstruct_base_mesh_3, base_mesh, 3)

/* vstree_estimate_normals and its parameters */
CALL(normals_mesh_null) { return normals_with(NULL, NULL, NULL); }
CALL(normals_out_null) { return vstree_estimate_normals(g_cloud_nn, NULL, NULL, NULL, NULL, NULL); }
CALL(normals_two_points) { return on_points(2, 0, 0); }
CALL(normals_collinear) { return on_points(12, 1, 0); }
CALL(normals_report_size_zero) {
  vstree_normals_report report;
  vstree_status s;
  memset(&report, 0x5a, sizeof report);
  report.struct_size = 0;
  s = normals_with(g_cloud_nn, NULL, &report);
  if (report.struct_size != 0 || report.estimated != 0x5a5a5a5a5a5a5a5aULL) {
    problem("the report was written by a failing call");
  }
  return s;
}
CALL(normals_report_size_short) {
  vstree_normals_report report;
  vstree_status s;
  memset(&report, 0x5a, sizeof report);
  report.struct_size = 12;
  s = normals_with(g_cloud_nn, NULL, &report);
  if (report.struct_size != 12 || report.estimated != 0x5a5a5a5a5a5a5a5aULL) {
    problem("the report was written by a failing call");
  }
  return s;
}
CALL(normals_report_size_long) {
  /* A caller's report larger than the library's is fine: the library fills what it knows
   * and says how much. */
  vstree_normals_report report[2];
  vstree_status s;
  memset(report, 0x5a, sizeof report);
  report[0].struct_size = (uint32_t)(2 * sizeof report[0]);
  s = normals_with(g_cloud_nn, NULL, &report[0]);
  if (s == VSTREE_STATUS_OK && report[0].struct_size != sizeof report[0]) {
    problem("struct_size of the report is not the bytes the library filled");
  }
  if (((const unsigned char *)&report[1])[0] != 0x5a) {
    problem("the report was written past the size the library knows");
  }
  return s;
}

#define NORMAL_PARAM(name, field, value)                                                       \
  CALL(name) {                                                                                 \
    vstree_normal_params p = vstree_normal_params_default();                                   \
    p.field = value;                                                                           \
    return normals_with(g_cloud_nn, &p, NULL);                                                 \
  }
NORMAL_PARAM(normals_size_zero, struct_size, 0)
NORMAL_PARAM(normals_size_short, struct_size, 19)
NORMAL_PARAM(normals_size_long, struct_size, 4096)
NORMAL_PARAM(normals_orient_99, orient, 99)
NORMAL_PARAM(normals_orient_neg, orient, -1)
NORMAL_PARAM(normals_neighbours_zero, neighbours, 0)
NORMAL_PARAM(normals_neighbours_2, neighbours, 2)
NORMAL_PARAM(normals_neighbours_257, neighbours, 257)
NORMAL_PARAM(normals_neighbours_huge, neighbours, UINT32_MAX)
NORMAL_PARAM(normals_reorient_2, reorient_given, 2)
NORMAL_PARAM(normals_threads_1025, threads, 1025)
NORMAL_PARAM(normals_threads_huge, threads, UINT32_MAX)

/* vstree_last_error_copy: returns the whole length; a result >= capacity means the copy was
 * cut. These rows report VSTREE_STATUS_BUFFER_TOO_SMALL when it was cut and OK when the
 * message fitted, and the message column is the last error, which copying must not change. */
static vstree_status copy_error(size_t capacity, const char *expected_copy) {
  char buffer[256];
  size_t full = strlen(vstree_last_error_message()), got;
  memset(buffer, 'x', sizeof buffer);
  got = vstree_last_error_copy(capacity ? buffer : NULL, capacity);
  if (got != full) problem("vstree_last_error_copy did not return the whole length");
  if (expected_copy == NULL) {
    if (buffer[0] != 'x') problem("a NULL/0 copy wrote into the buffer");
  } else if (strcmp(buffer, expected_copy) != 0) {
    char detail[400];
    snprintf(detail, sizeof detail, "copied \"%.300s\"", buffer);
    problem(detail);
  } else if (buffer[strlen(expected_copy) + 1] != 'x') {
    problem("vstree_last_error_copy wrote past the NUL");
  }
  return got >= capacity ? VSTREE_STATUS_BUFFER_TOO_SMALL : VSTREE_STATUS_OK;
}
/* The message is "vstree_mesh_load: `out_mesh` is NULL" (36 bytes). */
static void fail_load(void) { (void)vstree_mesh_load("x.ply", NULL); }
CALL(error_copy_null_buffer) { fail_load(); return copy_error(0, NULL); }
CALL(error_copy_capacity_1) { fail_load(); return copy_error(1, ""); }
CALL(error_copy_capacity_8) { fail_load(); return copy_error(8, "vstree_"); }
CALL(error_copy_one_short) {
  fail_load();
  return copy_error(36, "vstree_mesh_load: `out_mesh` is NUL");
}
CALL(error_copy_exact) {
  fail_load();
  return copy_error(37, "vstree_mesh_load: `out_mesh` is NULL");
}
CALL(error_copy_utf8_boundary) {
  /* "é" is two bytes; a cut inside it must drop the whole character. */
  char path[4096];
  vstree_mesh *m = (vstree_mesh *)SENTINEL;
  size_t prefix;
  char expected[4096];
  snprintf(path, sizeof path, "%s/\xc3\xa9.ply", g_dir);
  mesh_out(vstree_mesh_load(path, &m), m);
  prefix = (size_t)(strstr(vstree_last_error_message(), "\xc3\xa9") - vstree_last_error_message());
  memcpy(expected, vstree_last_error_message(), prefix);
  expected[prefix] = '\0';
  return copy_error(prefix + 2, expected); /* room for the prefix and one byte of "é" */
}
CALL(error_copy_after_success) {
  vstree_status s = vstree_mesh_copy_triangles(g_cloud, NULL, 0); /* succeeds: message "" */
  if (s != VSTREE_STATUS_OK) problem("the successful call failed");
  return copy_error(1, "");
}

/* Progress callbacks that cancel */
typedef struct stopper {
  int calls;
  int stop_at;
  const char *stop_stage; /* if set, stop at the first report of this stage */
} stopper;

static int32_t stop_cb(void *user_data, float fraction, const char *stage) {
  stopper *s = (stopper *)user_data;
  int stop = s->stop_stage ? strcmp(stage, s->stop_stage) == 0 : s->calls == s->stop_at;
  (void)fraction;
  s->calls++;
  return stop ? 0 : 1;
}

static vstree_status simplify_cancel(int stop_at, const char *stage) {
  stopper st = {0, 0, NULL};
  vstree_simplify_result *r = (vstree_simplify_result *)SENTINEL;
  vstree_status s;
  st.stop_at = stop_at;
  st.stop_stage = stage;
  s = vstree_simplify(g_mesh, NULL, stop_cb, &st, &r);
  simplify_out(s, r);
  return s;
}
CALL(cancel_simplify_first) { return simplify_cancel(0, NULL); }
CALL(cancel_simplify_done) { return simplify_cancel(-1, "done"); }
CALL(cancel_simplify_cluster) { return simplify_cancel(-1, "clustering"); }
CALL(cancel_tree_first) {
  stopper st = {0, 0, NULL};
  vstree_tree *t = (vstree_tree *)SENTINEL;
  vstree_status s = vstree_tree_build(g_mesh, NULL, stop_cb, &st, &t);
  tree_out(s, t);
  return s;
}
CALL(cancel_reconstruct_first) {
  stopper st = {0, 0, NULL};
  vstree_reconstruct_params p = quick_reconstruct();
  vstree_reconstruct_result *r = (vstree_reconstruct_result *)SENTINEL;
  vstree_status s = vstree_reconstruct(g_cloud, &p, stop_cb, &st, &r);
  reconstruct_out(s, r);
  return s;
}
CALL(cancel_normals_first) {
  stopper st = {0, 0, NULL};
  vstree_mesh *m = (vstree_mesh *)SENTINEL;
  vstree_status s = vstree_estimate_normals(g_cloud_nn, NULL, stop_cb, &st, &m, NULL);
  mesh_out(s, m);
  return s;
}
CALL(cancel_normals_done) {
  stopper st = {0, -1, "normals: done"};
  vstree_mesh *m = (vstree_mesh *)SENTINEL;
  vstree_status s = vstree_estimate_normals(g_cloud_nn, NULL, stop_cb, &st, &m, NULL);
  mesh_out(s, m);
  return s;
}

/* ---- the table ---- */

typedef struct bad_case {
  const char *name;
  vstree_status (*call)(void);
  vstree_status status;
  const char *message; /* exact; "{dir}" = TEMP_DIR, '*' = any run of characters */
} bad_case;


/* ---- results that would be empty or wrong, files that are not regular, outputs that must not
 * be replaced ---- */
/* Plain clustering: with the topology kept (the default for this closed torus) the smallest
 * closed torus is the result instead. */
CALL(simplify_error_whole_model) {
  vstree_simplify_params p = vstree_simplify_params_default();
  p.error = 100.0;
  p.keep_topology = VSTREE_KEEP_TOPOLOGY_OFF;
  return simplify_with(g_mesh, &p);
}
CALL(simplify_l21_above_4) {
  vstree_simplify_params p = vstree_simplify_params_default();
  p.metric = VSTREE_METRIC_L21;
  p.error = 5.0;
  return simplify_with(g_mesh, &p);
}
RECONSTRUCT_PARAM(reconstruct_max_depth_1, max_depth, 1)
RECONSTRUCT_PARAM(reconstruct_error_1e300, error, 1e300)
CALL(reconstruct_flat_cloud) {
  static float flat[3 * 40], up[3 * 40];
  vstree_mesh *m = NULL;
  vstree_status s;
  vstree_reconstruct_params p = quick_reconstruct();
  size_t k;
  for (k = 0; k < 40; k++) {
    flat[3 * k] = (float)(k % 7);
    flat[3 * k + 1] = (float)(k / 7);
    flat[3 * k + 2] = 0.0f;
    up[3 * k] = 0.0f;
    up[3 * k + 1] = 0.0f;
    up[3 * k + 2] = 1.0f;
  }
  if (vstree_mesh_create(flat, 40, up, NULL, 0, &m) != VSTREE_STATUS_OK) {
    problem("cannot make the flat fixture");
    return VSTREE_STATUS_OK;
  }
  s = reconstruct_with(m, &p);
  vstree_mesh_free(m);
  return s;
}
#ifndef _WIN32
/* Makes TEMP_DIR/name a FIFO (or a link to `target`), once. */
static void special(const char *name, const char *target) {
  char path[4096];
  snprintf(path, sizeof path, "%s/%s", g_dir, name);
  if ((target ? symlink(target, path) : mkfifo(path, 0600)) != 0 && errno != EEXIST) {
    problem("cannot make the special file");
  }
}
CALL(load_fifo) {
  special("pipe.ply", NULL);
  return load("pipe.ply");
}
CALL(load_char_device) {
  special("zero.ply", "/dev/zero");
  return load("zero.ply");
}
#endif
CALL(load_zeros) {
  static const char zeros[4096];
  write_file("zeros.xyz", zeros, sizeof zeros);
  return load("zeros.xyz");
}
CALL(load_with_bom) { return load_text("bom.off", "\xEF\xBB\xBFOFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"); }
CALL(load_no_vertices) { return load_text("none.off", "OFF\n0 0 0\n"); }
CALL(load_obj_two_corner_face) { return load_text("line.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n"); }
#ifndef _WIN32
CALL(save_to_fifo) {
  special("out-pipe.ply", NULL);
  return save(g_mesh, "out-pipe.ply", 0);
}
CALL(save_to_char_device) {
  special("null.ply", "/dev/null");
  return save(g_mesh, "null.ply", 0);
}
CALL(save_through_dangling_link) {
  special("dangling.ply", "no-such-dir/target.ply");
  return save(g_mesh, "dangling.ply", 0);
}
#endif
CALL(save_into_missing_folder) { return save(g_mesh, "no-such-dir/out.ply", 0); }
CALL(save_over_directory) { return save(g_mesh, "sub.ply", 0); }

/* Metric defaults, sizes that ignore the bound, and results that keep nothing of the shape */
CALL(simplify_density_default_bound) {
  vstree_simplify_params p = vstree_simplify_params_default();
  p.metric = VSTREE_METRIC_DENSITY;
  return simplify_with(g_mesh, &p);
}
CALL(simplify_density_size_ignores_bound) {
  vstree_simplify_params p = vstree_simplify_params_default();
  p.metric = VSTREE_METRIC_DENSITY;
  p.error = 0.5;
  p.target_faces = 300;
  return simplify_with(g_mesh, &p);
}
CALL(simplify_size_ignores_nan_bound) {
  vstree_simplify_params p = vstree_simplify_params_default();
  p.error = NAN;
  p.target_faces = 300;
  return simplify_with(g_mesh, &p);
}
CALL(simplify_min_cell_collapses_all) {
  vstree_simplify_params p = vstree_simplify_params_default();
  p.min_cell_size = 0.99;
  p.keep_topology = VSTREE_KEEP_TOPOLOGY_OFF;
  return simplify_with(g_mesh, &p);
}
static vstree_status three_points(double error, int32_t metric) {
  static const float p[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  static const float n[9] = {0, 0, 1, 0, 0, 1, 0, 0, 1};
  vstree_simplify_params params = vstree_simplify_params_default();
  vstree_mesh *cloud = NULL;
  vstree_status s = vstree_mesh_create(p, 3, n, NULL, 0, &cloud);
  if (s != VSTREE_STATUS_OK) return s;
  params.metric = metric;
  params.error = error;
  s = simplify_with(cloud, &params);
  vstree_mesh_free(cloud);
  return s;
}
CALL(simplify_three_points) { return three_points(1e-3, VSTREE_METRIC_L2); }
CALL(simplify_three_points_density_1) { return three_points(1.0, VSTREE_METRIC_DENSITY); }
/* A PLY is read up to the end of the elements its header declares: a body of another kind is
 * refused at its first byte, which the message names (no raw control byte), and a tail after
 * the elements is ignored. */
static const char g_ascii_header[] =
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
    "property float z\nend_header\n";
static char g_nul_body[sizeof g_ascii_header - 1 + 4096];
static size_t nul_body(void) {
  memset(g_nul_body, 0, sizeof g_nul_body);
  memcpy(g_nul_body, g_ascii_header, sizeof g_ascii_header - 1);
  return sizeof g_nul_body;
}
/* Not nul.ply: NUL is a device name on Windows, where these tests run under Wine too. */
CALL(load_ply_ascii_nul_body) {
  write_file("zeros.ply", g_nul_body, nul_body());
  return load("zeros.ply");
}
CALL(memory_ply_ascii_nul_body) { return load_memory(g_nul_body, nul_body(), "ply"); }
CALL(load_ply_binary_with_tail) {
  static const char zeros[4096];
  char path[4096];
  FILE *f;
  if (save(g_mesh, "tail.ply", 0) != VSTREE_STATUS_OK) problem("cannot save tail.ply");
  snprintf(path, sizeof path, "%s/tail.ply", g_dir);
  f = fopen(path, "ab");
  if (!f || fwrite(zeros, 1, sizeof zeros, f) != sizeof zeros || fclose(f) != 0) {
    problem("cannot append to tail.ply");
  }
  return load("tail.ply");
}
/* Vertex colours are not used: colours on some vertices only are no error. */
CALL(load_obj_colours_on_some_vertices) {
  return load_text("colours.obj", "v 0 0 0 1 0 0\nv 1 0 0\nv 0 1 0 0 0 1\nv 0 0 1\nf 1 3 2\n"
                                  "f 1 2 4\nf 1 4 3\nf 2 3 4\n");
}

#define ROW(call, status, message) {#call, call, VSTREE_STATUS_##status, message}

static const bad_case g_cases[] = {
    ROW(simplify_error_whole_model, INVALID_PARAMETER, "vstree_simplify: parameter `error`: 100: every triangle collapsed (1 cluster "
        "for the whole model): the model is within this bound of too few planes; use a "
        "smaller bound (a flat model, within any bound of one plane, needs the density "
        "metric)"),
    ROW(simplify_l21_above_4, INVALID_PARAMETER,
        "vstree_simplify: parameter `error`: 5: the L2,1 bound must be in (0, 4]"),
    ROW(reconstruct_max_depth_1, INVALID_PARAMETER, "vstree_reconstruct: parameter `max_depth`: 1: the tree reached this depth "
        "before any cell saw the surface as a height field, so there is nothing to make "
        "the base mesh from; allow a deeper tree (default 24)"),
    ROW(reconstruct_error_1e300, INVALID_PARAMETER, "vstree_reconstruct: parameter `error`: 1e300: the cloud fits this bound in 1 "
        "octree cell too coarse to see the surface as a height field, so there is "
        "nothing to make the base mesh from; use a smaller bound (default 1e-5)"),
    ROW(reconstruct_flat_cloud, INVALID_INPUT, "vstree_reconstruct: invalid input: all 40 points lie in one plane (thickness 0 "
        "of the cloud's extent): they enclose no volume, so there is no closed surface "
        "to reconstruct"),
#ifndef _WIN32
    ROW(load_fifo, IO, "vstree_mesh_load: {dir}/pipe.ply: a FIFO (named pipe), not a regular file: "
        "vstree reads meshes from regular files only"),
    ROW(load_char_device, IO, "vstree_mesh_load: {dir}/zero.ply: a character device, not a regular file: "
        "vstree reads meshes from regular files only"),
#endif
    ROW(load_zeros, PARSE, "vstree_mesh_load: {dir}/zeros.xyz: line 1: a NUL byte: this is binary data, not "
        "a text file"),
    ROW(load_with_bom, OK, ""),
    ROW(load_no_vertices, INVALID_INPUT, "vstree_mesh_load: invalid input: {dir}/none.off: no vertices: the file holds "
        "neither a mesh nor points"),
    ROW(load_obj_two_corner_face, PARSE, "vstree_mesh_load: {dir}/line.obj: line 4: a face with 2 corners: a face needs "
        "at least 3 (a line is written with `l`)"),
#ifndef _WIN32
    ROW(save_to_fifo, IO, "vstree_mesh_save: {dir}/out-pipe.ply: a FIFO (named pipe), not a regular file: "
        "vstree replaces regular files only"),
    ROW(save_to_char_device, IO, "vstree_mesh_save: {dir}/null.ply: a character device, not a regular file: "
        "vstree replaces regular files only"),
    ROW(save_through_dangling_link, IO, "vstree_mesh_save: {dir}/dangling.ply: a symbolic link to a missing file: not "
        "writing through a dangling link"),
#endif
    ROW(save_into_missing_folder, IO, "vstree_mesh_save: {dir}/no-such-dir/out.ply: No such file or directory (os "
        "error 2)"),
    ROW(save_over_directory, IO, "vstree_mesh_save: {dir}/sub.ply: a directory, not a regular file: vstree "
        "replaces regular files only"),
    ROW(create_out_null, NULL_POINTER, "vstree_mesh_create: `out_mesh` is NULL"),
    ROW(create_positions_null, NULL_POINTER, "vstree_mesh_create: `positions` is NULL"),
    ROW(create_triangles_null, NULL_POINTER, "vstree_mesh_create: `triangles` is NULL"),
    ROW(create_zero_vertices, INVALID_INPUT,
        "vstree_mesh_create: `vertex_count` is 0: a mesh needs at least one vertex"),
    ROW(create_zero_vertices_all_null, INVALID_INPUT,
        "vstree_mesh_create: `vertex_count` is 0: a mesh needs at least one vertex"),
    ROW(create_zero_vertices_with_triangles, INVALID_INPUT,
        "vstree_mesh_create: `vertex_count` is 0: a mesh needs at least one vertex"),
    ROW(create_vertices_above_u32, TOO_LARGE,
        "vstree_mesh_create: `vertex_count` is 4294967296, more than the limit of 4294967295"),
    ROW(create_vertices_size_max, TOO_LARGE,
        "vstree_mesh_create: `vertex_count` is 18446744073709551615, more than the limit of "
        "4294967295"),
    ROW(create_vertices_times_3_overflows, TOO_LARGE,
        "vstree_mesh_create: `vertex_count` is 6148914691236517206, more than the limit of "
        "4294967295"),
    ROW(create_triangles_above_u32, TOO_LARGE,
        "vstree_mesh_create: `triangle_count` is 4294967296, more than the limit of 4294967295"),
    ROW(create_triangles_size_max, TOO_LARGE,
        "vstree_mesh_create: `triangle_count` is 18446744073709551615, more than the limit of "
        "4294967295"),
    ROW(create_positions_misaligned, INVALID_ARGUMENT,
        "vstree_mesh_create: `positions`: 0x* is not aligned to 4 bytes as its element type "
        "requires"),
    ROW(create_normals_misaligned, INVALID_ARGUMENT,
        "vstree_mesh_create: `normals`: 0x* is not aligned to 4 bytes as its element type "
        "requires"),
    ROW(create_triangles_misaligned, INVALID_ARGUMENT,
        "vstree_mesh_create: `triangles`: 0x* is not aligned to 4 bytes as its element type "
        "requires"),
    ROW(create_position_nan, INVALID_INPUT,
        "vstree_mesh_create: invalid input: vertex 1 has a NaN or infinite coordinate"),
    ROW(create_position_inf, INVALID_INPUT,
        "vstree_mesh_create: invalid input: vertex 1 has a NaN or infinite coordinate"),
    ROW(create_position_minus_inf, INVALID_INPUT,
        "vstree_mesh_create: invalid input: vertex 3 has a NaN or infinite coordinate"),
    ROW(create_position_above_1e18, INVALID_INPUT,
        "vstree_mesh_create: invalid input: vertex 2 has a coordinate of 2e18: at most 1e18 in "
        "magnitude is supported (32-bit geometry); rescale the input"),
    ROW(create_position_below_minus_1e18, INVALID_INPUT,
        "vstree_mesh_create: invalid input: vertex 3 has a coordinate of 1e19: at most 1e18 in "
        "magnitude is supported (32-bit geometry); rescale the input"),
    ROW(create_position_float_max, INVALID_INPUT,
        "vstree_mesh_create: invalid input: vertex 0 has a coordinate of 3.4e38: at most 1e18 in "
        "magnitude is supported (32-bit geometry); rescale the input"),
    ROW(create_normal_nan, INVALID_INPUT,
        "vstree_mesh_create: invalid input: normal 3 has a NaN or infinite component"),
    ROW(create_normal_inf, INVALID_INPUT,
        "vstree_mesh_create: invalid input: normal 1 has a NaN or infinite component"),
    ROW(create_index_equal_count, INVALID_INPUT,
        "vstree_mesh_create: invalid input: triangle 0 uses vertex 4, but there are only 4 "
        "vertices"),
    ROW(create_index_u32_max, INVALID_INPUT,
        "vstree_mesh_create: invalid input: triangle 0 uses vertex 4294967295, but there are "
        "only 4 vertices"),
    ROW(create_index_in_second_triangle, INVALID_INPUT,
        "vstree_mesh_create: invalid input: triangle 1 uses vertex 1000, but there are only 4 "
        "vertices"),
    ROW(create_f64_out_null, NULL_POINTER, "vstree_mesh_create_f64: `out_mesh` is NULL"),
    ROW(create_f64_positions_null, NULL_POINTER, "vstree_mesh_create_f64: `positions` is NULL"),
    ROW(create_f64_triangles_null, NULL_POINTER, "vstree_mesh_create_f64: `triangles` is NULL"),
    ROW(create_f64_zero_vertices, INVALID_INPUT,
        "vstree_mesh_create_f64: `vertex_count` is 0: a mesh needs at least one vertex"),
    ROW(create_f64_vertices_above_u32, TOO_LARGE,
        "vstree_mesh_create_f64: `vertex_count` is 4294967296, more than the limit of "
        "4294967295"),
    ROW(create_f64_vertices_times_3_overflows, TOO_LARGE,
        "vstree_mesh_create_f64: `vertex_count` is 6148914691236517206, more than the limit of "
        "4294967295"),
    ROW(create_f64_triangles_size_max, TOO_LARGE,
        "vstree_mesh_create_f64: `triangle_count` is 18446744073709551615, more than the limit "
        "of 4294967295"),
    ROW(create_f64_positions_aligned_to_4_only, INVALID_ARGUMENT,
        "vstree_mesh_create_f64: `positions`: 0x* is not aligned to 8 bytes as its element type "
        "requires"),
    ROW(create_f64_normals_misaligned, INVALID_ARGUMENT,
        "vstree_mesh_create_f64: `normals`: 0x* is not aligned to 4 bytes as its element type "
        "requires"),
    ROW(create_f64_position_nan, INVALID_INPUT,
        "vstree_mesh_create_f64: invalid input: vertex 1 has a NaN or infinite coordinate (1, "
        "NaN, 0)"),
    ROW(create_f64_position_minus_inf, INVALID_INPUT,
        "vstree_mesh_create_f64: invalid input: vertex 3 has a NaN or infinite coordinate (-inf, "
        "0, 1)"),
    ROW(create_f64_position_above_1e18, INVALID_INPUT,
        "vstree_mesh_create_f64: invalid input: vertex 2 has a coordinate of 2e18: at most 1e18 "
        "in magnitude is supported (32-bit geometry); rescale the input"),
    ROW(create_f64_position_below_minus_1e18, INVALID_INPUT,
        "vstree_mesh_create_f64: invalid input: vertex 3 has a coordinate of 1e19: at most 1e18 "
        "in magnitude is supported (32-bit geometry); rescale the input"),
    ROW(create_f64_position_beyond_float, INVALID_INPUT,
        "vstree_mesh_create_f64: invalid input: vertex 0 has a coordinate of 1e300: at most "
        "1e18 in magnitude is supported (32-bit geometry); rescale the input"),
    ROW(create_f64_normal_nan, INVALID_INPUT,
        "vstree_mesh_create_f64: invalid input: normal 3 has a NaN or infinite component"),
    ROW(create_f64_index_equal_count, INVALID_INPUT,
        "vstree_mesh_create_f64: invalid input: triangle 0 uses vertex 4, but there are only 4 "
        "vertices"),

    ROW(load_out_null, NULL_POINTER, "vstree_mesh_load: `out_mesh` is NULL"),
    ROW(load_path_null, NULL_POINTER, "vstree_mesh_load: `path` is NULL"),
    ROW(load_path_empty, INVALID_ARGUMENT, "vstree_mesh_load: `path`: the path is empty"),
    ROW(load_missing, IO,
        "vstree_mesh_load: {dir}/missing.ply: No such file or directory (os error 2)"),
    ROW(load_directory, IO, "vstree_mesh_load: {dir}/sub.ply: a directory, not a regular file: vstree reads meshes from "
        "regular files only"),
    ROW(load_unsupported_extension, UNSUPPORTED_FORMAT,
        "vstree_mesh_load: {dir}/mesh.stl: unsupported file format (expected .ply, .obj, .off, "
        ".xyz or .pwn)"),
    ROW(load_no_extension, UNSUPPORTED_FORMAT,
        "vstree_mesh_load: {dir}/mesh: unsupported file format (expected .ply, .obj, .off, .xyz "
        "or .pwn)"),
    ROW(load_ply_empty, PARSE, "vstree_mesh_load: {dir}/empty.ply: line 1: file is empty"),
    ROW(load_ply_not_ply, PARSE,
        "vstree_mesh_load: {dir}/magic.ply: line 1: not a PLY file: it must start with a `ply` "
        "line"),
    ROW(load_ply_bad_format, PARSE,
        "vstree_mesh_load: {dir}/format.ply: line 2: unsupported PLY version `2.0`"),
    ROW(load_ply_no_end_header, PARSE,
        "vstree_mesh_load: {dir}/noend.ply: header: file ends before `end_header`"),
    ROW(load_ply_truncated, PARSE,
        "vstree_mesh_load: {dir}/truncated.ply: line 9: file ends after 2 of the 3 `vertex` "
        "elements"),
    ROW(load_ply_bad_number, PARSE,
        "vstree_mesh_load: {dir}/number.ply: line 9: vertex 1: expected a number, found `zero`"),
    ROW(load_ply_face_out_of_range, PARSE,
        "vstree_mesh_load: {dir}/range.ply: line 13: face 0: uses vertex 3, but there are only 3 "
        "vertices"),
    ROW(load_ply_no_xyz, PARSE,
        "vstree_mesh_load: {dir}/noxyz.ply: line 3: the vertex element has no scalar `z` property"),
    ROW(load_ply_binary_truncated, PARSE,
        "vstree_mesh_load: {dir}/binary.ply: vertex 1: file ends after 1 of the 2 `vertex` "
        "elements"),
    ROW(load_off_bad_header, PARSE,
        "vstree_mesh_load: {dir}/header.off: line 1: expected OFF, NOFF or COFF, found `OFX`"),
    ROW(load_off_bad_counts, PARSE,
        "vstree_mesh_load: {dir}/counts.off: line 2: expected a number, found `x`"),
    ROW(load_off_truncated, PARSE,
        "vstree_mesh_load: {dir}/short.off: line 4: file ends after 2 of the 3 vertices"),
    ROW(load_off_out_of_range, PARSE,
        "vstree_mesh_load: {dir}/range.off: line 6: face 0: uses vertex 7, but there are only 3 "
        "vertices"),
    ROW(load_off_nan, PARSE,
        "vstree_mesh_load: {dir}/nan.off: line 4: vertex 1: has a NaN or infinite coordinate "
        "(NaN, 0, 0)"),
    ROW(load_off_huge_coordinate, PARSE,
        "vstree_mesh_load: {dir}/huge.off: line 4: vertex 1: has a coordinate of 1e19: at most "
        "1e18 in magnitude is supported (32-bit geometry); rescale the input"),
    ROW(load_obj_short_vertex, PARSE,
        "vstree_mesh_load: {dir}/short.obj: line 2: expected 3 numbers, found 2"),
    ROW(load_obj_bad_number, PARSE,
        "vstree_mesh_load: {dir}/number.obj: line 3: expected a number, found `x`"),
    ROW(load_obj_face_out_of_range, PARSE,
        "vstree_mesh_load: {dir}/range.obj: line 4: vertex index 9 is out of range: the file has "
        "3 `v` lines"),
    ROW(load_obj_face_zero_index, PARSE,
        "vstree_mesh_load: {dir}/zero.obj: line 4: vertex index 0 is invalid: indices start at 1"),
    ROW(load_obj_faces_without_vertices, PARSE,
        "vstree_mesh_load: {dir}/faces.obj: line 2: vertex index 1 is out of range: the file has "
        "0 `v` lines"),
    ROW(load_xyz_two_numbers, PARSE,
        "vstree_mesh_load: {dir}/two.xyz: line 3: expected 3 numbers like line 1, found 2"),
    ROW(load_xyz_bad_number, PARSE,
        "vstree_mesh_load: {dir}/number.xyz: line 3: expected a number, found `two`"),
    ROW(load_xyz_inf, PARSE,
        "vstree_mesh_load: {dir}/inf.xyz: line 2: point 1: has a NaN or infinite coordinate "
        "(inf, 0, 0)"),
    ROW(load_pwn_bad_count, PARSE,
        "vstree_mesh_load: {dir}/count.pwn: line 1: expected a number, found `many`"),

    ROW(memory_out_null, NULL_POINTER, "vstree_mesh_load_memory: `out_mesh` is NULL"),
    ROW(memory_data_null, NULL_POINTER, "vstree_mesh_load_memory: `data` is NULL"),
    ROW(memory_name_null, NULL_POINTER, "vstree_mesh_load_memory: `name` is NULL"),
    ROW(memory_name_empty, INVALID_ARGUMENT, "vstree_mesh_load_memory: `name`: the path is empty"),
    ROW(memory_name_unsupported, UNSUPPORTED_FORMAT,
        "vstree_mesh_load_memory: memory.stl: unsupported file format (expected .ply, .obj, "
        ".off, .xyz or .pwn)"),
    ROW(memory_name_unsupported_file, UNSUPPORTED_FORMAT,
        "vstree_mesh_load_memory: part.step: unsupported file format (expected .ply, "
        ".obj, .off, .xyz or .pwn)"),
    ROW(memory_size_huge, TOO_LARGE,
        "vstree_mesh_load_memory: `size` is 18446744073709551615, more than any buffer can hold"),
    ROW(memory_empty, PARSE, "vstree_mesh_load_memory: memory.ply: line 1: file is empty"),
    ROW(memory_garbage_ply, PARSE,
        "vstree_mesh_load_memory: scan.ply: line 1: not a PLY file: it must start with a `ply` "
        "line"),
    ROW(memory_nul_in_off, PARSE,
        "vstree_mesh_load_memory: memory.off: line 4: a NUL byte: this is binary data, not a text "
        "file"),
    ROW(memory_invalid_utf8_obj, PARSE,
        "vstree_mesh_load_memory: memory.obj: line 3: expected a number, found "
        "`\xef\xbf\xbd\xef\xbf\xbd`"),
    ROW(memory_off_prefix_only, PARSE,
        "vstree_mesh_load_memory: memory.off: line 3: vertex 0: expected 3 numbers, found 1"),
    ROW(memory_xyz_nan, PARSE,
        "vstree_mesh_load_memory: points.xyz: line 2: point 1: has a NaN or infinite coordinate "
        "(1, 1, NaN)"),

    ROW(save_mesh_null, NULL_POINTER, "vstree_mesh_save: `mesh` is NULL"),
    ROW(save_path_null, NULL_POINTER, "vstree_mesh_save: `path` is NULL"),
    ROW(save_path_empty, INVALID_ARGUMENT, "vstree_mesh_save: `path`: the path is empty"),
    ROW(save_flags_unknown, INVALID_ARGUMENT,
        "vstree_mesh_save: `flags`: 0x2 has unknown bits (known: VSTREE_SAVE_ASCII = 1)"),
    ROW(save_flags_all, INVALID_ARGUMENT,
        "vstree_mesh_save: `flags`: 0x* has unknown bits (known: VSTREE_SAVE_ASCII = 1)"),
    ROW(save_unsupported, UNSUPPORTED_FORMAT,
        "vstree_mesh_save: {dir}/a.stl: unsupported file format (expected .ply, .obj, .off, .xyz "
        "or .pwn)"),
    ROW(save_missing_directory, IO,
        "vstree_mesh_save: {dir}/no/such/dir/a.ply: No such file or directory (os error 2)"),

    ROW(copy_positions_mesh_null, NULL_POINTER, "vstree_mesh_copy_positions: `mesh` is NULL"),
    ROW(copy_positions_out_null, NULL_POINTER, "vstree_mesh_copy_positions: `out` is NULL"),
    ROW(copy_positions_null_and_zero, BUFFER_TOO_SMALL,
        "vstree_mesh_copy_positions: `capacity` is 0, but 864 elements are needed for `out`"),
    ROW(copy_positions_one_short, BUFFER_TOO_SMALL,
        "vstree_mesh_copy_positions: `capacity` is 863, but 864 elements are needed for `out`"),
    ROW(copy_positions_misaligned, INVALID_ARGUMENT,
        "vstree_mesh_copy_positions: `out`: 0x* is not aligned to 4 bytes as its element type "
        "requires"),
    ROW(copy_normals_mesh_null, NULL_POINTER, "vstree_mesh_copy_normals: `mesh` is NULL"),
    ROW(copy_normals_none, INVALID_ARGUMENT,
        "vstree_mesh_copy_normals: `mesh`: has no normals (see vstree_mesh_has_normals)"),
    ROW(copy_normals_out_null, NULL_POINTER, "vstree_mesh_copy_normals: `out` is NULL"),
    ROW(copy_normals_small, BUFFER_TOO_SMALL,
        "vstree_mesh_copy_normals: `capacity` is 3, but 864 elements are needed for `out`"),
    ROW(copy_triangles_mesh_null, NULL_POINTER, "vstree_mesh_copy_triangles: `mesh` is NULL"),
    ROW(copy_triangles_out_null, NULL_POINTER, "vstree_mesh_copy_triangles: `out` is NULL"),
    ROW(copy_triangles_one_short, BUFFER_TOO_SMALL,
        "vstree_mesh_copy_triangles: `capacity` is 1727, but 1728 elements are needed for `out`"),
    ROW(copy_triangles_misaligned, INVALID_ARGUMENT,
        "vstree_mesh_copy_triangles: `out`: 0x* is not aligned to 4 bytes as its element type "
        "requires"),

    ROW(simplify_mesh_null, NULL_POINTER, "vstree_simplify: `mesh` is NULL"),
    ROW(simplify_out_null, NULL_POINTER, "vstree_simplify: `out_result` is NULL"),
    ROW(simplify_cloud_without_normals, INVALID_INPUT,
        "vstree_simplify: invalid input: the point cloud has no normals (estimate them first)"),
    ROW(simplify_only_degenerate, INVALID_INPUT,
        "vstree_simplify: invalid input: every triangle of the mesh is degenerate (zero area)"),
    ROW(simplify_cloud_zero_normal, INVALID_INPUT,
        "vstree_simplify: invalid input: point 2 has a zero-length normal"),
    ROW(simplify_params_misaligned, INVALID_ARGUMENT,
        "vstree_simplify: `params`: pointer is misaligned"),
    ROW(simplify_size_zero, INVALID_ARGUMENT,
        "vstree_simplify: `params->struct_size`: 0 is not a size of vstree_simplify_params this "
        "library knows (48 to 56): initialise the struct with its _default() function"),
    ROW(simplify_size_short, INVALID_ARGUMENT,
        "vstree_simplify: `params->struct_size`: 4 is not a size of vstree_simplify_params this "
        "library knows (48 to 56): initialise the struct with its _default() function"),
    ROW(simplify_size_one_more, INVALID_ARGUMENT,
        "vstree_simplify: `params->struct_size`: 57 is not a size of vstree_simplify_params this "
        "library knows (48 to 56): the program was compiled against a newer vstree.h than this "
        "library"),
    ROW(simplify_size_huge, INVALID_ARGUMENT,
        "vstree_simplify: `params->struct_size`: 4294967295 is not a size of "
        "vstree_simplify_params this library knows (48 to 56): the program was compiled against "
        "a newer vstree.h than this library"),
    ROW(simplify_tree_kind_99, INVALID_PARAMETER,
        "vstree_simplify: parameter `tree_kind`: 99: must be one of 0 "
        "(VSTREE_TREE_KIND_VS_TREE), 1 (VSTREE_TREE_KIND_OCTREE)"),
    ROW(simplify_tree_kind_neg, INVALID_PARAMETER,
        "vstree_simplify: parameter `tree_kind`: -1: must be one of 0 "
        "(VSTREE_TREE_KIND_VS_TREE), 1 (VSTREE_TREE_KIND_OCTREE)"),
    ROW(simplify_metric_99, INVALID_PARAMETER,
        "vstree_simplify: parameter `metric`: 99: must be one of 0 (VSTREE_METRIC_L2), 1 "
        "(VSTREE_METRIC_L21), 2 (VSTREE_METRIC_DENSITY)"),
    ROW(simplify_metric_neg, INVALID_PARAMETER,
        "vstree_simplify: parameter `metric`: -1: must be one of 0 (VSTREE_METRIC_L2), 1 "
        "(VSTREE_METRIC_L21), 2 (VSTREE_METRIC_DENSITY)"),
    ROW(simplify_sampling_99, INVALID_PARAMETER,
        "vstree_simplify: parameter `sampling`: 99: must be one of 0 (VSTREE_SAMPLING_VERTICES), "
        "1 (VSTREE_SAMPLING_FACE_CENTERS)"),
    ROW(simplify_sampling_neg, INVALID_PARAMETER,
        "vstree_simplify: parameter `sampling`: -1: must be one of 0 (VSTREE_SAMPLING_VERTICES), "
        "1 (VSTREE_SAMPLING_FACE_CENTERS)"),
    ROW(simplify_error_zero, INVALID_PARAMETER,
        "vstree_simplify: parameter `error`: 0: must be a finite number > 0"),
    ROW(simplify_error_neg, INVALID_PARAMETER,
        "vstree_simplify: parameter `error`: -0.001: must be a finite number > 0"),
    ROW(simplify_error_nan, INVALID_PARAMETER,
        "vstree_simplify: parameter `error`: NaN: must be a finite number > 0"),
    ROW(simplify_error_inf, INVALID_PARAMETER,
        "vstree_simplify: parameter `error`: inf: must be a finite number > 0"),
    ROW(simplify_error_minus_inf, INVALID_PARAMETER,
        "vstree_simplify: parameter `error`: -inf: must be a finite number > 0"),
    ROW(simplify_d_a_neg, INVALID_PARAMETER,
        "vstree_simplify: parameter `d_a`: -0.1: must be in [0, 1]"),
    ROW(simplify_d_a_big, INVALID_PARAMETER,
        "vstree_simplify: parameter `d_a`: 1.5: must be in [0, 1]"),
    ROW(simplify_d_a_nan, INVALID_PARAMETER,
        "vstree_simplify: parameter `d_a`: NaN: must be in [0, 1]"),
    ROW(simplify_d_a_inf, INVALID_PARAMETER,
        "vstree_simplify: parameter `d_a`: inf: must be in [0, 1]"),
    ROW(simplify_d_d_neg, INVALID_PARAMETER,
        "vstree_simplify: parameter `d_d`: -0.25: must be in [0, 1]"),
    ROW(simplify_d_d_big, INVALID_PARAMETER,
        "vstree_simplify: parameter `d_d`: 2: must be in [0, 1]"),
    ROW(simplify_d_d_nan, INVALID_PARAMETER,
        "vstree_simplify: parameter `d_d`: NaN: must be in [0, 1]"),
    ROW(simplify_max_depth_zero, INVALID_PARAMETER,
        "vstree_simplify: parameter `max_depth`: 0: must be from 1 to 30"),
    ROW(simplify_max_depth_31, INVALID_PARAMETER,
        "vstree_simplify: parameter `max_depth`: 31: must be from 1 to 30"),
    ROW(simplify_max_depth_huge, INVALID_PARAMETER,
        "vstree_simplify: parameter `max_depth`: 4294967295: must be from 1 to 30"),
    ROW(simplify_threads_1025, INVALID_PARAMETER,
        "vstree_simplify: parameter `threads`: 1025: must be 0 (all cores) to 1024"),
    ROW(simplify_threads_huge, INVALID_PARAMETER,
        "vstree_simplify: parameter `threads`: 4294967295: must be 0 (all cores) to 1024"),
    ROW(simplify_min_cell_neg, INVALID_PARAMETER,
        "vstree_simplify: parameter `min_cell_size`: -0.000000001: must be in [0, 1)"),
    ROW(simplify_min_cell_one, INVALID_PARAMETER,
        "vstree_simplify: parameter `min_cell_size`: 1: must be in [0, 1)"),
    ROW(simplify_min_cell_nan, INVALID_PARAMETER,
        "vstree_simplify: parameter `min_cell_size`: NaN: must be in [0, 1)"),
    ROW(simplify_min_cell_inf, INVALID_PARAMETER,
        "vstree_simplify: parameter `min_cell_size`: inf: must be in [0, 1)"),
    ROW(simplify_keep_topology_3, INVALID_PARAMETER,
        "vstree_simplify: parameter `keep_topology`: 3: must be one of 0 "
        "(VSTREE_KEEP_TOPOLOGY_AUTO), 1 (VSTREE_KEEP_TOPOLOGY_ON), 2 (VSTREE_KEEP_TOPOLOGY_OFF)"),
    ROW(simplify_keep_topology_neg, INVALID_PARAMETER,
        "vstree_simplify: parameter `keep_topology`: -1: must be one of 0 "
        "(VSTREE_KEEP_TOPOLOGY_AUTO), 1 (VSTREE_KEEP_TOPOLOGY_ON), 2 (VSTREE_KEEP_TOPOLOGY_OFF)"),
    ROW(simplify_target_above_input, INVALID_PARAMETER,
        "vstree_simplify: parameter `target_faces`: 577: more than the input's 576 triangles"),
    ROW(simplify_target_huge, INVALID_PARAMETER,
        "vstree_simplify: parameter `target_faces`: 4294967295: more than the input's 576 "
        "triangles"),
    ROW(simplify_target_on_cloud, INVALID_PARAMETER,
        "vstree_simplify: parameter `target_faces`: 10 triangles asked of a point cloud: a target "
        "needs a mesh (use the error bound)"),
    ROW(simplify_density_half, INVALID_PARAMETER,
        "vstree_simplify: parameter `error`: 0.5 samples per cell: must be at least 1"),
    ROW(simplify_l21_zero, INVALID_PARAMETER,
        "vstree_simplify: parameter `error`: 0: must be a finite number > 0"),

    ROW(tree_mesh_null, NULL_POINTER, "vstree_tree_build: `mesh` is NULL"),
    ROW(tree_out_null, NULL_POINTER, "vstree_tree_build: `out_tree` is NULL"),
    ROW(tree_cloud_without_normals, INVALID_INPUT,
        "vstree_tree_build: invalid input: the point cloud has no normals (estimate them first)"),
    ROW(tree_size_zero, INVALID_ARGUMENT,
        "vstree_tree_build: `params->struct_size`: 0 is not a size of vstree_simplify_params "
        "this library knows (48 to 56): initialise the struct with its _default() function"),
    ROW(tree_size_long, INVALID_ARGUMENT,
        "vstree_tree_build: `params->struct_size`: 4096 is not a size of vstree_simplify_params "
        "this library knows (48 to 56): the program was compiled against a newer vstree.h than "
        "this library"),
    ROW(tree_tree_kind_99, INVALID_PARAMETER,
        "vstree_tree_build: parameter `tree_kind`: 99: must be one of 0 "
        "(VSTREE_TREE_KIND_VS_TREE), 1 (VSTREE_TREE_KIND_OCTREE)"),
    ROW(tree_metric_neg, INVALID_PARAMETER,
        "vstree_tree_build: parameter `metric`: -1: must be one of 0 (VSTREE_METRIC_L2), 1 "
        "(VSTREE_METRIC_L21), 2 (VSTREE_METRIC_DENSITY)"),
    ROW(tree_sampling_99, INVALID_PARAMETER,
        "vstree_tree_build: parameter `sampling`: 99: must be one of 0 "
        "(VSTREE_SAMPLING_VERTICES), 1 (VSTREE_SAMPLING_FACE_CENTERS)"),
    ROW(tree_error_nan, INVALID_PARAMETER,
        "vstree_tree_build: parameter `error`: NaN: must be a finite number > 0"),
    ROW(tree_d_a_big, INVALID_PARAMETER,
        "vstree_tree_build: parameter `d_a`: 1.01: must be in [0, 1]"),
    ROW(tree_d_d_neg, INVALID_PARAMETER,
        "vstree_tree_build: parameter `d_d`: -1: must be in [0, 1]"),
    ROW(tree_max_depth_zero, INVALID_PARAMETER,
        "vstree_tree_build: parameter `max_depth`: 0: must be from 1 to 30"),
    ROW(tree_threads_1025, INVALID_PARAMETER,
        "vstree_tree_build: parameter `threads`: 1025: must be 0 (all cores) to 1024"),
    ROW(tree_min_cell_one, INVALID_PARAMETER,
        "vstree_tree_build: parameter `min_cell_size`: 1: must be in [0, 1)"),

    ROW(take_mesh_result_null, NULL_POINTER, "vstree_simplify_result_take_mesh: `result` is NULL"),
    ROW(take_mesh_out_null, NULL_POINTER, "vstree_simplify_result_take_mesh: `out_mesh` is NULL"),
    ROW(copy_nodes_tree_null, NULL_POINTER, "vstree_tree_copy_nodes: `tree` is NULL"),
    ROW(copy_nodes_out_null, NULL_POINTER, "vstree_tree_copy_nodes: `out` is NULL"),
    ROW(copy_nodes_one_short, BUFFER_TOO_SMALL,
        "vstree_tree_copy_nodes: `capacity` is 104, but 105 elements are needed for `out`"),
    ROW(copy_nodes_misaligned, INVALID_ARGUMENT,
        "vstree_tree_copy_nodes: `out`: 0x* is not aligned to 4 bytes as its element type "
        "requires"),
    ROW(copy_t_nodes_tree_null, NULL_POINTER, "vstree_tree_copy_t_nodes: `tree` is NULL"),
    ROW(copy_t_nodes_zero, BUFFER_TOO_SMALL,
        "vstree_tree_copy_t_nodes: `capacity` is 0, but 52 elements are needed for `out`"),
    ROW(copy_t_nodes_out_null, NULL_POINTER, "vstree_tree_copy_t_nodes: `out` is NULL"),
    ROW(copy_levels_tree_null, NULL_POINTER, "vstree_tree_copy_levels: `tree` is NULL"),
    ROW(copy_levels_one_short, BUFFER_TOO_SMALL,
        "vstree_tree_copy_levels: `capacity` is 3, but 4 elements are needed for `out`"),
    ROW(copy_levels_out_null, NULL_POINTER, "vstree_tree_copy_levels: `out` is NULL"),
    ROW(labels_tree_null, NULL_POINTER, "vstree_tree_copy_vertex_labels: `tree` is NULL"),
    ROW(labels_kind_2, INVALID_ARGUMENT,
        "vstree_tree_copy_vertex_labels: `kind`: 2: must be VSTREE_LABEL_KIND_CLUSTER (0) or "
        "VSTREE_LABEL_KIND_T_NODE (1)"),
    ROW(labels_kind_neg, INVALID_ARGUMENT,
        "vstree_tree_copy_vertex_labels: `kind`: -1: must be VSTREE_LABEL_KIND_CLUSTER (0) or "
        "VSTREE_LABEL_KIND_T_NODE (1)"),
    ROW(labels_kind_99, INVALID_ARGUMENT,
        "vstree_tree_copy_vertex_labels: `kind`: 99: must be VSTREE_LABEL_KIND_CLUSTER (0) or "
        "VSTREE_LABEL_KIND_T_NODE (1)"),
    ROW(labels_out_null, NULL_POINTER, "vstree_tree_copy_vertex_labels: `out` is NULL"),
    ROW(labels_one_short, BUFFER_TOO_SMALL,
        "vstree_tree_copy_vertex_labels: `capacity` is 287, but 288 elements are needed for `out`"),

    ROW(reconstruct_cloud_null, NULL_POINTER, "vstree_reconstruct: `cloud` is NULL"),
    ROW(reconstruct_out_null, NULL_POINTER, "vstree_reconstruct: `out_result` is NULL"),
    ROW(reconstruct_nine_points, INVALID_INPUT,
        "vstree_reconstruct: invalid input: 9 points: at least 10 are needed"),
    ROW(reconstruct_collinear, INVALID_INPUT,
        "vstree_reconstruct: invalid input: all 12 points lie on one line: no surface passes "
        "through them"),
    ROW(reconstruct_take_mesh_null, NULL_POINTER,
        "vstree_reconstruct_result_take_mesh: `result` is NULL"),
    ROW(reconstruct_size_zero, INVALID_ARGUMENT,
        "vstree_reconstruct: `params->struct_size`: 0 is not a size of vstree_reconstruct_params "
        "this library knows (80 to 88): initialise the struct with its _default() function"),
    ROW(reconstruct_size_short, INVALID_ARGUMENT,
        "vstree_reconstruct: `params->struct_size`: 8 is not a size of vstree_reconstruct_params "
        "this library knows (80 to 88): initialise the struct with its _default() function"),
    ROW(reconstruct_size_long, INVALID_ARGUMENT,
        "vstree_reconstruct: `params->struct_size`: 4096 is not a size of "
        "vstree_reconstruct_params this library knows (80 to 88): the program was compiled "
        "against a newer vstree.h than this library"),
    ROW(reconstruct_orient_99, INVALID_PARAMETER,
        "vstree_reconstruct: parameter `orient`: 99: must be one of 0 "
        "(VSTREE_ORIENTATION_UNORIENTED), 1 (VSTREE_ORIENTATION_PROPAGATE), 2 "
        "(VSTREE_ORIENTATION_PROPAGATE_MAJORITY), 3 (VSTREE_ORIENTATION_PROPAGATE_OUTWARD)"),
    ROW(reconstruct_orient_neg, INVALID_PARAMETER,
        "vstree_reconstruct: parameter `orient`: -1: must be one of 0 "
        "(VSTREE_ORIENTATION_UNORIENTED), 1 (VSTREE_ORIENTATION_PROPAGATE), 2 "
        "(VSTREE_ORIENTATION_PROPAGATE_MAJORITY), 3 (VSTREE_ORIENTATION_PROPAGATE_OUTWARD)"),
    ROW(reconstruct_error_zero, INVALID_PARAMETER,
        "vstree_reconstruct: parameter `error`: 0: must be a finite number > 0"),
    ROW(reconstruct_error_neg, INVALID_PARAMETER,
        "vstree_reconstruct: parameter `error`: -1: must be a finite number > 0"),
    ROW(reconstruct_error_nan, INVALID_PARAMETER,
        "vstree_reconstruct: parameter `error`: NaN: must be a finite number > 0"),
    ROW(reconstruct_error_inf, INVALID_PARAMETER,
        "vstree_reconstruct: parameter `error`: inf: must be a finite number > 0"),
    ROW(reconstruct_d_a_one, INVALID_PARAMETER,
        "vstree_reconstruct: parameter `d_a`: 1: the height-field test (every normal's dot "
        "product with the cell's mean normal above d_a) can never hold, so no cell becomes a "
        "T-node and there is no base mesh; reconstruction needs d_a below 1 (default 0)"),
    ROW(reconstruct_d_d_zero, INVALID_PARAMETER,
        "vstree_reconstruct: parameter `d_d`: 0: the height-field test (every sample's height "
        "over the cell's plane below d_d times the cell's radius) can never hold, so no cell "
        "becomes a T-node and there is no base mesh; reconstruction needs d_d above 0 (default "
        "0.1667)"),
    ROW(reconstruct_d_a_neg, INVALID_PARAMETER,
        "vstree_reconstruct: parameter `d_a`: -0.5: must be in [0, 1]"),
    ROW(reconstruct_d_a_nan, INVALID_PARAMETER,
        "vstree_reconstruct: parameter `d_a`: NaN: must be in [0, 1]"),
    ROW(reconstruct_d_d_big, INVALID_PARAMETER,
        "vstree_reconstruct: parameter `d_d`: 1.5: must be in [0, 1]"),
    ROW(reconstruct_d_d_inf, INVALID_PARAMETER,
        "vstree_reconstruct: parameter `d_d`: inf: must be in [0, 1]"),
    ROW(reconstruct_max_depth_zero, INVALID_PARAMETER,
        "vstree_reconstruct: parameter `max_depth`: 0: must be from 1 to 30"),
    ROW(reconstruct_max_depth_31, INVALID_PARAMETER,
        "vstree_reconstruct: parameter `max_depth`: 31: must be from 1 to 30"),
    ROW(reconstruct_max_levels_13, INVALID_PARAMETER,
        "vstree_reconstruct: parameter `max_levels`: 13: must be from 0 to 12"),
    ROW(reconstruct_max_levels_huge, INVALID_PARAMETER,
        "vstree_reconstruct: parameter `max_levels`: 4294967295: must be from 0 to 12"),
    ROW(reconstruct_min_cell_neg, INVALID_PARAMETER,
        "vstree_reconstruct: parameter `min_cell_size`: -0.0000001: must be in [0, 1)"),
    ROW(reconstruct_min_cell_one, INVALID_PARAMETER,
        "vstree_reconstruct: parameter `min_cell_size`: 1: must be in [0, 1)"),
    ROW(reconstruct_min_cell_nan, INVALID_PARAMETER,
        "vstree_reconstruct: parameter `min_cell_size`: NaN: must be in [0, 1)"),
    ROW(reconstruct_target_neg, INVALID_PARAMETER,
        "vstree_reconstruct: parameter `target_distance`: -0.001: must be a finite number >= 0"),
    ROW(reconstruct_target_nan, INVALID_PARAMETER,
        "vstree_reconstruct: parameter `target_distance`: NaN: must be a finite number >= 0"),
    ROW(reconstruct_target_inf, INVALID_PARAMETER,
        "vstree_reconstruct: parameter `target_distance`: inf: must be a finite number >= 0"),
    ROW(reconstruct_displaced_neg, INVALID_PARAMETER,
        "vstree_reconstruct: parameter `min_displaced`: -0.1: must be in [0, 1]"),
    ROW(reconstruct_displaced_big, INVALID_PARAMETER,
        "vstree_reconstruct: parameter `min_displaced`: 1.5: must be in [0, 1]"),
    ROW(reconstruct_displaced_nan, INVALID_PARAMETER,
        "vstree_reconstruct: parameter `min_displaced`: NaN: must be in [0, 1]"),
    ROW(reconstruct_max_triangles_zero, INVALID_PARAMETER,
        "vstree_reconstruct: parameter `max_triangles`: 0: must be from 1 to 4294967295"),
    ROW(reconstruct_grid_3, INVALID_PARAMETER,
        "vstree_reconstruct: parameter `max_grid_depth`: 3: must be from 4 to 20"),
    ROW(reconstruct_grid_21, INVALID_PARAMETER,
        "vstree_reconstruct: parameter `max_grid_depth`: 21: must be from 4 to 20"),
    ROW(reconstruct_grid_zero, INVALID_PARAMETER,
        "vstree_reconstruct: parameter `max_grid_depth`: 0: must be from 4 to 20"),
    ROW(reconstruct_trim_neg, INVALID_PARAMETER,
        "vstree_reconstruct: parameter `trim`: -1: must be a finite number >= 0"),
    ROW(reconstruct_trim_nan, INVALID_PARAMETER,
        "vstree_reconstruct: parameter `trim`: NaN: must be a finite number >= 0"),
    ROW(reconstruct_trim_inf, INVALID_PARAMETER,
        "vstree_reconstruct: parameter `trim`: inf: must be a finite number >= 0"),
    ROW(reconstruct_neighbours_2, INVALID_PARAMETER,
        "vstree_reconstruct: parameter `neighbours`: 2: must be from 3 to 256"),
    ROW(reconstruct_neighbours_257, INVALID_PARAMETER,
        "vstree_reconstruct: parameter `neighbours`: 257: must be from 3 to 256"),
    ROW(reconstruct_reorient_2, INVALID_PARAMETER,
        "vstree_reconstruct: parameter `reorient_given`: 2: must be 0 or 1"),
    ROW(reconstruct_threads_1025, INVALID_PARAMETER,
        "vstree_reconstruct: parameter `threads`: 1025: must be 0 (all cores) to 1024"),
    ROW(reconstruct_base_mesh_3, INVALID_PARAMETER,
        "vstree_reconstruct: parameter `base_mesh`: 3: must be one of 0 (VSTREE_BASE_MESH_WINDING), "
        "1 (VSTREE_BASE_MESH_PAPER), 2 (VSTREE_BASE_MESH_ADAPTIVE)"),

    ROW(normals_mesh_null, NULL_POINTER, "vstree_estimate_normals: `mesh` is NULL"),
    ROW(normals_out_null, NULL_POINTER, "vstree_estimate_normals: `out_mesh` is NULL"),
    ROW(normals_two_points, INVALID_INPUT,
        "vstree_estimate_normals: invalid input: 2 points: normals need at least 3"),
    ROW(normals_collinear, INVALID_INPUT,
        "vstree_estimate_normals: invalid input: all 12 points lie on one line: no surface passes "
        "through them"),
    ROW(normals_report_size_zero, INVALID_ARGUMENT,
        "vstree_estimate_normals: `out_report->struct_size`: 0: set it to "
        "sizeof(vstree_normals_report) before the call"),
    ROW(normals_report_size_short, INVALID_ARGUMENT,
        "vstree_estimate_normals: `out_report->struct_size`: 12: set it to "
        "sizeof(vstree_normals_report) before the call"),
    ROW(normals_report_size_long, OK, ""),
    ROW(normals_size_zero, INVALID_ARGUMENT,
        "vstree_estimate_normals: `params->struct_size`: 0 is not a size of vstree_normal_params "
        "this library knows (20 to 20): initialise the struct with its _default() function"),
    ROW(normals_size_short, INVALID_ARGUMENT,
        "vstree_estimate_normals: `params->struct_size`: 19 is not a size of "
        "vstree_normal_params this library knows (20 to 20): initialise the struct with its "
        "_default() function"),
    ROW(normals_size_long, INVALID_ARGUMENT,
        "vstree_estimate_normals: `params->struct_size`: 4096 is not a size of "
        "vstree_normal_params this library knows (20 to 20): the program was compiled against a "
        "newer vstree.h than this library"),
    ROW(normals_orient_99, INVALID_PARAMETER,
        "vstree_estimate_normals: parameter `orient`: 99: must be one of 0 "
        "(VSTREE_ORIENTATION_UNORIENTED), 1 (VSTREE_ORIENTATION_PROPAGATE), 2 "
        "(VSTREE_ORIENTATION_PROPAGATE_MAJORITY), 3 (VSTREE_ORIENTATION_PROPAGATE_OUTWARD)"),
    ROW(normals_orient_neg, INVALID_PARAMETER,
        "vstree_estimate_normals: parameter `orient`: -1: must be one of 0 "
        "(VSTREE_ORIENTATION_UNORIENTED), 1 (VSTREE_ORIENTATION_PROPAGATE), 2 "
        "(VSTREE_ORIENTATION_PROPAGATE_MAJORITY), 3 (VSTREE_ORIENTATION_PROPAGATE_OUTWARD)"),
    ROW(normals_neighbours_zero, INVALID_PARAMETER,
        "vstree_estimate_normals: parameter `neighbours`: 0: must be from 3 to 256"),
    ROW(normals_neighbours_2, INVALID_PARAMETER,
        "vstree_estimate_normals: parameter `neighbours`: 2: must be from 3 to 256"),
    ROW(normals_neighbours_257, INVALID_PARAMETER,
        "vstree_estimate_normals: parameter `neighbours`: 257: must be from 3 to 256"),
    ROW(normals_neighbours_huge, INVALID_PARAMETER,
        "vstree_estimate_normals: parameter `neighbours`: 4294967295: must be from 3 to 256"),
    ROW(normals_reorient_2, INVALID_PARAMETER,
        "vstree_estimate_normals: parameter `reorient_given`: 2: must be 0 or 1"),
    ROW(normals_threads_1025, INVALID_PARAMETER,
        "vstree_estimate_normals: parameter `threads`: 1025: must be 0 (all cores) to 1024"),
    ROW(normals_threads_huge, INVALID_PARAMETER,
        "vstree_estimate_normals: parameter `threads`: 4294967295: must be 0 (all cores) to 1024"),

    ROW(error_copy_null_buffer, BUFFER_TOO_SMALL, "vstree_mesh_load: `out_mesh` is NULL"),
    ROW(error_copy_capacity_1, BUFFER_TOO_SMALL, "vstree_mesh_load: `out_mesh` is NULL"),
    ROW(error_copy_capacity_8, BUFFER_TOO_SMALL, "vstree_mesh_load: `out_mesh` is NULL"),
    ROW(error_copy_one_short, BUFFER_TOO_SMALL, "vstree_mesh_load: `out_mesh` is NULL"),
    ROW(error_copy_exact, OK, "vstree_mesh_load: `out_mesh` is NULL"),
    ROW(error_copy_utf8_boundary, BUFFER_TOO_SMALL,
        "vstree_mesh_load: {dir}/\xc3\xa9.ply: No such file or directory (os error 2)"),
    ROW(error_copy_after_success, OK, ""),

    ROW(cancel_simplify_first, CANCELLED, "vstree_simplify: cancelled"),
    ROW(cancel_simplify_done, CANCELLED, "vstree_simplify: cancelled"),
    ROW(cancel_simplify_cluster, CANCELLED, "vstree_simplify: cancelled"),
    ROW(cancel_tree_first, CANCELLED, "vstree_tree_build: cancelled"),
    ROW(cancel_reconstruct_first, CANCELLED, "vstree_reconstruct: cancelled"),
    ROW(cancel_normals_first, CANCELLED, "vstree_estimate_normals: cancelled"),
    ROW(cancel_normals_done, CANCELLED, "vstree_estimate_normals: cancelled"),

    ROW(simplify_density_default_bound, OK, ""),
    ROW(simplify_density_size_ignores_bound, OK, ""),
    ROW(simplify_size_ignores_nan_bound, OK, ""),
    ROW(simplify_min_cell_collapses_all, INVALID_PARAMETER,
        "vstree_simplify: parameter `min_cell_size`: 0.99: every triangle collapsed (1 cluster for "
        "the whole model): cells this small (relative to the diagonal) are not split, so the tree "
        "is coarser than the bound asks; use a smaller size (default 1e-7)"),
    ROW(simplify_three_points, INVALID_PARAMETER,
        "vstree_simplify: parameter `error`: 0.001: all 3 points collapsed into one (1 cluster for "
        "the whole model): the model is within this bound of too few planes; use a smaller bound (a "
        "flat model, within any bound of one plane, needs the density metric)"),
    ROW(simplify_three_points_density_1, OK, ""),
    ROW(load_ply_ascii_nul_body, PARSE,
        "vstree_mesh_load: {dir}/zeros.ply: line 8: vertex 0: byte 0x00: this is binary data, but "
        "the header says `format ascii`"),
    ROW(memory_ply_ascii_nul_body, PARSE,
        "vstree_mesh_load_memory: memory.ply: line 8: vertex 0: byte 0x00: this is binary data, "
        "but the header says `format ascii`"),
    ROW(load_ply_binary_with_tail, OK, ""),
    ROW(load_obj_colours_on_some_vertices, OK, ""),
};

/* ---- matching and the run ---- */

/* Glob match of `text` against `pattern`, where '*' matches any run of characters. */
static int glob(const char *pattern, const char *text) {
  if (*pattern == '\0') return *text == '\0';
  if (*pattern == '*') {
    for (;; text++) {
      if (glob(pattern + 1, text)) return 1;
      if (*text == '\0') return 0;
    }
  }
  return *pattern == *text && glob(pattern + 1, text + 1);
}

/* `pattern` with every "{dir}" replaced by TEMP_DIR (and, on Windows, the POSIX text for a
 * missing file by '*': see the top of this file). */
static void expand(const char *pattern, char *out, size_t size) {
  size_t n = 0, dir = strlen(g_dir);
#ifdef _WIN32
  static const char enoent[] = "No such file or directory (os error 2)";
#endif
  while (*pattern && n + 1 < size) {
    if (strncmp(pattern, "{dir}", 5) == 0 && n + dir + 1 < size) {
      memcpy(out + n, g_dir, dir);
      n += dir;
      pattern += 5;
#ifdef _WIN32
    } else if (strncmp(pattern, enoent, sizeof enoent - 1) == 0) {
      out[n++] = '*';
      pattern += sizeof enoent - 1;
#endif
    } else {
      out[n++] = *pattern++;
    }
  }
  out[n] = '\0';
}

static vstree_mesh *fixture(const float *p, const float *normals, const uint32_t *t, size_t m) {
  vstree_mesh *mesh = NULL;
  if (vstree_mesh_create(p, g_vertex_count, normals, t, m, &mesh) != VSTREE_STATUS_OK) {
    fprintf(stderr, "cannot make a fixture: %s\n", vstree_last_error_message());
    exit(2);
  }
  return mesh;
}

/* A torus, rings x segments, two triangles per quad. */
/* The fixture arrays: common.h's torus without bumps. */
static torus g_torus;
static void make_fixture_arrays(unsigned rings, unsigned segments) {
  g_torus = make_torus(rings, segments, 0.0f);
  g_positions = g_torus.positions;
  g_normals = g_torus.normals;
  g_triangles = g_torus.triangles;
  g_vertex_count = g_torus.vertex_count;
  g_triangle_count = g_torus.triangle_count;
}

int main(int argc, char **argv) {
  size_t k, n = sizeof g_cases / sizeof g_cases[0];
  int failed = 0;
  char sub[4096];
  if (argc != 2) {
    fprintf(stderr, "usage: %s TEMP_DIR\n", argv[0]);
    return 2;
  }
  snprintf(g_dir, sizeof g_dir, "%s", argv[1]);
  snprintf(sub, sizeof sub, "%s/sub.ply", g_dir);
  if (mkdir(sub, 0700) != 0 && errno != EEXIST) {
    fprintf(stderr, "cannot make %s\n", sub);
    return 2;
  }
  make_fixture_arrays(24, 12);
  g_mesh = fixture(g_positions, g_normals, g_triangles, g_triangle_count);
  g_cloud = fixture(g_positions, g_normals, NULL, 0);
  g_cloud_nn = fixture(g_positions, NULL, NULL, 0);
  if (vstree_tree_build(g_mesh, NULL, NULL, NULL, &g_tree) != VSTREE_STATUS_OK ||
      vstree_tree_t_node_count(g_tree) == 0) {
    fprintf(stderr, "cannot build the fixture tree: %s\n", vstree_last_error_message());
    return 2;
  }

  for (k = 0; k < n; k++) {
    const bad_case *c = &g_cases[k];
    char expected[8192];
    const char *got_message;
    vstree_status got;
    g_problem[0] = '\0';
    got = c->call();
    got_message = vstree_last_error_message();
    expand(c->message, expected, sizeof expected);
    if (got != c->status || !glob(expected, got_message) || g_problem[0] != '\0') {
      failed++;
      fprintf(stderr,
              "FAIL %s\n  got      %d %s: \"%s\"\n  expected %d %s: \"%s\"%s%s\n", c->name,
              (int)got, vstree_status_str(got), got_message, (int)c->status,
              vstree_status_str(c->status), expected, g_problem[0] ? "\n  and " : "", g_problem);
    }
  }

  vstree_tree_free(g_tree);
  vstree_mesh_free(g_mesh);
  vstree_mesh_free(g_cloud);
  vstree_mesh_free(g_cloud_nn);
  free_torus(&g_torus);
  printf("%d passed, %d failed\n", (int)n - failed, failed);
  return failed == 0 ? 0 : 1;
}
