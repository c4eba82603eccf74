// ffsr/detail/parallel.hpp -- the one thread pool of ffsr: indices [0, count) in fixed chunks on a
// few threads, with per-thread workspaces, an optional in-order commit and progress reports.
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <functional>
#include <limits>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

// Determinism. The chunk boundaries depend on `count` and `options.chunk` only, never on the
// number of threads: chunk c is [c * chunk, min(count, (c + 1) * chunk)). The threads take chunks
// from an atomic counter, in increasing order. So
//   - work that writes the result of index i into slot i gives the same bits for any thread count;
//   - work that reduces (sums, appends text) keeps one partial result per chunk, or writes it in
//     `options.commit`, which runs chunk after chunk in index order: the same bits again.
//
// Errors. An exception thrown by `work` or `commit` stops the run: chunks above the failed one are
// not started (chunks below it, already handed out, still run their `work`, so the failure of the
// lowest index is the one reported, whatever the thread count), commits stop, the threads are
// joined, and the exception of the lowest failing chunk is rethrown on the calling thread.
//
// Progress. `options.progress`, if set, is called on the calling thread with the number of indices
// done (worked and committed) about every `options.progress_every`, and once at the end with
// `count` when nothing failed.
//
// The two loops of the code base in this form (a sketch):
//   // one value per index (uncertainty sampling)
//   detail::parallel_for(n, threads, [&](std::uint64_t i) { out[i] = f(i); });
//   // a CSV written in order by per-thread workers (the map subcommand)
//   detail::ParallelOptions opt;
//   opt.chunk = kBlock;
//   opt.commit = [&](unsigned t, std::uint64_t, std::uint64_t) { file.write(workers[t]->text); };
//   opt.progress = [&](std::uint64_t done) { progress(done, count); };
//   opt.progress_every = std::chrono::milliseconds(200);
//   detail::parallel_chunks(count, threads,
//                           [&](unsigned t, std::uint64_t lo, std::uint64_t hi) { workers[t]->run(lo, hi); },
//                           opt);

namespace ffsr::detail {

/// The work on one chunk: `worker` in [0, threads) names the thread (an index into per-thread
/// workspaces; a worker runs one chunk at a time), [lo, hi) the indices.
using ChunkWork = std::function<void(unsigned worker, std::uint64_t lo, std::uint64_t hi)>;

struct ParallelOptions {
  std::uint64_t chunk = 1;  ///< indices per chunk (0 is taken as 1)
  /// If set: called after `work` on each chunk, one chunk at a time and in chunk order, by the
  /// worker that did the chunk (so it may read that worker's workspace).
  ChunkWork commit;
  /// If set: called on the calling thread with the number of indices done.
  std::function<void(std::uint64_t done)> progress;
  std::chrono::milliseconds progress_every{50};
};

/// Runs work(worker, lo, hi) over the chunks of [0, count) on at most `threads` threads (0 is
/// taken as 1). One thread and no progress: everything runs on the calling thread. See the top of
/// this file for the order, the errors and the progress reports.
inline void parallel_chunks(std::uint64_t count, unsigned threads, const ChunkWork& work,
                            const ParallelOptions& options = {});

/// Runs fn(i) for every i in [0, count), each index once, on at most `threads` threads; the
/// chunks, commit and progress of `options` as in parallel_chunks.
template <class Fn>
inline void parallel_for(std::uint64_t count, unsigned threads, Fn&& fn,
                         const ParallelOptions& options = {}) {
  parallel_chunks(
      count, threads,
      [&fn](unsigned, std::uint64_t lo, std::uint64_t hi) {
        for (std::uint64_t i = lo; i < hi; ++i) fn(i);
      },
      options);
}

namespace parallel_impl {

/// What the threads share: the chunk counter, the commit turn, the first error.
struct Shared {
  std::uint64_t count, chunk, chunks;
  const ChunkWork& work;
  const ParallelOptions& options;
  std::atomic<std::uint64_t> next{0}, done{0};
  std::atomic<bool> stop{false};
  std::mutex mutex;
  std::condition_variable changed;
  std::uint64_t next_commit = 0;  ///< the chunk whose commit is due
  unsigned running = 0;           ///< threads not yet finished
  std::exception_ptr error;
  std::atomic<std::uint64_t> error_chunk{std::numeric_limits<std::uint64_t>::max()};

  Shared(std::uint64_t n, std::uint64_t c, const ChunkWork& w, const ParallelOptions& o)
      : count(n), chunk(c), chunks((n + c - 1) / c), work(w), options(o) {}

  /// Records the exception being handled (kept if its chunk is the lowest so far) and stops.
  void fail(std::uint64_t c) {
    std::lock_guard<std::mutex> lock(mutex);
    if (c < error_chunk) {
      error_chunk = c;
      error = std::current_exception();
    }
    stop = true;
    changed.notify_all();
  }

  /// Waits for chunk c's turn and commits it; false when the run stopped meanwhile.
  bool commit(unsigned worker, std::uint64_t c, std::uint64_t lo, std::uint64_t hi) {
    std::unique_lock<std::mutex> lock(mutex);
    changed.wait(lock, [&] { return next_commit == c || stop.load(); });
    if (stop.load()) return false;
    options.commit(worker, lo, hi);
    ++next_commit;
    changed.notify_all();
    return true;
  }

  /// One thread: takes chunks until none is left or the run stopped.
  void run(unsigned worker) {
    for (;;) {
      const std::uint64_t c = next.fetch_add(1);
      if (c >= chunks || c > error_chunk.load()) break;  // chunks below a failed one still run
      const std::uint64_t lo = c * chunk, hi = std::min(count, lo + chunk);
      try {
        work(worker, lo, hi);
        if (options.commit && !commit(worker, c, lo, hi)) break;
      } catch (...) {
        fail(c);
        break;
      }
      done.fetch_add(hi - lo);
    }
    std::lock_guard<std::mutex> lock(mutex);
    --running;
    changed.notify_all();
  }

  /// The calling thread while the workers run: progress reports until all have finished.
  void watch() {
    std::unique_lock<std::mutex> lock(mutex);
    while (running > 0) {
      changed.wait_for(lock, options.progress_every, [&] { return running == 0; });
      if (running == 0 || stop.load()) continue;
      lock.unlock();
      options.progress(done.load());
      lock.lock();
    }
  }
};

}  // namespace parallel_impl

inline void parallel_chunks(std::uint64_t count, unsigned threads, const ChunkWork& work,
                            const ParallelOptions& options) {
  if (count == 0) return;
  parallel_impl::Shared s(count, std::max<std::uint64_t>(1, options.chunk), work, options);
  const unsigned nt = static_cast<unsigned>(std::min<std::uint64_t>(std::max(1u, threads), s.chunks));
  s.running = nt;
  if (nt == 1 && !options.progress) {
    s.run(0);
  } else {
    std::vector<std::thread> pool;
    try {
      for (unsigned t = 0; t < nt; ++t) pool.emplace_back([&s, t] { s.run(t); });
    } catch (...) {  // no thread for the rest: stop the others, then report why
      {
        std::lock_guard<std::mutex> lock(s.mutex);
        s.stop = true;
        s.changed.notify_all();
      }
      for (auto& t : pool) t.join();
      throw;
    }
    if (options.progress) s.watch();
    for (auto& t : pool) t.join();
    if (options.progress && !s.error) options.progress(s.done.load());
  }
  if (s.error) std::rethrow_exception(s.error);
}

}  // namespace ffsr::detail
