// Deterministic fork-join over an index range: the work is split into contiguous chunks, one
// per thread, and every caller merges the chunks' results in chunk order, so what a parallel
// stage computes does not depend on the number of threads (issue 20: "threads change only the
// speed"). No pool: a stage forks once per call, on ranges of tens of thousands of items.
#pragma once

#include <algorithm>
#include <atomic>
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

/// Runs work(begin, end, worker) over [0, n) split into contiguous chunks of about equal total
/// weight (weight(i) ≥ 0: the work of item i), chunks_per_thread of them per thread, which the
/// threads take in turn as they finish (worker 0 is the calling thread). For items of very
/// unequal cost, where equal-length chunks leave one thread waiting for the other: the first
/// pricing of the shape greedy has its ~2000 segment moves of 500 edges each at the front and
/// 2M single edges behind them (1M grid, issue 20). Which worker runs a chunk varies from run to
/// run: the work must write only its chunk's results (per-worker scratch is fine). One chunk on
/// the calling thread when n < min_parallel.
template <class Weight, class Work>
void parallel_weighted_chunks(std::size_t n, int threads, std::size_t min_parallel, std::size_t chunks_per_thread,
                              Weight&& weight, Work&& work) {
  const std::size_t t = n < min_parallel ? 1 : std::max<std::size_t>(1, std::min(thread_count(threads), n));
  if (t == 1) {
    work(std::size_t{0}, n, std::size_t{0});
    return;
  }
  double total = 0.0;
  for (std::size_t i = 0; i < n; ++i) total += weight(i);
  const std::size_t k = t * std::max<std::size_t>(1, chunks_per_thread);
  std::vector<std::size_t> bounds{0};
  double sum = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    sum += weight(i);
    if (sum >= total * double(bounds.size()) / double(k) && bounds.size() < k) bounds.push_back(i + 1);
  }
  if (bounds.back() != n) bounds.push_back(n);
  std::atomic<std::size_t> next = 0;
  auto run = [&](std::size_t worker) {
    for (std::size_t c = next++; c + 1 < bounds.size(); c = next++) work(bounds[c], bounds[c + 1], worker);
  };
  std::vector<std::thread> pool;
  for (std::size_t w = 1; w < t; ++w) pool.emplace_back(run, w);
  run(0);
  for (std::thread& th : pool) th.join();
}

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
