// ValidationReport helpers.
#include <algorithm>

#include "conus/format/container.h"
#include "conus/format/validation.h"

namespace conus::format {

std::string label(Rule rule) { return rule == Rule::Unreadable ? "error" : "V" + std::to_string(number(rule)); }

bool ValidationReport::violates(Rule rule) const {
    return std::any_of(issues.begin(), issues.end(), [rule](const Issue& i) { return i.rule == rule; });
}

namespace {

// "V7: message", or "error: message" for rule 0.
std::string line(const Issue& issue) {
    return label(issue.rule) + ": " + issue.message;
}

}  // namespace

void ValidationReport::add(Rule rule, std::string message, long long count) {
    std::replace_if(message.begin(), message.end(), [](char c) { return c == '\n' || c == '\r'; }, ' ');
    issues.push_back({rule, std::move(message), count});
}

std::vector<int> ValidationReport::ruleNumbers() const {
    std::vector<int> rules;
    for (const Issue& issue : issues)
        if (std::find(rules.begin(), rules.end(), number(issue.rule)) == rules.end()) rules.push_back(number(issue.rule));
    return rules;
}

std::string ValidationReport::str() const {
    std::string out;
    for (const Issue& issue : issues) out += (out.empty() ? "" : "; ") + line(issue);
    return out;
}

long long ValidationReport::problemCount() const {
    long long n = 0;
    for (const Issue& issue : issues) n += issue.count;
    return n;
}

std::string ValidationReport::summary() const {
    constexpr std::size_t kShown = 3;  // enough to see what is wrong, short enough for one line
    if (issues.empty()) return "valid";
    std::string out;
    long long shown = 0;
    for (std::size_t i = 0; i < issues.size() && i < kShown; ++i) {
        out += (i ? "; " : "") + line(issues[i]);
        shown += issues[i].count;
    }
    if (const long long more = problemCount() - shown; more > 0)
        out += " (and " + std::to_string(more) + " more problem" + (more == 1 ? "" : "s") + "; `conus validate` lists them)";
    return out;
}

}  // namespace conus::format
