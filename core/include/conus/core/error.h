// The one error type of the CoNUS libraries. Libraries never print and never exit: they throw
// conus::Error (with a code a caller can branch on) or return a ValidationReport (validation.h).
#pragma once

#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace conus {

enum class ErrorCode {
    InvalidArgument,  // a caller passed a value outside the documented range
    Io,               // a file could not be opened, read, written or renamed
    NotConus,         // a readable EXR file that is not a CoNUS file (no `conus` part)
    Corrupt,          // a file that breaks the format: damaged EXR, or a CoNUS rule (spec V-rules)
    LimitExceeded,    // a size beyond the reader's limits (checked before anything is allocated)
    InvalidMap,       // a sampling map that is folded, degenerate, NaN or off its boundary
    Unsupported,      // a valid request this build cannot serve
};

// `text` on one line: line breaks (a library's multi-line message) become "; ", trailing ones go.
// Scripts read the last line of stderr, so every CoNUS error is one line.
std::string oneLine(std::string text);

// A number as messages show it: `significantDigits` digits, %g style ("0.1", "1e+06", "nan").
std::string numberText(double value, int significantDigits = 6);
// A loss in dB as messages say it: "loses 1.50 dB", or for a negative loss "gains 0.44 dB" (`lose`
// and `gain` the verbs as they agree with the subject), to `decimals` places. The CLI and the
// Python module say a budget's findings with it, so that neither prints "loses -0.9 dB".
std::string lossText(double db, const char* lose, const char* gain, int decimals);

class Error : public std::runtime_error {
public:
    // The message is kept on one line (oneLine), whatever a library underneath said.
    Error(ErrorCode code, const std::string& message) : std::runtime_error(oneLine(message)), m_code(code) {}
    // An error that breaks rules of the format's specification (spec/conus-format.md: V1, V4, ...),
    // by number, in the order the message names them.
    Error(ErrorCode code, const std::string& message, std::vector<int> rules)
        : std::runtime_error(oneLine(message)), m_code(code), m_rules(std::move(rules)) {}
    ErrorCode code() const noexcept { return m_code; }
    const std::vector<int>& rules() const noexcept { return m_rules; }

private:
    ErrorCode m_code;
    std::vector<int> m_rules;
};

// Long operations report progress in [0,1] through this callback; an empty one is allowed.
using ProgressFn = std::function<void(double fraction)>;

}  // namespace conus
