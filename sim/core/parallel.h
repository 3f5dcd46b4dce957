// The one wrapper every parallel loop goes through (house style 8).
// Work is split into fixed chunks of `grain` items; how TBB schedules the chunks
// never changes what a loop computes, so results do not depend on the thread count.
#pragma once
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cstddef>
#include <memory>
#include <vector>

namespace shellmpm {

/// Runs body(begin, end) over [0, n) in chunks of at most `grain` items.
/// With `serial` true the chunks run in order on the calling thread.
template <class Body>
void parallel_for(std::size_t n, std::size_t grain, Body&& body, bool serial = false) {
  if (n == 0) return;
  grain = std::max<std::size_t>(grain, 1);
  if (serial || n <= grain) {
    for (std::size_t b = 0; b < n; b += grain) body(b, std::min(n, b + grain));
    return;
  }
  const std::size_t chunks = (n + grain - 1) / grain;
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, chunks, 1),
      [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t c = r.begin(); c != r.end(); ++c)
          body(c * grain, std::min(n, (c + 1) * grain));
      },
      tbb::simple_partitioner());
}

/// Runs body(i) for each i in [0, n), chunked by `grain`.
template <class Body>
void parallel_for_each(std::size_t n, std::size_t grain, Body&& body, bool serial = false) {
  parallel_for(
      n, grain,
      [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) body(i);
      },
      serial);
}

/// The deterministic reduction every parallel sum, maximum or list goes through: runs
/// chunk(b, e, part) for each chunk [b, e) of `grain` items, each on its own `part` (a
/// copy of `zero`), and returns the parts in chunk order, for the caller to merge in
/// that order: the same result for any thread count.
template <class T, class Chunk>
std::vector<T> chunk_parts(std::size_t n, std::size_t grain, bool serial, const T& zero,
                           Chunk&& chunk) {
  grain = std::max<std::size_t>(grain, 1);
  std::vector<T> part((n + grain - 1) / grain, zero);
  parallel_for(
      n, grain, [&](std::size_t b, std::size_t e) { chunk(b, e, part[b / grain]); }, serial);
  return part;
}

/// Combines chunk(b, e), the partial result of each chunk [b, e) of `grain` items, in
/// chunk order starting from `zero` (chunk_parts). T needs operator+=.
template <class T, class Chunk>
T ordered_reduce_chunks(std::size_t n, std::size_t grain, bool serial, const T& zero,
                        Chunk&& chunk) {
  const std::vector<T> part = chunk_parts(
      n, grain, serial, zero, [&](std::size_t b, std::size_t e, T& out) { out = chunk(b, e); });
  T total = zero;
  for (const T& v : part) total += v;
  return total;
}

/// Sums f(i) over [0, n): each chunk of `grain` items from `zero` in index order, then
/// the chunk sums in chunk order (ordered_reduce_chunks).
template <class T, class F>
T ordered_reduce(std::size_t n, std::size_t grain, bool serial, const T& zero, F&& f) {
  return ordered_reduce_chunks(n, grain, serial, zero, [&](std::size_t b, std::size_t e) {
    T acc = zero;
    for (std::size_t i = b; i < e; ++i) acc += f(i);
    return acc;
  });
}

/// Limits TBB to `threads` workers for the lifetime of this object (0 = all cores).
class ThreadLimit {
 public:
  explicit ThreadLimit(int threads) {
    if (threads > 0)
      control_ = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                       static_cast<std::size_t>(threads));
  }
  /// The number of threads TBB may use now.
  static int active() {
    return static_cast<int>(
        tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
  }

 private:
  std::unique_ptr<tbb::global_control> control_;
};

}  // namespace shellmpm
