// Deterministic fork-join over an index range: the work is split into contiguous chunks, one
// per thread, and every caller merges the chunks' results in chunk order, so what a parallel
// stage computes does not depend on the number of threads (issue 20: "threads change only the
// speed"). No pool: a stage forks once per call, on ranges of tens of thousands of items.
#pragma once

#include <algorithm>
#include <cstddef>
#include <thread>
#include <vector>

namespace quadlod {

/// Threads for a `threads` option: > 0 as given, 0 = every core.
inline std::size_t thread_count(int threads) {
  return threads > 0 ? std::size_t(threads) : std::max(1u, std::thread::hardware_concurrency());
}

/// Runs work(begin, end, chunk) over [0, n) in at most thread_count(threads) contiguous chunks
/// numbered 0, 1, …; chunk 0 runs on the calling thread. One chunk when n < min_parallel (a
/// thread costs more than it saves on a small mesh). Returns the number of chunks.
template <class Work>
std::size_t parallel_chunks(std::size_t n, int threads, std::size_t min_parallel, Work&& work) {
  std::size_t t = n < min_parallel ? 1 : thread_count(threads);
  t = std::max<std::size_t>(1, std::min(t, n));
  const std::size_t chunk = (n + t - 1) / std::max<std::size_t>(1, t);
  std::vector<std::thread> pool;
  for (std::size_t k = 1; k < t; ++k)
    pool.emplace_back([&, k] { work(std::min(n, k * chunk), std::min(n, (k + 1) * chunk), k); });
  work(0, std::min(n, chunk), std::size_t{0});
  for (std::thread& th : pool) th.join();
  return t;
}

}  // namespace quadlod
