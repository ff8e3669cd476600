#include "progress.h"

#include <unistd.h>

#include <cstdio>
#include <exception>
#include <mutex>

namespace conus::cli {
namespace {
std::mutex g_printMutex;  // progress callbacks arrive from worker threads
}

Progress::Progress(std::string label, bool quiet)
    : m_label(std::move(label)), m_quiet(quiet), m_tty(::isatty(STDERR_FILENO) != 0),
      m_start(std::chrono::steady_clock::now()) {
    if (!m_quiet && m_tty) std::fprintf(stderr, "%s ...", m_label.c_str());
}

Progress::~Progress() {
    if (m_finished) return;
    if (std::uncaught_exceptions() > 0) {
        // Unwinding from an error: the step did not finish; main prints the reason.
        if (!m_quiet && m_tty) std::fprintf(stderr, "\n");
        return;
    }
    done();
}

ProgressFn Progress::callback() {
    if (m_quiet || !m_tty) return {};
    return [this](double fraction) {
        const int percent = static_cast<int>(fraction * 100.0);
        std::lock_guard lock(g_printMutex);
        if (percent <= m_lastPercent) return;
        m_lastPercent = percent;
        std::fprintf(stderr, "\r%s %3d%%", m_label.c_str(), percent);
        std::fflush(stderr);
    };
}

void Progress::done() {
    if (m_finished) return;
    m_finished = true;
    if (m_quiet) return;
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - m_start).count();
    std::lock_guard lock(g_printMutex);
    std::fprintf(stderr, "%s%s done (%.2f s)\n", m_tty ? "\r" : "", m_label.c_str(), seconds);
}

}  // namespace conus::cli
