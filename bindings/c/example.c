/* A complete C program using vstree: load a mesh, simplify it with a progress bar, save it.
 *
 *   cc example.c $(pkg-config --cflags --libs vstree) -o vstree-example
 *   ./vstree-example bunny.ply bunny-small.ply 2e-3
 *
 * Every call returns a vstree_status; on failure vstree_last_error_message() says what went
 * wrong (which file and line, which parameter...). Every handle is freed on every path.
 */
#include <stdio.h>
#include <stdlib.h>

#include <vstree.h>

/* Prints a progress line; returning 0 would cancel the simplification. */
static int32_t on_progress(void *user_data, float fraction, const char *stage) {
  int *last_percent = (int *)user_data;
  int percent = (int)(100.0f * fraction);
  if (percent != *last_percent) {
    fprintf(stderr, "\r%3d%% %-20s", percent, stage);
    *last_percent = percent;
  }
  return 1;
}

static int fail(const char *what, vstree_status status) {
  fprintf(stderr, "\nvstree-example: %s failed: %s (%s)\n", what, vstree_status_str(status),
          vstree_last_error_message());
  return 1;
}

int main(int argc, char **argv) {
  vstree_mesh *input = NULL;
  vstree_simplify_result *result = NULL;
  vstree_simplify_params params = vstree_simplify_params_default();
  const vstree_simplify_stats *stats;
  vstree_status status;
  int last_percent = -1;
  int exit_code = 0;

  if (argc < 3 || argc > 4) {
    fprintf(stderr, "usage: %s INPUT OUTPUT [ERROR]\n(vstree %s)\n", argv[0], vstree_version());
    return 2;
  }
  if (argc == 4) {
    params.error = strtod(argv[3], NULL); /* checked by the library: bad values are refused */
  }

  status = vstree_mesh_load(argv[1], &input);
  if (status != VSTREE_STATUS_OK) {
    return fail("loading", status);
  }
  status = vstree_simplify(input, &params, on_progress, &last_percent, &result);
  if (status != VSTREE_STATUS_OK) {
    exit_code = fail("simplifying", status);
  } else {
    status = vstree_mesh_save(vstree_simplify_result_get_mesh(result), argv[2], 0);
    if (status != VSTREE_STATUS_OK) {
      exit_code = fail("saving", status);
    } else {
      stats = vstree_simplify_result_get_stats(result);
      fprintf(stderr, "\n%llu -> %llu triangles, %llu clusters, %llu T-nodes, depth %u, %.3f s\n",
              (unsigned long long)stats->input_triangles,
              (unsigned long long)stats->output_triangles, (unsigned long long)stats->clusters,
              (unsigned long long)stats->t_nodes, stats->max_depth, stats->seconds_total);
    }
  }
  vstree_simplify_result_free(result);
  vstree_mesh_free(input);
  return exit_code;
}
