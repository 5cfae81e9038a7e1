/* Helpers shared by the C tests: a check macro that counts, and generated meshes. */
#ifndef VSTREE_TEST_COMMON_H
#define VSTREE_TEST_COMMON_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <vstree.h>

static int g_checks = 0;
static int g_failures = 0;

#define CHECK(cond)                                                                            \
  do {                                                                                         \
    g_checks++;                                                                                \
    if (!(cond)) {                                                                             \
      g_failures++;                                                                            \
      fprintf(stderr, "%s:%d: CHECK failed: %s (last error: %s)\n", __FILE__, __LINE__, #cond, \
              vstree_last_error_message());                                                    \
    }                                                                                          \
  } while (0)

/* A torus grid: `rings` x `segments` vertices, two triangles per quad, closed, counter-clockwise
 * seen from outside. `bump` wrinkles the tube so different meshes give different trees.
 * Arrays are malloc'ed; the caller frees them with free_torus(). */
typedef struct torus {
  float *positions;
  float *normals;
  uint32_t *triangles;
  size_t vertex_count;
  size_t triangle_count;
} torus;

static inline torus make_torus(unsigned rings, unsigned segments, float bump) {
  const float pi = 3.14159265358979f;
  torus t;
  unsigned i, j;
  size_t k = 0;
  t.vertex_count = (size_t)rings * segments;
  t.triangle_count = 2 * t.vertex_count;
  t.positions = (float *)malloc(3 * t.vertex_count * sizeof(float));
  t.normals = (float *)malloc(3 * t.vertex_count * sizeof(float));
  t.triangles = (uint32_t *)malloc(3 * t.triangle_count * sizeof(uint32_t));
  if (!t.positions || !t.normals || !t.triangles) {
    fprintf(stderr, "out of memory\n");
    exit(2);
  }
  for (i = 0; i < rings; i++) {
    float u = 2 * pi * (float)i / (float)rings;
    for (j = 0; j < segments; j++) {
      float v = 2 * pi * (float)j / (float)segments;
      float r = 0.3f * (1.0f + bump * sinf(5 * u) * sinf(3 * v));
      size_t n = (size_t)i * segments + j;
      t.normals[3 * n + 0] = cosf(v) * cosf(u);
      t.normals[3 * n + 1] = cosf(v) * sinf(u);
      t.normals[3 * n + 2] = sinf(v);
      t.positions[3 * n + 0] = (1.0f + r * cosf(v)) * cosf(u);
      t.positions[3 * n + 1] = (1.0f + r * cosf(v)) * sinf(u);
      t.positions[3 * n + 2] = r * sinf(v);
    }
  }
  for (i = 0; i < rings; i++) {
    for (j = 0; j < segments; j++) {
      uint32_t a = (uint32_t)(i * segments + j);
      uint32_t b = (uint32_t)(((i + 1) % rings) * segments + j);
      uint32_t c = (uint32_t)(((i + 1) % rings) * segments + (j + 1) % segments);
      uint32_t d = (uint32_t)(i * segments + (j + 1) % segments);
      t.triangles[k++] = a;
      t.triangles[k++] = b;
      t.triangles[k++] = c;
      t.triangles[k++] = a;
      t.triangles[k++] = c;
      t.triangles[k++] = d;
    }
  }
  return t;
}

static inline void free_torus(torus *t) {
  free(t->positions);
  free(t->normals);
  free(t->triangles);
}

/* A mesh handle from a torus; exits on failure. */
static inline vstree_mesh *torus_mesh(const torus *t, int with_normals, int with_triangles) {
  vstree_mesh *m = NULL;
  vstree_status s = vstree_mesh_create(t->positions, t->vertex_count,
                                       with_normals ? t->normals : NULL,
                                       with_triangles ? t->triangles : NULL,
                                       with_triangles ? t->triangle_count : 0, &m);
  if (s != VSTREE_STATUS_OK) {
    fprintf(stderr, "cannot make the test mesh: %s\n", vstree_last_error_message());
    exit(2);
  }
  return m;
}

static inline int finish(const char *name) {
  fprintf(stderr, "%s: %d checks, %d failures\n", name, g_checks, g_failures);
  return g_failures == 0 ? 0 : 1;
}

#endif
