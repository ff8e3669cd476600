// Private to format/: the checks a file passes before OpenEXR's C++ library reads it: the raw
// header scan, the C core's parse, and the chunk tables against the file's size (exr_screen.cpp).
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include <openexr.h>

#include "conus/core/error.h"
#include "conus/core/limits.h"
#include "conus/format/validation.h"

namespace conus::format::detail {

// The C core's error handler: keeps the first message in the std::string its user data points to.
void recordCoreError(exr_const_context_t ctx, exr_result_t code, const char* msg);

// An open C core context. The core reports some header errors (an attribute larger than the
// file, say) through the handler and still returns success, skipping the attribute; CoNUS refuses
// such a file, so `error` holds the first message the core reported, whatever it returned.
class CoreFile {
public:
    explicit CoreFile(const std::string& path) {
        exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
        init.error_handler_fn = &recordCoreError;
        init.user_data = &m_error;
        // A damaged offset table is refused, not rebuilt by scanning the file.
        init.flags = EXR_CONTEXT_FLAG_DISABLE_CHUNK_RECONSTRUCTION;
        const exr_result_t rv = exr_start_read(&m_ctx, path.c_str(), &init);
        if (rv != EXR_ERR_SUCCESS && m_error.empty()) m_error = exr_get_default_error_message(rv);
    }
    ~CoreFile() {
        if (m_ctx) exr_finish(&m_ctx);
    }
    CoreFile(const CoreFile&) = delete;
    CoreFile& operator=(const CoreFile&) = delete;

    exr_const_context_t ctx() const { return m_ctx; }
    const std::string& error() const { return m_error; }

private:
    exr_context_t m_ctx = nullptr;
    std::string m_error;
};

// A refusal: the rule it breaks and how readConusFile throws.
struct Problem {
    Rule rule = Rule::V1;
    ErrorCode code = ErrorCode::Corrupt;
    std::string message;  // empty: no problem
};

// Level 0 of part `p` (what CoNUS reads), chunk by chunk: every chunk inside the file, the chunks
// together no larger than the file, none declaring more pixels than its compression can expand to.
Problem checkChunks(exr_const_context_t ctx, int p, std::uintmax_t fileSize);

// Readers 1 and 2 of the three (exr_screen.cpp): the raw scan, then the C core's parse and its
// header-level checks. On success `core` holds the open context for the chunk checks.
Problem checkHeaders(const std::string& path, std::uintmax_t size, const Limits& limits, std::unique_ptr<CoreFile>& core);

}  // namespace conus::format::detail
