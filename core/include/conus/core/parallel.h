// Rows split across threads, for every per-pixel loop of CoNUS (codec's encode and decode, the
// viewer's CPU frames). Work is handed out in small chunks so that rows of uneven cost (a focus in
// the middle of the image) keep every core busy; the first exception thrown by any band is
// rethrown on the calling thread once all have stopped.
#pragma once

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <system_error>
#include <thread>
#include <vector>

#include "conus/core/check.h"

namespace conus {

inline int threadCount(int requested) {
    if (requested > 0) return requested;
    return std::max(1u, std::thread::hardware_concurrency());
}

// Calls fn(y0, y1) for disjoint row ranges covering [0, rows). Rethrows the first exception. Where
// the system gives fewer threads than asked, the rows are shared among those it gives.
template <typename Fn>
void parallelRows(int rows, int threads, Fn&& fn, int chunk = 8) {
    CONUS_DCHECK_GE(chunk, 1);  // a chunk of 0 rows would hand out the same rows forever
    const int n = std::min(threadCount(threads), std::max(1, (rows + chunk - 1) / chunk));
    if (n <= 1) {
        fn(0, rows);
        return;
    }
    std::atomic<int> next{0};
    std::exception_ptr error;
    std::mutex errorMutex;
    auto worker = [&] {
        try {
            for (int y0; (y0 = next.fetch_add(chunk)) < rows;) fn(y0, std::min(rows, y0 + chunk));
        } catch (...) {
            std::lock_guard lock(errorMutex);
            if (!error) error = std::current_exception();
            next = rows;
        }
    };
    std::vector<std::thread> pool;
    pool.reserve(n - 1);
    for (int t = 1; t < n; ++t) {
        try {
            pool.emplace_back(worker);
        } catch (const std::system_error&) {
            break;  // no more threads to be had: the ones started and this one share the rows
        }
    }
    worker();
    for (auto& t : pool) t.join();
    if (error) std::rethrow_exception(error);
}

}  // namespace conus
