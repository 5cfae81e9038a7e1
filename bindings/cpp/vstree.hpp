/**
 * \file vstree.hpp
 * \brief Header-only C++11 wrapper of the vstree C API (vstree.h): RAII handles that free
 * themselves, std::vector in and out, and vstree::error exceptions carrying the status and the
 * library's message.
 *
 * \code
 *   vstree::mesh input = vstree::mesh::load("bunny.ply");
 *   vstree_simplify_params p = vstree::default_params();
 *   p.error = 2e-3;
 *   vstree::simplify_result r = vstree::simplify(input, p, [](float f, const char *stage) {
 *       std::printf("%3.0f%% %s\n", 100 * f, stage);
 *       return true;  // false cancels: vstree::error with VSTREE_STATUS_CANCELLED
 *   });
 *   r.mesh().save("bunny-simplified.ply");
 *
 *   vstree::mesh scan = vstree::mesh::load("scan.xyz");        // points, no normals
 *   vstree::reconstruct_result s = vstree::reconstruct(scan);  // normals estimated inside
 *   s.mesh().save("scan-surface.ply");
 * \endcode
 *
 * Thread safety is the C API's: objects are immutable once made, so const use from several
 * threads is fine. Exceptions thrown by a progress callback are carried across the C library
 * (which is never unwound through) and rethrown by the call that invoked it.
 */
#ifndef VSTREE_HPP
#define VSTREE_HPP

#include "vstree.h"

#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace vstree {

/** A failed call: the C status and the library's message (function, argument, detail). */
class error : public std::runtime_error {
public:
  error(vstree_status status, const std::string &message)
      : std::runtime_error(message), status_(status) {}
  /** The ::vstree_status of the failed call. */
  vstree_status status() const noexcept { return status_; }

private:
  vstree_status status_;
};

namespace detail {

/** Throws vstree::error when `status` is not VSTREE_STATUS_OK. */
inline void check(vstree_status status) {
  if (status != VSTREE_STATUS_OK) {
    std::string message = vstree_last_error_message();
    if (message.empty()) {
      message = vstree_status_str(status);
    }
    throw error(status, message);
  }
}

/** Move-only owner of a C handle, freed with `Free`. */
template <typename T, void (*Free)(T *)> class handle {
public:
  handle() noexcept : p_(nullptr) {}
  explicit handle(T *p) noexcept : p_(p) {}
  handle(handle &&other) noexcept : p_(other.release()) {}
  handle &operator=(handle &&other) noexcept {
    if (this != &other) {
      Free(p_);
      p_ = other.release();
    }
    return *this;
  }
  handle(const handle &) = delete;
  handle &operator=(const handle &) = delete;
  ~handle() { Free(p_); }
  T *get() const noexcept { return p_; }
  T *release() noexcept {
    T *p = p_;
    p_ = nullptr;
    return p;
  }

private:
  T *p_;
};

/** Carries a std::function progress callback and any exception it throws through C. */
struct progress_state {
  const std::function<bool(float, const char *)> *fn;
  std::exception_ptr failure;
};

inline int32_t progress_trampoline(void *user_data, float fraction, const char *stage) {
  progress_state *state = static_cast<progress_state *>(user_data);
  try {
    return (*state->fn)(fraction, stage) ? 1 : 0;
  } catch (...) {
    state->failure = std::current_exception(); // rethrown once the C call has returned
    return 0;
  }
}

/** Calls `call(callback, user_data)` with `progress` adapted to the C callback. */
template <typename Call>
void with_progress(const std::function<bool(float, const char *)> &progress, Call call) {
  if (!progress) {
    check(call(static_cast<vstree_progress_fn>(nullptr), static_cast<void *>(nullptr)));
    return;
  }
  progress_state state = {&progress, nullptr};
  vstree_status status = call(&progress_trampoline, static_cast<void *>(&state));
  if (state.failure) {
    std::rethrow_exception(state.failure);
  }
  check(status);
}

} // namespace detail

/** Progress callback: (fraction in [0, 1], stage name) -> keep going? Called on the calling
 * thread only. */
