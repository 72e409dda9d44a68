// Internal to src/eval/: what the metrics of `quadlod eval` (metrics.cpp) and their features
// section (§6c, feature_metrics.cpp) share — the thread-count independent parallel loop, the
// compensated sum and the directed surface distances. The public contract is
// include/quadlod/metrics.h; the definitions are docs/metrics.md.
#pragma once

#include "geometry/bvh.h"
#include "geometry/sampling.h"
#include "quadlod/metrics.h"
#include "quadlod/mesh.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <thread>
#include <vector>

namespace quadlod::eval_detail {

/// Geometry-only copy in metric units: p ↦ s·(p − centre), faces shared verbatim; evaluate()'s
/// normalisation, also used by the LOD chain's Hausdorff (pipeline/lod_distance.cpp) so both
/// measure the same numbers.
PolyMesh scaled_copy(const PolyMesh& m, const Vec3& centre, double s);

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Calls fn(begin, end) for the fixed chunks [k·kChunk, min(n, (k+1)·kChunk)) on `threads`
/// threads (chunks handed out by an atomic counter). The chunk boundaries do not depend on the
/// thread count, so per-chunk state (the warm-start hint of the nearest-point queries) gives
/// thread-independent results. fn must only write state owned by its chunk.
inline constexpr std::size_t kChunk = 1024;
template <class Fn>
void parallel_chunks(std::size_t n, unsigned threads, const Fn& fn) {
  const std::size_t chunks = (n + kChunk - 1) / kChunk;
  std::atomic<std::size_t> next{0};
  auto worker = [&] {
    for (;;) {
      const std::size_t c = next.fetch_add(1, std::memory_order_relaxed);
      if (c >= chunks) return;
      fn(c * kChunk, std::min(n, (c + 1) * kChunk));
    }
  };
  const unsigned t = static_cast<unsigned>(std::min<std::size_t>(threads, chunks));
  if (t <= 1) {
    worker();
    return;
  }
  std::vector<std::thread> pool;
  pool.reserve(t - 1);
  for (unsigned k = 1; k < t; ++k) pool.emplace_back(worker);
  worker();
  for (auto& th : pool) th.join();
}

/// Runs a() and b() concurrently when threads > 1.
template <class A, class B>
void run_both(unsigned threads, const A& a, const B& b) {
  if (threads <= 1) {
    a();
    b();
    return;
  }
  std::thread th(a);
  b();
  th.join();
}

/// Neumaier-compensated sum, accumulated in a fixed order.
struct Sum {
  double s = 0.0, c = 0.0;
  void add(double x) {
    const double t = s + x;
    c += std::abs(s) >= std::abs(x) ? (s - t) + x : (x - t) + s;
    s = t;
  }
  double value() const { return s + c; }
};

/// Distances from sample points (and extra points, max only) to a triangle set.
struct Directed {
  std::vector<double> dist;       ///< per surface sample
  std::vector<Index> nearest;     ///< per surface sample: nearest triangle of the other mesh
  double mean = 0.0;              ///< mean of dist
  double mean_sq = 0.0;           ///< mean of dist²
  double max = 0.0;               ///< max over samples and extra points
};

/// Query order of a and b's points (indices into a, then b) by Morton code (metrics.cpp).
std::vector<std::uint32_t> morton_order(const std::vector<Vec3>& a, const std::vector<Vec3>& b);

/// §6c, every metric of the features section (feature_metrics.cpp).
void feature_metrics(const PolyMesh& input, const PolyMesh& output, const PolyMesh& in,
                     const PolyMesh& out, const TriangleSoup& soup_in, const TriangleSoup& soup_out,
                     const SurfaceSamples& s_out, const Directed& d_out, const TriangleBvh& bvh_in,
                     const EvalParams& params, unsigned threads, EvalResult& r);

}  // namespace quadlod::eval_detail
