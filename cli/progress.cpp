#include "progress.h"

#include <time.h>
#include <unistd.h>

#include <CLI/CLI.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <exception>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>

namespace conus::cli {
namespace {
std::mutex g_printMutex;  // progress callbacks arrive from worker threads
bool g_quiet = false;             // -q, read by CLI11
std::atomic<bool> g_silenced{false};  // setQuiet: a batch runs its items quiet
std::atomic<int> g_stages{0};
std::string g_command;
std::map<std::string, std::size_t> g_batchWarnings;  // a batch's warnings, and how many items gave each
const auto g_started = std::chrono::steady_clock::now();
double g_startUp = 0;       // seconds from the process's start to the command's
double g_stageSeconds = 0;  // the finished stages', under g_printMutex

// Seconds since the process started (the kernel's start time, 10 ms ticks): the loading of the
// shared libraries included, which happens before any of our code runs.
double sinceProcessStart() {
    std::ifstream stat("/proc/self/stat");
    std::string text;
    std::getline(stat, text);
    const std::size_t close = text.rfind(')');
    timespec now{};
    if (close != std::string::npos && ::clock_gettime(CLOCK_BOOTTIME, &now) == 0) {
        std::istringstream fields(text.substr(close + 2));
        std::string field;
        for (int i = 3; i <= 22 && fields >> field; ++i)
            if (i == 22) return now.tv_sec + now.tv_nsec * 1e-9 - std::stod(field) / double(::sysconf(_SC_CLK_TCK));
    }
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - g_started).count();
}
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

void Progress::show(const std::string& shown, double fraction) {
    const int percent = static_cast<int>(fraction * 100.0);
    if (percent <= m_lastPercent) return;
    m_lastPercent = percent;
    std::fprintf(stderr, "\r\033[Kconus %s: %s %3d%%", g_command.c_str(), shown.c_str(), percent);
    std::fflush(stderr);
}

ProgressFn Progress::callback() {
    if (quiet() || !m_tty) return {};
    return [this](double fraction) {
        std::lock_guard lock(g_printMutex);
        show(m_label, fraction);
    };
}

ProgressFn Progress::steps(std::string step) {
    if (quiet() || !m_tty) return {};
    return [this, step = std::move(step)](double fraction) {
        std::lock_guard lock(g_printMutex);
        if (fraction == 0.0) {
            ++m_step;
            m_lastPercent = -1;
        }
        show(m_label + ": " + step + " " + std::to_string(m_step), fraction);
    };
}

void Progress::done() {
    if (m_finished) return;
    m_finished = true;
    ++g_stages;
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - m_start).count();
    std::lock_guard lock(g_printMutex);
    g_stageSeconds += seconds;
    if (quiet()) return;
    std::fprintf(stderr, "%sconus %s: %s done (%.2f s)\n", m_tty ? "\r\033[K" : "", g_command.c_str(), m_label.c_str(), seconds);
}

void beginCommand(const std::string& name) {
    g_command = name;
    g_startUp = sinceProcessStart();
}

const std::string& commandName() { return g_command; }

void printTotal() {
    if (quiet() || g_stages < 2) return;
    const double total = sinceProcessStart();
    std::lock_guard lock(g_printMutex);
    // Rounded so that the parts add up to the total as printed.
    const double whole = std::round(total * 100) / 100, staged = std::round(g_stageSeconds * 100) / 100,
                 start = std::round(g_startUp * 100) / 100;
    std::fprintf(stderr,
                 "conus %s: done in %.2f s: %d stages %.2f s, start-up %.2f s, outside the stages %.2f s (loading "
                 "OpenImageIO or GL on first use, choosing the backend)\n",
                 g_command.c_str(), whole, g_stages.load(), staged, start, std::max(0.0, whole - staged - start));
}

void warn(const std::string& text) {
    std::lock_guard lock(g_printMutex);
    if (g_silenced && ++g_batchWarnings[text] > 1) return;
    std::fprintf(stderr, "%sconus %s: warning: %s\n", ::isatty(STDERR_FILENO) ? "\r\033[K" : "", g_command.c_str(), text.c_str());
}

void reportRepeatedWarnings(std::size_t inputs) {
    std::lock_guard lock(g_printMutex);
    for (const auto& [text, count] : g_batchWarnings)
        if (count > 1)
            std::fprintf(stderr, "conus %s: the warning \"%.60s%s\" held for %zu of %zu inputs (printed once)\n",
                         g_command.c_str(), text.c_str(), text.size() > 60 ? "..." : "", count, inputs);
    g_batchWarnings.clear();
}

std::string plural(std::size_t n, const char* one, const char* many) {
    return std::to_string(n) + " " + (n == 1 ? one : many);
}

}  // namespace conus::cli
