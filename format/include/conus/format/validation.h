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
    // Line breaks in the message (a library's text may hold some) become spaces. `count` is the
    // number of problems the issue stands for (N for a capped rule's "... and N more" line).
    void add(int rule, std::string message, long long count = 1);
    // Every problem, counting the ones a capped rule summed up in "... and N more".
    long long problemCount() const;
    // One line for an error message: the first few issues, "V5: <message>; V6: <message>", then
    // how many more problems there are.
    std::string summary() const;
    // Every issue on one line, "V7: <message>; V9: <message>" (rule 0 reads "error: ...").
    std::string str() const;
};

}  // namespace conus::format