typedef std::function<bool(float fraction, const char *stage)> progress_fn;

/** The default parameters (with `struct_size` set): change fields by name. */
inline vstree_simplify_params default_params() { return vstree_simplify_params_default(); }

/** A non-owning view of a mesh: the accessors every mesh has. */
class mesh_view {
public:
  explicit mesh_view(const vstree_mesh *m) noexcept : m_(m) {}
  /** The C handle, for calls this wrapper does not cover. */
  const vstree_mesh *get() const noexcept { return m_; }
  std::size_t vertex_count() const noexcept { return vstree_mesh_vertex_count(m_); }
  std::size_t triangle_count() const noexcept { return vstree_mesh_triangle_count(m_); }
  bool has_normals() const noexcept { return vstree_mesh_has_normals(m_) != 0; }
  /** x y z per vertex. */
  std::vector<float> positions() const {
    std::vector<float> out(3 * vertex_count());
    detail::check(vstree_mesh_copy_positions(m_, out.data(), out.size()));
    return out;
  }
  /** x y z per vertex in double: the exact positions of a model far from the origin (see
   * vstree_mesh_copy_positions_f64()). */
  std::vector<double> positions_f64() const {
    std::vector<double> out(3 * vertex_count());
    detail::check(vstree_mesh_copy_positions_f64(m_, out.data(), out.size()));
    return out;
  }
  /** x y z per vertex; empty when the mesh has no normals. */
  std::vector<float> normals() const {
    std::vector<float> out;
    if (has_normals()) {
      out.resize(3 * vertex_count());
      detail::check(vstree_mesh_copy_normals(m_, out.data(), out.size()));
    }
    return out;
  }
  /** Three vertex indices per triangle. */
  std::vector<uint32_t> triangles() const {
    std::vector<uint32_t> out(3 * triangle_count());
    detail::check(vstree_mesh_copy_triangles(m_, out.data(), out.size()));
    return out;
  }
  /** Writes the mesh; the format comes from the extension. Atomic: on error the file is left
   * as it was. */
  void save(const std::string &path, bool ascii = false) const {
    detail::check(vstree_mesh_save(m_, path.c_str(), ascii ? VSTREE_SAVE_ASCII : 0u));
  }

private:
  const vstree_mesh *m_;
};

