// Progress on long steps, printed to stderr: a live percentage on a terminal, then one line per
// stage ("conus encode: read photo.jpg done (0.21 s)"), and one total line when the command ends. `--quiet` (every
// subcommand has it) silences all of it; warnings and errors still print. Only cli/ prints.
#pragma once

#include <chrono>
#include <string>

#include "conus/core/error.h"

namespace CLI {
class App;
}

namespace conus::cli {

class Progress {
public:
    explicit Progress(std::string label);
    ~Progress();  // finishes the line if done() was not called
    ProgressFn callback();
    // A stage made of steps whose count is not known ahead (a budget's confirming encodes): each
    // call with 0 starts the next, shown as "<label>: <step> N" and its own percentage.
    ProgressFn steps(std::string step);
    void done();

private:
    // The live line: `shown` and the percentage of `fraction`, where it moved on (the caller holds
    // the print lock).
    void show(const std::string& shown, double fraction);

    std::string m_label;
    bool m_tty;
    bool m_finished = false;
    int m_lastPercent = -1;
    int m_step = 0;  // steps(): the step shown
    std::chrono::steady_clock::time_point m_start;
};

// Adds -q/--quiet to a subcommand.
void addQuietOption(CLI::App& command);
bool quiet();
// Silences the stage lines (not warnings or errors) until called again with false: a batch runs
// its items quiet and reports for them.
void setQuiet(bool silenced);
// "conus <command>: <text>" on stderr on a line of its own, even when quiet (a batch's failures).
void report(const std::string& text);
// On a terminal, replaces the live line with "conus <command>: <text>"; elsewhere, and when
// quiet, nothing.
void liveLine(const std::string& text);

// The subcommand that runs, for the lines below (main.cpp sets it).
void beginCommand(const std::string& name);
const std::string& commandName();

// "conus <command>: done in 2.41 s: 4 stages 2.10 s, start-up 0.05 s, outside the stages 0.26 s" once
// a command of several stages succeeded: the parts add up to the total, counted from the process's start.
void printTotal();

// "conus <command>: warning: <text>" on stderr, even when quiet. While a batch runs its items
// (setQuiet(true)) a warning already given is not repeated; reportRepeatedWarnings says how many
// of the batch's inputs each one held for.
void warn(const std::string& text);
void reportRepeatedWarnings(std::size_t inputs);

// "N focus" / "N foci": counts said right.
std::string plural(std::size_t n, const char* one, const char* many);

}  // namespace conus::cli
