// Deterministic fork-join over an index range: the work is split into contiguous chunks, one
// per thread, and every caller merges the chunks' results in chunk order, so what a parallel
// stage computes does not depend on the number of threads (issue 20: "threads change only the
// speed"). No pool: a stage forks once per call, on ranges of tens of thousands of items.
#pragma once

#include <algorithm>
#include <cstddef>
#include <exception>
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

namespace quadlod {

/// Runs `beside` on a second thread while `work` runs on the calling thread, when `threads`
/// allows more than one and `overlap` is true; otherwise `work`, then `beside`. For independent
/// computations (each reads only what both share and writes only its own results), so what they
/// compute does not depend on which way they ran. An exception thrown by `beside` is rethrown
/// here after both finished.
template <class Work, class Beside>
void run_beside(int threads, bool overlap, Work&& work, Beside&& beside) {
  if (!overlap || thread_count(threads) < 2) {
    work();
    beside();
    return;
  }
  std::exception_ptr failed;
  std::thread side([&] {
    try {
      beside();
    } catch (...) {
      failed = std::current_exception();
    }
  });
  try {
    work();
  } catch (...) {
    side.join();
    throw;
  }
  side.join();
  if (failed) std::rethrow_exception(failed);
}

}  // namespace quadlod