/** An owned mesh or point cloud. */
class mesh {
public:
  /** From arrays (copied): 3 floats per vertex, optional normals (empty = none), 3 indices
   * per triangle (empty = point cloud). */
  static mesh create(const std::vector<float> &positions,
                     const std::vector<uint32_t> &triangles = std::vector<uint32_t>(),
                     const std::vector<float> &normals = std::vector<float>()) {
    check_sizes(positions.size(), triangles.size(), normals.size(), "create");
    vstree_mesh *m = nullptr;
    detail::check(vstree_mesh_create(positions.data(), positions.size() / 3,
                                     normals.empty() ? nullptr : normals.data(),
                                     triangles.data(), triangles.size() / 3, &m));
    return mesh(m);
  }
  /** As create(), with double positions, kept as a file's are: a model far from the origin
   * keeps its detail (see vstree_mesh_create_f64()). Its own name, not an overload of
   * create(): a braced list of numbers would fit both. */
  static mesh create_f64(const std::vector<double> &positions,
                         const std::vector<uint32_t> &triangles = std::vector<uint32_t>(),
                         const std::vector<float> &normals = std::vector<float>()) {
    check_sizes(positions.size(), triangles.size(), normals.size(), "create_f64");
    vstree_mesh *m = nullptr;
    detail::check(vstree_mesh_create_f64(positions.data(), positions.size() / 3,
                                         normals.empty() ? nullptr : normals.data(),
                                         triangles.data(), triangles.size() / 3, &m));
    return mesh(m);
  }
  /** Reads .ply, .obj, .off, .xyz or .pwn. */
  static mesh load(const std::string &path) {
    vstree_mesh *m = nullptr;
    detail::check(vstree_mesh_load(path.c_str(), &m));
    return mesh(m);
  }
  /** Parses a file held in memory; `name` ("scan.ply" or "ply") gives the format. */
  static mesh load_memory(const void *data, std::size_t size, const std::string &name) {
    vstree_mesh *m = nullptr;
    detail::check(vstree_mesh_load_memory(data, size, name.c_str(), &m));
    return mesh(m);
  }
  /** Takes ownership of a C handle. */
  explicit mesh(vstree_mesh *m) noexcept : h_(m) {}
  const vstree_mesh *get() const noexcept { return h_.get(); }
  mesh_view view() const noexcept { return mesh_view(h_.get()); }
  operator mesh_view() const noexcept { return view(); }
  std::size_t vertex_count() const noexcept { return view().vertex_count(); }
  std::size_t triangle_count() const noexcept { return view().triangle_count(); }
  bool has_normals() const noexcept { return view().has_normals(); }
  std::vector<float> positions() const { return view().positions(); }
  std::vector<double> positions_f64() const { return view().positions_f64(); }
  std::vector<float> normals() const { return view().normals(); }
  std::vector<uint32_t> triangles() const { return view().triangles(); }
  void save(const std::string &path, bool ascii = false) const { view().save(path, ascii); }

private:
  /** The array sizes create() and create_f64() need: x y z triples, as many normals as
   * positions. */
  static void check_sizes(std::size_t positions, std::size_t triangles, std::size_t normals,
                          const char *function) {
    if (positions % 3 != 0 || triangles % 3 != 0 || (normals != 0 && normals != positions)) {
      throw error(VSTREE_STATUS_INVALID_ARGUMENT,
                  std::string("vstree::mesh::") + function +
                      ": array sizes must be multiples of 3, with as many normals as positions");
    }
  }
  detail::handle<vstree_mesh, vstree_mesh_free> h_;
};

/** What vstree::simplify() returns: the simplified mesh and statistics. */
class simplify_result {
public:
  explicit simplify_result(vstree_simplify_result *r) noexcept : h_(r) {}
  /** The simplified mesh, valid while this result lives. */
  mesh_view mesh() const noexcept { return mesh_view(vstree_simplify_result_get_mesh(h_.get())); }
  /** Statistics: counts, tree figures, timings. */
  const vstree_simplify_stats &stats() const noexcept {
    return *vstree_simplify_result_get_stats(h_.get());
  }
  /** Moves the mesh out; this result is empty afterwards. */
  vstree::mesh take_mesh() {
    vstree_mesh *m = nullptr;
    detail::check(vstree_simplify_result_take_mesh(h_.release(), &m));
    return vstree::mesh(m);
  }

private:
  detail::handle<vstree_simplify_result, vstree_simplify_result_free> h_;
};

/** Simplifies a mesh or point cloud (see vstree_simplify()). */
inline simplify_result simplify(mesh_view input,
                                const vstree_simplify_params &params = default_params(),
                                const progress_fn &progress = progress_fn()) {
  vstree_simplify_result *r = nullptr;
  detail::with_progress(progress, [&](vstree_progress_fn cb, void *user) {
    return vstree_simplify(input.get(), &params, cb, user, &r);
  });
  return simplify_result(r);
}

