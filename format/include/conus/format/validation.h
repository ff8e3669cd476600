// Validation reports: every violated rule of spec/ (V1, V2, ...) with the offending values, in the
// manner of OpenEXR's validation.c. Validators collect every problem; they never throw for bad
// content.
#pragma once

#include <string>
#include <vector>

namespace conus::format {

// The rules of spec/conus-format.md by number (Rule::V7 is V7); Unreadable: the file could not be
// read at all, so no rule could be checked.
enum class Rule : int { Unreadable = 0, V1, V2, V3, V4, V5, V6, V7, V8, V9, V10, V11, V12, V13, V14, V15, V16, V17, V18, V19 };
inline constexpr int number(Rule rule) { return static_cast<int>(rule); }
// "V7", or "error" for Unreadable: how messages name a rule.
std::string label(Rule rule);

struct Issue {
    Rule rule = Rule::Unreadable;
    std::string message;  // what is wrong, with the bad values
    long long count = 1;  // problems it stands for: N for a "... and N more" line
};

struct ValidationReport {
    std::vector<Issue> issues;

    bool ok() const { return issues.empty(); }
    bool violates(Rule rule) const;
    // Line breaks in the message (a library's text may hold some) become spaces. `count` is the
    // number of problems the issue stands for (N for a capped rule's "... and N more" line).
    void add(Rule rule, std::string message, long long count = 1);
    // Every problem, counting the ones a capped rule summed up in "... and N more".
    long long problemCount() const;
    // One line for an error message: the first few issues, "V5: <message>; V6: <message>", then
    // how many more problems there are.
    std::string summary() const;
    // Every issue on one line, "V7: <message>; V9: <message>" (rule 0 reads "error: ...").
    std::string str() const;
    // The numbers of the rules broken, each once, in the report's order (what conus::Error carries).
    std::vector<int> ruleNumbers() const;
};

}  // namespace conus::format
