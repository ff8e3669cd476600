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
};

struct ValidationReport {
    std::vector<Issue> issues;

    bool ok() const { return issues.empty(); }
    bool violates(int rule) const;
    // Line breaks in the message (a library's text may hold some) become spaces.
    void add(int rule, std::string message);
    // Every issue on one line, "V7: <message>; V9: <message>" (rule 0 reads "error: ..."), so an
    // error message built from a report never spans lines.
    std::string str() const;
};

}  // namespace conus::format
