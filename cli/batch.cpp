#include "batch.h"

#include <unistd.h>

#include <csignal>
#include <cstring>

#include <CLI/CLI.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <mutex>
#include <thread>

#include "conus/core/atomic_file.h"
#include "conus/core/error.h"
#include "output_files.h"
#include "progress.h"

namespace conus::cli {
namespace {

namespace fs = std::filesystem;

// A list is a regular file (a FIFO or /dev/zero could be read forever) or standard input, and at
// most kMaxListBytes: a list that long names a million files.
constexpr std::size_t kMaxListBytes = 64 << 20;

std::vector<std::string> readList(const std::string& listFile) {
    std::ifstream file;
    if (listFile != "-") {
        checkInputPath(listFile);
        file.open(listFile, std::ios::binary);
        if (!file) throw Error(ErrorCode::Io, "cannot read the list " + listFile);
    }
    std::istream& in = listFile == "-" ? std::cin : file;
    const auto tooLong = [&] {
        return Error(ErrorCode::LimitExceeded, "the list " + listFile + " is longer than " + std::to_string(kMaxListBytes) +
                                                   " bytes or has a line of over 4096");
    };
    // Read in blocks, never a line at a time: a stream without a newline (/dev/zero) would make
    // one line of any length.
    std::string text;
    char block[1 << 16];
    while (in.read(block, sizeof block) || in.gcount() > 0) {
        text.append(block, std::size_t(in.gcount()));
        if (text.size() > kMaxListBytes) throw tooLong();
    }
    std::vector<std::string> inputs;
    std::size_t start = 0;
    while (start < text.size()) {
        const std::size_t end = std::min(text.find('\n', start), text.size());
        std::string line = text.substr(start, end - start);
        start = end + 1;
        if (line.size() > 4096) throw tooLong();
        while (!line.empty() && (line.back() == '\r' || line.back() == ' ' || line.back() == '\t')) line.pop_back();
        const std::size_t first = line.find_first_not_of(" \t");
        if (first == std::string::npos || line[first] == '#') continue;  // blank lines and comments
        inputs.push_back(line.substr(first));
    }
    return inputs;
}

std::string replaceAll(std::string text, const std::string& from, const std::string& to) {
    for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
        text.replace(at, from.size(), to);
    return text;
}

std::string outputName(const std::string& pattern, const std::string& input, std::size_t index) {
    const fs::path path(input);
    std::string ext = path.extension().string();
    if (!ext.empty()) ext.erase(0, 1);
    std::string name = replaceAll(pattern, "{stem}", path.stem().string());
    name = replaceAll(name, "{name}", path.filename().string());
    name = replaceAll(name, "{ext}", ext);
    return replaceAll(name, "{index}", std::to_string(index));
}

std::string clock(double seconds) {
    const long s = std::lround(std::max(0.0, seconds));
    char text[32];
    if (s >= 3600) std::snprintf(text, sizeof text, "%ld:%02ld:%02ld", s / 3600, s / 60 % 60, s % 60);
    else std::snprintf(text, sizeof text, "%ld:%02ld", s / 60, s % 60);
    return text;
}

// What an interrupted batch says (Ctrl-C, SIGTERM, SIGHUP): the handler may only write(2), so the
// line is kept current in one of two buffers under the batch's mutex and the handler writes the
// latest, then runs the handler it replaced (core's: remove the temporaries, die by the signal).
constexpr int kSignals[] = {SIGINT, SIGTERM, SIGHUP};
char g_note[2][320];
std::atomic<int> g_latest{0};
struct sigaction g_replaced[std::size(kSignals)];

extern "C" void noteInterruption(int signal) {
    const char* note = g_note[g_latest.load()];
    [[maybe_unused]] const ssize_t written = ::write(STDERR_FILENO, note, std::strlen(note));
    for (std::size_t i = 0; i < std::size(kSignals); ++i)
        if (kSignals[i] == signal && g_replaced[i].sa_handler != SIG_DFL && g_replaced[i].sa_handler != SIG_IGN &&
            g_replaced[i].sa_handler != nullptr) {
            g_replaced[i].sa_handler(signal);
            return;
        }
    std::signal(signal, SIG_DFL);
    std::raise(signal);
}

// Under the batch's mutex: the note for `done` of `total` finished.
void setInterruptionNote(const std::string& command, std::size_t done, std::size_t total) {
    const int next = 1 - g_latest.load();
    std::snprintf(g_note[next], sizeof g_note[next],
                  "%sconus %s: interrupted: %zu done, %zu left (no partial output is left behind); run again with "
                  "--skip-existing to finish\n",
                  ::isatty(STDERR_FILENO) ? "\r\033[K" : "", command.c_str(), done, total - done);
    g_latest = next;
}

class InterruptionNote {
public:
    InterruptionNote() {
        struct sigaction action {};
        action.sa_handler = &noteInterruption;
        sigemptyset(&action.sa_mask);
        action.sa_flags = SA_RESETHAND;
        for (std::size_t i = 0; i < std::size(kSignals); ++i) ::sigaction(kSignals[i], &action, &g_replaced[i]);
    }
    ~InterruptionNote() {
        for (std::size_t i = 0; i < std::size(kSignals); ++i) ::sigaction(kSignals[i], &g_replaced[i], nullptr);
    }
};

}  // namespace

void addBatchOptions(CLI::App& command, BatchOptions& options, const std::string& inputHelp, const std::string& outputHelp,
                     const std::string& defaultName) {
    options.name = defaultName;
    command.add_option("inputs", options.inputs, inputHelp + " (several make a batch; see --out-dir)");
    writesFile(command.add_option("-o,--output", options.output, outputHelp + " (one input)"));
    command.add_option("--out-dir", options.outDir, "batch: write each input's output into this folder (made if missing)");
    command.add_option("--name", options.name, "batch: output file name, from {stem}, {name}, {ext}, {index} (default " +
                                                   defaultName + ")");
    command.add_option("--list", options.listFile, "batch: read the inputs from this file, one a line ('-': standard input)");
    command.add_option("--jobs,-j", options.jobs, "batch: inputs converted at once (default 1; each already uses every core)")
        ->check(CLI::Range(1, 256));
    command.add_flag("--skip-existing", options.skipExisting, "batch: leave inputs whose output exists alone");
    command.add_flag("--fail-fast", options.failFast, "batch: stop at the first failure (default: try every input)");
}

bool isBatch(const BatchOptions& o) { return o.inputs.size() > 1 || !o.listFile.empty() || !o.outDir.empty(); }

std::vector<Job> planJobs(const BatchOptions& o) {
    std::vector<std::string> inputs = o.inputs;
    if (!o.listFile.empty()) {
        const std::vector<std::string> listed = readList(o.listFile);
        inputs.insert(inputs.end(), listed.begin(), listed.end());
    }
    if (inputs.empty()) throw Error(ErrorCode::InvalidArgument, "no input given");
    if (!isBatch(o)) {
        if (o.output.empty()) throw Error(ErrorCode::InvalidArgument, "-o,--output is required (or --out-dir for a batch)");
        return {{inputs.front(), o.output}};
    }
    if (!o.output.empty())
        throw Error(ErrorCode::InvalidArgument, "-o names the output of one input; for " + std::to_string(inputs.size()) +
                                                    " inputs give --out-dir (and --name)");
    if (o.outDir.empty()) throw Error(ErrorCode::InvalidArgument, "several inputs need --out-dir for their outputs");
    if (inputs.size() > 1 && o.name.find("{stem}") == std::string::npos && o.name.find("{name}") == std::string::npos &&
        o.name.find("{index}") == std::string::npos)
        throw Error(ErrorCode::InvalidArgument, "--name '" + o.name + "' gives every input the same output; use {stem}, {name} or {index}");
    std::vector<Job> jobs;
    std::map<std::string, std::string> seen;  // output -> the input that writes it
    for (std::size_t i = 0; i < inputs.size(); ++i) {
        // Outputs stay inside --out-dir: no absolute name, no ".." out of it.
        const fs::path name = fs::path(outputName(o.name, inputs[i], i + 1)).lexically_normal();
        if (name.empty() || name.is_absolute() || *name.begin() == ".." || name.has_root_name())
            throw Error(ErrorCode::InvalidArgument, "--name '" + o.name + "' gives '" + name.string() +
                                                        "', which is not a file name inside --out-dir");
        Job job{inputs[i], (fs::path(o.outDir) / name).string()};
        const std::string key = fs::path(job.output).lexically_normal().string();
        if (auto [it, fresh] = seen.emplace(key, job.input); !fresh)
            throw Error(ErrorCode::InvalidArgument, job.input + " and " + it->second + " would both write " + job.output +
                                                        "; use {name} or {index} in --name");
        jobs.push_back(std::move(job));
    }
    // Before any work: no output replaces an input (its own or another's; a --list's too).
    for (const std::string& input : inputs) protectInput(input);
    for (const Job& job : jobs) checkNotAnInput(job.output, inputs);
    return jobs;
}

int runBatch(const std::vector<Job>& jobs, const BatchOptions& options, const std::function<std::string(const Job&)>& convert) {
    std::error_code ec;
    const bool made = !fs::exists(options.outDir, ec);  // removed again when the batch writes nothing into it
    fs::create_directories(options.outDir, ec);
    if (ec) throw Error(ErrorCode::Io, "cannot make the folder " + options.outDir + ": " + ec.message());

    const bool userQuiet = quiet();  // -q; the items below run quiet whatever it says
    const auto start = std::chrono::steady_clock::now();
    std::atomic<std::size_t> next{0};
    std::atomic<bool> stop{false};
    std::mutex mutex;  // the counts and the reasons below
    std::size_t converted = 0, skipped = 0, failed = 0, finished = 0;
    std::vector<std::string> reasons;
    double convertingSeconds = 0;  // work done by the converted items, for the time left

    auto show = [&] {  // under `mutex`
        const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        std::string line = std::to_string(finished) + "/" + std::to_string(jobs.size()) + " (" + std::to_string(converted) +
                           " converted, " + std::to_string(skipped) + " skipped, " + std::to_string(failed) + " failed)";
        const std::size_t left = jobs.size() - finished;
        if (converted > 0 && left > 0) {
            // Converting is what takes the time: the mean so far, over the jobs that run at once.
            const double each = convertingSeconds / double(converted);
            const double parallel = double(std::min<std::size_t>(std::size_t(options.jobs), left));
            line += ", " + clock(each * double(left) / parallel) + " left";
        }
        line += " [" + clock(elapsed) + "]";
        liveLine(line);
    };

    setInterruptionNote(commandName(), 0, jobs.size());
    const InterruptionNote interruption;

    auto worker = [&] {
        for (std::size_t i; !stop && (i = next++) < jobs.size();) {
            const Job& job = jobs[i];
            const auto begun = std::chrono::steady_clock::now();
            std::string outcome, error;
            bool skip = false;
            std::error_code missing;  // this thread's own
            if (options.skipExisting && fs::exists(job.output, missing)) {
                skip = true;
            } else {
                try {
                    outcome = convert(job);
                } catch (const std::exception& e) {
                    error = e.what();
                }
            }
            const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - begun).count();
            std::lock_guard lock(mutex);
            ++finished;
            if (skip) {
                ++skipped;
            } else if (!error.empty()) {
                ++failed;
                // Most messages name the file already.
                const std::string reason = error.rfind(job.input, 0) == 0 ? error : job.input + ": " + error;
                reasons.push_back(reason);
                if (!userQuiet)  // -q: the summary alone lists it
                    report("[" + std::to_string(finished) + "/" + std::to_string(jobs.size()) + "] failed: " + reason);
                if (options.failFast) stop = true;
            } else {
                ++converted;
                convertingSeconds += seconds;
                if (!userQuiet && !::isatty(STDERR_FILENO))  // a log keeps one line an item
                    report("[" + std::to_string(finished) + "/" + std::to_string(jobs.size()) + "] " + outcome);
            }
            setInterruptionNote(commandName(), finished, jobs.size());
            show();
        }
    };

