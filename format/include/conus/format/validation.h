// Validation reports: every violated rule of spec/ (V1, V2, ...) with the offending values, in the
// manner of OpenEXR's validation.c. Validators collect every problem; they never throw for bad
// content.
#pragma once

#include <string>
#include <vector>

namespace conus::format {

struct Issue {
    int rule = 0;         // the spec's rule number: 7 means V7; 0 means "not readable at all"
    std::string message;  // what is wrong, with the bad values
    long long count = 1;  // problems it stands for: N for a "... and N more" line
};

struct ValidationReport {
    std::vector<Issue> issues;

    bool ok() const { return issues.empty(); }
    bool violates(int rule) const;
    void add(int rule, std::string message, long long count = 1) { issues.push_back({rule, std::move(message), count}); }
    // Every problem, counting the ones a capped rule summed up in "... and N more".
    long long problemCount() const;
    // One line: the first issue, then how many more problems there are.
    std::string summary() const;
    // One line per issue: "V7: <message>".
    std::string str() const;
};

}  // namespace conus::format
