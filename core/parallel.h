#pragma once
// Threads over independent parts of one job: each worker gets its index and the worker count,
// and chooses its share (a range of cells, nodes or slices) from them.
#include <algorithm>
#include <cstddef>
#include <thread>
#include <utility>
#include <vector>

namespace naris {

// `requested` threads when positive, else one per core.
inline unsigned thread_count(int requested) {
  return requested > 0 ? static_cast<unsigned>(requested)
                       : std::max(1u, std::thread::hardware_concurrency());
}

// Runs work(t, threads) for t = 0 .. threads−1, on the calling thread when there is one.
template <class F>
void run_threads(unsigned threads, F&& work) {
  if (threads <= 1) {
    work(0u, 1u);
    return;
  }
  std::vector<std::thread> pool;
  pool.reserve(threads);
  for (unsigned t = 0; t < threads; ++t)
    pool.emplace_back([&work, t, threads] { work(t, threads); });
  for (auto& p : pool) p.join();
}

// Part t of `threads` nearly equal parts of [0, n).
inline std::pair<std::size_t, std::size_t> share(std::size_t n, unsigned t, unsigned threads) {
  return {n * t / threads, n * (t + 1) / threads};
}

}  // namespace naris