    setQuiet(true);  // the items' stage lines: the batch reports instead; each warning once
    {
        std::vector<std::thread> threads;
        const int count = std::max(1, std::min<int>(options.jobs, int(jobs.size())));
        for (int t = 1; t < count; ++t) threads.emplace_back(worker);
        worker();
        for (std::thread& t : threads) t.join();
    }
    setQuiet(false);
    reportRepeatedWarnings(jobs.size());

    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::string summary = std::to_string(converted) + " converted, " + std::to_string(skipped) + " skipped (output exists), " +
                          std::to_string(failed) + " failed";
    if (stop) summary += ", " + std::to_string(jobs.size() - finished) + " not tried (--fail-fast)";
    summary += " in " + clock(elapsed);
    if (!userQuiet && ::isatty(STDERR_FILENO)) std::fprintf(stderr, "\r\033[K");
    if (!userQuiet || failed > 0) std::printf("%s\n", summary.c_str());  // -q: silent on success
    for (const std::string& reason : reasons) std::printf("  failed: %s\n", reason.c_str());
    if (made && converted == 0) fs::remove(options.outDir, ec);  // only when empty
    return failed > 0 ? 1 : 0;
}

int runConversions(const BatchOptions& options, const std::function<std::string(const Job&)>& convert) {
    const std::vector<Job> jobs = planJobs(options);
    if (isBatch(options)) return runBatch(jobs, options, convert);
    const std::string line = convert(jobs.front());
    if (!quiet()) std::printf("%s\n", line.c_str());
    return 0;
}

}  // namespace conus::cli
