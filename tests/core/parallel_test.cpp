// parallelRows: every row handed out exactly once in disjoint ranges, whatever the thread count and
// chunk; the first exception of any band rethrown on the caller, the rest of the rows abandoned;
// rows shared among the threads the system gives when it refuses some.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <mutex>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "conus/core/error.h"
#include "conus/core/parallel.h"

namespace {

// Per-row call counts and the ranges fn saw.
struct Coverage {
    std::vector<std::atomic<int>> hits;
    std::mutex mutex;
    std::vector<std::pair<int, int>> ranges;
    std::set<std::thread::id> threads;
    explicit Coverage(int rows) : hits(static_cast<std::size_t>(rows)) {}
    void operator()(int y0, int y1) {
        for (int y = y0; y < y1; ++y) hits[static_cast<std::size_t>(y)]++;
        std::lock_guard lock(mutex);
        ranges.emplace_back(y0, y1);
        threads.insert(std::this_thread::get_id());
    }
};

}  // namespace

TEST(ParallelRows, CoversEveryRowOnceInDisjointRanges) {
    for (const int rows : {0, 1, 7, 8, 9, 100, 1001})
        for (const int threads : {1, 2, 3, 8, 0})
            for (const int chunk : {1, 3, 8, 16, 2000}) {
                Coverage c(rows);
                conus::parallelRows(rows, threads, [&](int y0, int y1) { c(y0, y1); }, chunk);
                for (int y = 0; y < rows; ++y)
                    ASSERT_EQ(c.hits[static_cast<std::size_t>(y)], 1)
                        << "row " << y << " of " << rows << ", " << threads << " threads, chunk " << chunk;
                int covered = 0;
                for (const auto& [y0, y1] : c.ranges) {
                    EXPECT_LE(0, y0);
                    if (rows > 0) {
                        EXPECT_LT(y0, y1);  // no rows: one call over the empty range at most
                    }
                    EXPECT_LE(y1, rows);
                    // One thread or one chunk: a single call over the rows; else at most a chunk a call.
                    if (c.ranges.size() > 1) {
                        EXPECT_LE(y1 - y0, chunk);
                    }
                    covered += y1 - y0;
                }
                EXPECT_EQ(covered, rows);
                const int expectedThreads = std::min(conus::threadCount(threads), std::max(1, (rows + chunk - 1) / chunk));
                EXPECT_LE(static_cast<int>(c.threads.size()), expectedThreads);
            }
}

TEST(ParallelRows, RunsBandsOnSeveralThreadsAtOnce) {
    // Every band waits until two threads are inside fn together: with one thread this could not end
    // before the deadline.
    std::atomic<int> inside{0}, most{0};
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    conus::parallelRows(
        64, 2,
        [&](int, int) {
            const int now = ++inside;
            most = std::max(most.load(), now);
            while (most < 2 && std::chrono::steady_clock::now() < deadline) std::this_thread::yield();
            --inside;
        },
        8);
    EXPECT_EQ(most, 2);
}

TEST(ParallelRows, RethrowsTheFirstExceptionAndStopsHandingOutRows) {
    for (const int threads : {1, 2, 4}) {
        std::atomic<int> calls{0};
        try {
            conus::parallelRows(
                1000, threads,
                [&](int y0, int) {
                    ++calls;
                    if (y0 == 0) throw conus::Error(conus::ErrorCode::InvalidArgument, "row 0 is bad");
                    std::this_thread::sleep_for(std::chrono::milliseconds(1));  // the others are slow
                },
                1);
            ADD_FAILURE() << "no exception with " << threads << " threads";
        } catch (const conus::Error& e) {
            EXPECT_STREQ(e.what(), "row 0 is bad");
            EXPECT_EQ(e.code(), conus::ErrorCode::InvalidArgument);
        }
        // Row 0 is the first handed out: after its band throws, no new chunk starts.
        EXPECT_LT(calls, 100) << threads << " threads";
    }
}

TEST(ParallelRows, ReportsOneOfSeveralExceptions) {
    try {
        conus::parallelRows(
            64, 4, [](int y0, int) { throw std::runtime_error("band " + std::to_string(y0)); }, 8);
        FAIL() << "no exception";
    } catch (const std::runtime_error& e) {
        const std::string what = e.what();
        EXPECT_EQ(what.rfind("band ", 0), 0u) << what;
    }
}

// In a process whose address space cannot hold another thread's stack, std::thread throws;
// parallelRows then does every row on the calling thread. Exits 0 when it did.
[[noreturn]] void runWithThreadsRefused() {
    Coverage c(200);
    c.ranges.reserve(1000);
    long pages = 0;
    if (FILE* f = std::fopen("/proc/self/statm", "r")) {
        if (std::fscanf(f, "%ld", &pages) != 1) pages = 0;
        std::fclose(f);
    }
    if (pages == 0) _exit(3);
    rlimit limit{};
    getrlimit(RLIMIT_AS, &limit);
    limit.rlim_cur = static_cast<rlim_t>(pages) * static_cast<rlim_t>(sysconf(_SC_PAGESIZE)) + (1 << 20);
    if (setrlimit(RLIMIT_AS, &limit) != 0) _exit(4);
    conus::parallelRows(200, 4, [&](int y0, int y1) { c(y0, y1); }, 8);
    for (const auto& h : c.hits)
        if (h != 1) _exit(1);
    _exit(c.threads.size() == 1 ? 0 : 2);
}

TEST(ParallelRowsDeathTest, SharesTheRowsWhenTheSystemRefusesThreads) {
    // A fresh process (threadsafe style re-runs the binary): a forked one could reuse the stacks
    // glibc cached from the threads of the tests before, and never ask for a new one.
    GTEST_FLAG_SET(death_test_style, "threadsafe");
    EXPECT_EXIT(runWithThreadsRefused(), ::testing::ExitedWithCode(0), "");
}
