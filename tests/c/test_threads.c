/* Concurrency: several threads simplify different meshes (and two threads the same mesh) at
 * once, with the library's own worker threads too; every result equals the single-threaded
 * one bit for bit, progress callbacks run on the calling thread, and each thread keeps its own
 * last-error message.
 */
#define _POSIX_C_SOURCE 200809L
#include "common.h"

#include <pthread.h>
#include <sched.h>

#define MESHES 4
#define WORKERS 8
#define ROUNDS 3

typedef struct output {
  float *positions;
  uint32_t *triangles;
  size_t vertex_count;
  size_t triangle_count;
} output;

static vstree_mesh *g_meshes[MESHES];
static output g_expected[MESHES];

static output copy_output(const vstree_mesh *m) {
  output o;
  o.vertex_count = vstree_mesh_vertex_count(m);
  o.triangle_count = vstree_mesh_triangle_count(m);
  o.positions = (float *)malloc(3 * o.vertex_count * sizeof(float) + 1);
  o.triangles = (uint32_t *)malloc(3 * o.triangle_count * sizeof(uint32_t) + 1);
  if (vstree_mesh_copy_positions(m, o.positions, 3 * o.vertex_count) != VSTREE_STATUS_OK ||
      vstree_mesh_copy_triangles(m, o.triangles, 3 * o.triangle_count) != VSTREE_STATUS_OK) {
    fprintf(stderr, "copy failed: %s\n", vstree_last_error_message());
    exit(2);
  }
  return o;
}

static int same_output(const output *a, const output *b) {
  return a->vertex_count == b->vertex_count && a->triangle_count == b->triangle_count &&
         memcmp(a->positions, b->positions, 3 * a->vertex_count * sizeof(float)) == 0 &&
         memcmp(a->triangles, b->triangles, 3 * a->triangle_count * sizeof(uint32_t)) == 0;
}

static void free_output(output *o) {
  free(o->positions);
  free(o->triangles);
}

typedef struct worker {
  int index;
  pthread_t thread; /* written by main */
  pthread_t self;   /* written by the worker itself */
  int mismatches;
  int failures;
  int foreign_callbacks;
  int callbacks;
  int wrong_messages;
} worker;

static int32_t on_progress(void *user_data, float fraction, const char *stage) {
  worker *w = (worker *)user_data;
  (void)fraction;
  (void)stage;
  w->callbacks++;
  if (!pthread_equal(pthread_self(), w->self)) {
    w->foreign_callbacks++;
  }
  return 1;
}

static void *work(void *arg) {
  worker *w = (worker *)arg;
  int round;
  char expected[64];
  float nan_at[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  vstree_mesh *never = NULL;
  w->self = pthread_self();
  for (round = 0; round < ROUNDS; round++) {
    int m = (w->index + round) % MESHES;
    vstree_simplify_params p = vstree_simplify_params_default();
    vstree_simplify_result *r = NULL;
    p.threads = (unsigned)(w->index % 3); /* 0 (all cores), 1, 2 */
    if (vstree_simplify(g_meshes[m], &p, on_progress, w, &r) != VSTREE_STATUS_OK) {
      w->failures++;
      continue;
    }
    {
      output o = copy_output(vstree_simplify_result_get_mesh(r));
      w->mismatches += !same_output(&o, &g_expected[m]);
      free_output(&o);
    }
    vstree_simplify_result_free(r);

    /* A failure naming this worker's vertex; other threads fail differently meanwhile. */
    nan_at[3 * (w->index % 4)] = NAN;
    snprintf(expected, sizeof expected, "vertex %d ", w->index % 4);
    if (vstree_mesh_create(nan_at, 4, NULL, NULL, 0, &never) != VSTREE_STATUS_INVALID_INPUT) {
      w->failures++;
    }
    sched_yield();
    if (strstr(vstree_last_error_message(), expected) == NULL) {
      w->wrong_messages++;
    }
    nan_at[3 * (w->index % 4)] = 0;
  }
  return NULL;
}

int main(void) {
  torus tori[MESHES];
  worker workers[WORKERS];
  int i;
  for (i = 0; i < MESHES; i++) {
    vstree_simplify_params p = vstree_simplify_params_default();
    vstree_simplify_result *r = NULL;
    tori[i] = make_torus(60 + 20 * (unsigned)i, 30 + 6 * (unsigned)i, 0.1f * (float)(i + 1));
    g_meshes[i] = torus_mesh(&tori[i], 0, 1);
    p.threads = 1;
    CHECK(vstree_simplify(g_meshes[i], &p, NULL, NULL, &r) == VSTREE_STATUS_OK);
    g_expected[i] = copy_output(vstree_simplify_result_get_mesh(r));
    CHECK(g_expected[i].triangle_count > 0);
    vstree_simplify_result_free(r);
  }
  for (i = 0; i < WORKERS; i++) {
    memset(&workers[i], 0, sizeof workers[i]);
    workers[i].index = i;
  }
  for (i = 0; i < WORKERS; i++) {
    CHECK(pthread_create(&workers[i].thread, NULL, work, &workers[i]) == 0);
  }
  for (i = 0; i < WORKERS; i++) {
    CHECK(pthread_join(workers[i].thread, NULL) == 0);
    CHECK(workers[i].failures == 0);
    CHECK(workers[i].mismatches == 0);
    CHECK(workers[i].foreign_callbacks == 0 && workers[i].callbacks >= ROUNDS);
    CHECK(workers[i].wrong_messages == 0);
  }
  for (i = 0; i < MESHES; i++) {
    vstree_mesh_free(g_meshes[i]);
    free_output(&g_expected[i]);
    free_torus(&tori[i]);
  }
  fprintf(stderr, "test_threads: %d threads x %d simplifications on %d meshes matched the "
                  "single-threaded results\n", WORKERS, ROUNDS, MESHES);
  return finish("test_threads");
}
