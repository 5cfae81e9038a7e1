/* The C ABI through the shared library, from C: what a host pays around a 1M-triangle
 * simplification (arrays in, arrays out), measured within each run as the wall time minus the
 * library's own stage times, against the Rust call's median from benches/ffi_overhead.rs.
 * Built and run by benches/ffi_overhead.sh. */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include <vstree.h>

#define RUNS 15

static double now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int by_value(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

static double median(double *v) {
  qsort(v, RUNS, sizeof *v, by_value);
  return v[RUNS / 2];
}

static void ok(vstree_status s) {
  if (s != VSTREE_STATUS_OK) {
    fprintf(stderr, "%s\n", vstree_last_error_message());
    exit(1);
  }
}

int main(int argc, char **argv) {
  vstree_mesh *file = NULL;
  float *positions;
  uint32_t *triangles;
  size_t n, t;
  double error, rust;
  FILE *medians;
  if (argc != 3) {
    fprintf(stderr, "usage: %s MESH.ply RUST_MEDIANS.txt\n", argv[0]);
    return 2;
  }
  ok(vstree_mesh_load(argv[1], &file));
  n = vstree_mesh_vertex_count(file);
  t = vstree_mesh_triangle_count(file);
  positions = malloc(3 * n * sizeof *positions);
  triangles = malloc(3 * t * sizeof *triangles);
  ok(vstree_mesh_copy_positions(file, positions, 3 * n));
  ok(vstree_mesh_copy_triangles(file, triangles, 3 * t));
  vstree_mesh_free(file);
  medians = fopen(argv[2], "r");
  if (!medians) {
    fprintf(stderr, "cannot read %s\n", argv[2]);
    return 1;
  }
  printf("%6s %9s | %10s %10s %7s\n", "error", "rust ms", "host ms", "host: +ms", "%");
  while (fscanf(medians, "%lf %lf", &error, &rust) == 2) {
    double wall[RUNS], extra[RUNS];
    vstree_simplify_params p = vstree_simplify_params_default();
    int r;
    p.error = error;
    for (r = 0; r < RUNS; r++) {
      vstree_simplify_result *result = NULL;
      vstree_mesh *m = NULL;
      const vstree_mesh *out;
      const vstree_simplify_stats *s;
      float *op;
      uint32_t *oi;
      double library, t0 = now();
      ok(vstree_mesh_create(positions, n, NULL, triangles, t, &m));
      ok(vstree_simplify(m, &p, NULL, NULL, &result));
      out = vstree_simplify_result_get_mesh(result);
      op = malloc(3 * vstree_mesh_vertex_count(out) * sizeof *op);
      oi = malloc(3 * vstree_mesh_triangle_count(out) * sizeof *oi);
      ok(vstree_mesh_copy_positions(out, op, 3 * vstree_mesh_vertex_count(out)));
      ok(vstree_mesh_copy_triangles(out, oi, 3 * vstree_mesh_triangle_count(out)));
      s = vstree_simplify_result_get_stats(result);
      library = s->seconds_samples + s->seconds_tree + s->seconds_cluster;
      free(op);
      free(oi);
      vstree_simplify_result_free(result);
      vstree_mesh_free(m);
      wall[r] = now() - t0;
      extra[r] = wall[r] - library;
    }
    {
      double w = median(wall), x = median(extra);
      printf("%6.0e %9.1f | %10.1f %10.2f %6.1f%%\n", error, 1e3 * rust, 1e3 * w, 1e3 * x,
             100 * x / rust);
    }
  }
  fclose(medians);
  free(positions);
  free(triangles);
  return 0;
}