/** The tree a simplification clusters with, for viewers (see vstree_tree_build()). */
class tree {
public:
  static tree build(mesh_view input, const vstree_simplify_params &params = default_params(),
                    const progress_fn &progress = progress_fn()) {
    vstree_tree *t = nullptr;
    detail::with_progress(progress, [&](vstree_progress_fn cb, void *user) {
      return vstree_tree_build(input.get(), &params, cb, user, &t);
    });
    return tree(t);
  }
  explicit tree(vstree_tree *t) noexcept : h_(t) {}
  const vstree_tree *get() const noexcept { return h_.get(); }
  const vstree_tree_stats &stats() const noexcept { return *vstree_tree_get_stats(h_.get()); }
  std::vector<vstree_node> nodes() const {
    std::vector<vstree_node> out(vstree_tree_node_count(h_.get()));
    detail::check(vstree_tree_copy_nodes(h_.get(), out.data(), out.size()));
    return out;
  }
  std::vector<vstree_t_node> t_nodes() const {
    std::vector<vstree_t_node> out(vstree_tree_t_node_count(h_.get()));
    detail::check(vstree_tree_copy_t_nodes(h_.get(), out.data(), out.size()));
    return out;
  }
  std::vector<vstree_tree_level> levels() const {
    std::vector<vstree_tree_level> out(vstree_tree_level_count(h_.get()));
    detail::check(vstree_tree_copy_levels(h_.get(), out.data(), out.size()));
    return out;
  }
  /** One label per input vertex: its cluster (VSTREE_LABEL_KIND_CLUSTER) or T-node
   * (VSTREE_LABEL_KIND_T_NODE); VSTREE_NO_INDEX for none. */
  std::vector<uint32_t> vertex_labels(vstree_label_kind kind = VSTREE_LABEL_KIND_CLUSTER) const {
    std::vector<uint32_t> out(vstree_tree_vertex_count(h_.get()));
    detail::check(vstree_tree_copy_vertex_labels(h_.get(), kind, out.data(), out.size()));
    return out;
  }

private:
  detail::handle<vstree_tree, vstree_tree_free> h_;
};

/** The default reconstruction parameters (with `struct_size` set): change fields by name. */
inline vstree_reconstruct_params default_reconstruct_params() {
  return vstree_reconstruct_params_default();
}

/** The default normal-estimation parameters (with `struct_size` set). */
inline vstree_normal_params default_normal_params() { return vstree_normal_params_default(); }

/** What vstree::reconstruct() returns: the reconstructed mesh and statistics. */
class reconstruct_result {
public:
  explicit reconstruct_result(vstree_reconstruct_result *r) noexcept : h_(r) {}
  /** The reconstructed mesh, valid while this result lives. */
  mesh_view mesh() const noexcept {
    return mesh_view(vstree_reconstruct_result_get_mesh(h_.get()));
  }
  /** Statistics: normals, tree, base mesh, refinement, errors, timings. */
  const vstree_reconstruct_stats &stats() const noexcept {
    return *vstree_reconstruct_result_get_stats(h_.get());
  }
  /** Moves the mesh out; this result is empty afterwards. */
  vstree::mesh take_mesh() {
    vstree_mesh *m = nullptr;
    detail::check(vstree_reconstruct_result_take_mesh(h_.release(), &m));
    return vstree::mesh(m);
  }

private:
  detail::handle<vstree_reconstruct_result, vstree_reconstruct_result_free> h_;
};

/** Reconstructs a triangle mesh from the points of `cloud` (see vstree_reconstruct()). */
inline reconstruct_result reconstruct(
    mesh_view cloud, const vstree_reconstruct_params &params = default_reconstruct_params(),
    const progress_fn &progress = progress_fn()) {
  vstree_reconstruct_result *r = nullptr;
  detail::with_progress(progress, [&](vstree_progress_fn cb, void *user) {
    return vstree_reconstruct(cloud.get(), &params, cb, user, &r);
  });
  return reconstruct_result(r);
}

/** A copy of `input` with normals estimated where missing (or re-oriented, with
 * `params.reorient_given`); see vstree_estimate_normals(). `report`, if given, is filled. */
inline mesh estimate_normals(mesh_view input,
                             const vstree_normal_params &params = default_normal_params(),
                             const progress_fn &progress = progress_fn(),
                             vstree_normals_report *report = nullptr) {
  vstree_mesh *m = nullptr;
  if (report != nullptr) {
    report->struct_size = sizeof(vstree_normals_report);
  }
  detail::with_progress(progress, [&](vstree_progress_fn cb, void *user) {
    return vstree_estimate_normals(input.get(), &params, cb, user, &m, report);
  });
  return mesh(m);
}

/** The library's version string, e.g. "0.1.0". */
inline std::string version() { return vstree_version(); }

} // namespace vstree

#endif // VSTREE_HPP
