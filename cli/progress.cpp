#include "progress.h"

#include <unistd.h>

#include <CLI/CLI.hpp>

#include <atomic>
#include <cstdio>
#include <exception>
#include <mutex>

namespace conus::cli {
namespace {
std::mutex g_printMutex;  // progress callbacks arrive from worker threads
bool g_quiet = false;             // -q, read by CLI11
std::atomic<bool> g_silenced{false};  // setQuiet: a batch runs its items quiet
std::atomic<int> g_stages{0};
std::string g_command;
const auto g_started = std::chrono::steady_clock::now();
}  // namespace

void addQuietOption(CLI::App& command) {
    command.add_flag("-q,--quiet", g_quiet, "print no progress (warnings and errors still print)");
}

bool quiet() { return g_quiet || g_silenced; }

void setQuiet(bool silenced) { g_silenced = silenced; }

void report(const std::string& text) {
    std::lock_guard lock(g_printMutex);
    std::fprintf(stderr, "%sconus %s: %s\n", ::isatty(STDERR_FILENO) ? "\r\033[K" : "", g_command.c_str(), text.c_str());
}

void liveLine(const std::string& text) {
    if (g_quiet || !::isatty(STDERR_FILENO)) return;
    std::lock_guard lock(g_printMutex);
    std::fprintf(stderr, "\r\033[Kconus %s: %s", g_command.c_str(), text.c_str());
    std::fflush(stderr);
}

Progress::Progress(std::string label)
    : m_label(std::move(label)), m_tty(::isatty(STDERR_FILENO) != 0), m_start(std::chrono::steady_clock::now()) {
    if (!quiet() && m_tty) std::fprintf(stderr, "conus %s: %s ...", g_command.c_str(), m_label.c_str());
}

Progress::~Progress() {
    if (m_finished) return;
    if (std::uncaught_exceptions() > 0) {
        // Unwinding from an error: the stage did not finish; main prints the reason.
        if (!quiet() && m_tty) std::fprintf(stderr, "\n");
        return;
    }
    done();
}

ProgressFn Progress::callback() {
    if (quiet() || !m_tty) return {};
    return [this](double fraction) {
        const int percent = static_cast<int>(fraction * 100.0);
        std::lock_guard lock(g_printMutex);
        if (percent <= m_lastPercent) return;
        m_lastPercent = percent;
        std::fprintf(stderr, "\rconus %s: %s %3d%%", g_command.c_str(), m_label.c_str(), percent);
        std::fflush(stderr);
    };
}

void Progress::done() {
    if (m_finished) return;
    m_finished = true;
    ++g_stages;
    if (quiet()) return;
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - m_start).count();
    std::lock_guard lock(g_printMutex);
    std::fprintf(stderr, "%sconus %s: %s done (%.2f s)\n", m_tty ? "\r" : "", g_command.c_str(), m_label.c_str(), seconds);
}

void beginCommand(const std::string& name) { g_command = name; }

void printTotal() {
    if (quiet() || g_stages < 2) return;
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - g_started).count();
    std::fprintf(stderr, "conus %s: done in %.2f s (%d stages)\n", g_command.c_str(), seconds, g_stages.load());
}

void warn(const std::string& text) {
    std::lock_guard lock(g_printMutex);
    std::fprintf(stderr, "conus %s: warning: %s\n", g_command.c_str(), text.c_str());
}

std::string plural(std::size_t n, const char* one, const char* many) {
    return std::to_string(n) + " " + (n == 1 ? one : many);
}

}  // namespace conus::cli
