// tests/unit/test_parallel.cpp -- ffsr::detail::parallel_for and parallel_chunks: every index once,
// results independent of the thread count, in-order commits, progress, errors reach the caller.
#include <catch2/catch.hpp>

#include "ffsr/detail/parallel.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace test_parallel {

using ffsr::detail::parallel_chunks;
using ffsr::detail::parallel_for;
using ffsr::detail::ParallelOptions;

TEST_CASE("parallel_for: every index is visited once, for any thread count and chunk", "[parallel]") {
  for (unsigned threads : {1u, 2u, 4u, 7u})
    for (std::uint64_t chunk : {1u, 3u, 64u, 5000u}) {
      std::vector<std::atomic<int>> visits(1001);
      ParallelOptions o;
      o.chunk = chunk;
      parallel_for(
          visits.size(), threads, [&](std::uint64_t i) { visits[i].fetch_add(1); }, o);
      int wrong = 0;
      for (const auto& v : visits) wrong += v.load() != 1;
      INFO("threads " << threads << ", chunk " << chunk);
      CHECK(wrong == 0);
    }
  int calls = 0;
  parallel_for(0, 4, [&](std::uint64_t) { ++calls; });  // nothing to do: no call
  CHECK(calls == 0);
}

TEST_CASE("parallel_for: the same bits on 1 and 4 threads", "[parallel]") {
  // a per-index value and a per-chunk sum folded in chunk order by commit: both must not depend on
  // the thread count (floating-point sums do depend on the order of the terms)
  auto run = [](unsigned threads) {
    std::vector<double> value(20000), chunk_sum(20000);
    double total = 0;
    ParallelOptions o;
    o.chunk = 128;
    o.commit = [&](unsigned, std::uint64_t lo, std::uint64_t) { total += chunk_sum[lo]; };
    parallel_chunks(
        value.size(), threads,
        [&](unsigned, std::uint64_t lo, std::uint64_t hi) {
          for (std::uint64_t i = lo; i < hi; ++i) {
            value[i] = std::sin(0.001 * double(i)) / (1.0 + double(i));
            chunk_sum[lo] += value[i];
          }
        },
        o);
    return std::make_pair(value, total);
  };
  const auto one = run(1), four = run(4);
  CHECK(one.first == four.first);
  CHECK(one.second == four.second);  // exact: the same sums in the same order
}

TEST_CASE("parallel_chunks: commits run in chunk order, by the worker that did the chunk", "[parallel]") {
  std::vector<unsigned> owner(100, 99);
  std::vector<std::uint64_t> committed;
  bool right_worker = true;
  ParallelOptions o;
  o.chunk = 7;
  o.commit = [&](unsigned worker, std::uint64_t lo, std::uint64_t hi) {
    committed.push_back(lo);
    for (std::uint64_t i = lo; i < hi; ++i) right_worker = right_worker && owner[i] == worker;
  };
  parallel_chunks(
      owner.size(), 4,
      [&](unsigned worker, std::uint64_t lo, std::uint64_t hi) {
        CHECK(worker < 4);
        for (std::uint64_t i = lo; i < hi; ++i) owner[i] = worker;
      },
      o);
  std::vector<std::uint64_t> expected;
  for (std::uint64_t lo = 0; lo < 100; lo += 7) expected.push_back(lo);
  CHECK(committed == expected);
  CHECK(right_worker);
}

TEST_CASE("parallel_for: a worker's exception reaches the caller (the lowest failing index)", "[parallel]") {
  for (unsigned threads : {1u, 4u}) {
    INFO("threads " << threads);
    try {
      parallel_for(1000, threads, [](std::uint64_t i) {
        if (i == 37) throw std::runtime_error("index 37");
      });
      FAIL("no exception");
    } catch (const std::runtime_error& e) {
      CHECK(std::string(e.what()) == "index 37");
    }
    // several failures: the lowest index is reported (the chunks below a failed one still run)
    try {
      parallel_for(1000, threads, [](std::uint64_t i) {
        if (i % 100 == 30) throw std::runtime_error("index " + std::to_string(i));
      });
      FAIL("no exception");
    } catch (const std::runtime_error& e) {
      CHECK(std::string(e.what()) == "index 30");
    }
  }
  // an exception in a commit is reported too, and stops chunks waiting for their turn
  ParallelOptions o;
  o.commit = [](unsigned, std::uint64_t lo, std::uint64_t) {
    if (lo == 5) throw std::logic_error("commit 5");
  };
  CHECK_THROWS_AS(parallel_for(
                      50, 4, [](std::uint64_t) {}, o),
                  std::logic_error);
}

TEST_CASE("parallel_for: progress ends with the count, on the calling thread", "[parallel]") {
  std::vector<std::uint64_t> reports;
  const auto caller = std::this_thread::get_id();
  bool on_caller = true;
  ParallelOptions o;
  o.progress = [&](std::uint64_t done) {
    reports.push_back(done);
    on_caller = on_caller && std::this_thread::get_id() == caller;
  };
  o.progress_every = std::chrono::milliseconds(1);
  std::atomic<std::uint64_t> sum{0};
  parallel_for(
      3000, 2, [&](std::uint64_t i) { sum += i; }, o);
  CHECK(sum.load() == 3000ull * 2999ull / 2);
  REQUIRE(!reports.empty());
  CHECK(reports.back() == 3000);
  CHECK(std::is_sorted(reports.begin(), reports.end()));
  CHECK(on_caller);
}

}  // namespace test_parallel
