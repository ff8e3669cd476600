// Progress on long steps, printed to stderr: a live percentage on a terminal, one line per step
// with its duration otherwise (logs, CI). Only cli/ prints.
#pragma once

#include <chrono>
#include <string>

#include "conus/format/error.h"

namespace conus::cli {

class Progress {
public:
    explicit Progress(std::string label, bool quiet = false);
    ~Progress();  // finishes the line if done() was not called
    ProgressFn callback();
    void done();

private:
    std::string m_label;
    bool m_quiet;
    bool m_tty;
    bool m_finished = false;
    int m_lastPercent = -1;
    std::chrono::steady_clock::time_point m_start;
};

}  // namespace conus::cli
