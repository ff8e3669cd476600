// Many inputs, one command: what `encode` and `decode` share for batch conversion.
//
//   conus encode a.jpg b.jpg c.jpg --out-dir exr/ --jobs 2 --skip-existing
//   conus decode --list files.txt --out-dir png/ --name '{stem}-view.png'
//
// One input with -o is the single conversion it always was. Several inputs, --list or --out-dir
// make a batch: each input's output is OUT_DIR/<name pattern>; every input is tried (unless
// --fail-fast), one progress line covers the batch with the time left, and a summary line says
// how many were converted, skipped and failed, with the reasons. The exit code is 1 when any
// failed, 0 otherwise.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace conus::cli {

struct BatchOptions {
    std::vector<std::string> inputs;  // positional
    std::string output;               // -o: the output of a single input
    std::string outDir;               // --out-dir
    std::string name;                 // --name: {stem}, {name}, {ext}, {index}
    std::string listFile;             // --list: one input per line ('-': standard input)
    int jobs = 1;
    bool skipExisting = false, failFast = false;
};

// Adds the positional inputs, -o, --out-dir, --name (default `defaultName`), --list, --jobs,
// --skip-existing and --fail-fast.
void addBatchOptions(CLI::App& command, BatchOptions& options, const std::string& inputHelp, const std::string& outputHelp,
                     const std::string& defaultName);

struct Job {
    std::string input, output;
};

// Whether these options ask for a batch (several inputs, --list or --out-dir).
bool isBatch(const BatchOptions& options);

// The inputs (the list file's included) with their outputs. Throws conus::Error(InvalidArgument)
// for no input, -o with a batch, neither -o nor --out-dir, --name without a placeholder that
// tells inputs apart, or two inputs that would write the same output.
std::vector<Job> planJobs(const BatchOptions& options);

// Runs `convert` on every job, options.jobs at a time (each returns the line that says what it
// wrote; it runs quiet: the batch reports). Prints the batch's progress on stderr, each failure as
// it happens (not with -q, where the summary alone lists them), and the summary on stdout; returns
// the exit code.
int runBatch(const std::vector<Job>& jobs, const BatchOptions& options, const std::function<std::string(const Job&)>& convert);

// What `encode` and `decode` run: the jobs the options plan, as a batch (runBatch) or, for a
// single input, one conversion whose line is printed. Returns the exit code.
int runConversions(const BatchOptions& options, const std::function<std::string(const Job&)>& convert);

}  // namespace conus::cli
