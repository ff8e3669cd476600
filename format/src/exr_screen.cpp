// The checks before OpenEXR's C++ library reads a file (exr_screen_pvt.h): they refuse, with the rule
// broken, what would make that library allocate or read past what the file holds.
#include "exr_screen_pvt.h"

#include <cstring>
#include <filesystem>
#include <system_error>

#include "exr_io_pvt.h"
#include "header_scan_pvt.h"

namespace conus::format::detail {

// ---- Before OpenEXR reads a header -------------------------------------------------------------
// Three readers look at each header, in this order, and the file reaches the next only if the one
// before accepts it:
// 1. scanHeaders (header_scan.cpp) walks the raw bytes: every attribute's size inside the file and
//    within the caps (limits.h), and the values whose C++ reader ignores the declared size
//    (chlist, preview, stringvector) exactly as long as declared. This is where the attribute
//    caps apply, before anything is allocated: OpenEXR 3.1's C core has no hook for a cap (its
//    context initializer offers read and size functions only, and a smaller size would break
//    chunk reads), and its C++ library allocates whatever a size says (a 1.9 GB string in a
//    4 KB file cost 13 s and 2 GB). A chlist one byte short of its terminator made the C core end
//    the header where the C++ library went on to read a 1.8 GB string the core never saw.
// 2. OpenEXR's C core parses defensively (validation.c checks every window, channel and
//    attribute against the file) and allocates no pixels; any error it reports refuses the file.
// 3. The C++ library, which trusts more, reads the headers the first two agree on.

void recordCoreError(exr_const_context_t ctx, exr_result_t code, const char* msg) {
    void* user = nullptr;
    if (exr_get_user_data(ctx, &user) == EXR_ERR_SUCCESS && user != nullptr) {
        auto* first = static_cast<std::string*>(user);
        if (first->empty()) *first = msg ? msg : exr_get_default_error_message(code);
    }
}

namespace {

std::string partLabel(exr_const_context_t ctx, int p) {
    const char* name = nullptr;
    if (exr_get_name(ctx, p, &name) == EXR_ERR_SUCCESS && name) return "part " + std::to_string(p) + " (`" + name + "`)";
    return "part " + std::to_string(p);
}

// The header-level checks on the core's parse: display windows (V15), storage, chunk counts the
// file can hold.
Problem checkCoreHeaders(exr_const_context_t ctx, std::uintmax_t fileSize) {
    int parts = 0;
    if (exr_get_count(ctx, &parts) != EXR_ERR_SUCCESS || parts < 1) return {Rule::V1, ErrorCode::Corrupt, "no parts"};
    exr_attr_box2i_t firstDisplay{};
    for (int p = 0; p < parts; ++p) {
        exr_attr_box2i_t display{};
        if (exr_get_display_window(ctx, p, &display) == EXR_ERR_SUCCESS) {
            if (p == 0) firstDisplay = display;
            if (std::memcmp(&display, &firstDisplay, sizeof display) != 0) {
                // OpenEXR's C++ library refuses such a file with a vague message; name the rule.
                return {Rule::V15, ErrorCode::Corrupt,
                        "part " + std::to_string(p) + " displayWindow (" + std::to_string(display.min.x) + ", " +
                            std::to_string(display.min.y) + ") - (" + std::to_string(display.max.x) + ", " +
                            std::to_string(display.max.y) + ") differs from part 0's (" + std::to_string(firstDisplay.min.x) +
                            ", " + std::to_string(firstDisplay.min.y) + ") - (" + std::to_string(firstDisplay.max.x) + ", " +
                            std::to_string(firstDisplay.max.y) + ")"};
            }
        }
        int32_t chunks = 0;
        exr_storage_t storage = EXR_STORAGE_LAST_TYPE;
        if (exr_get_storage(ctx, p, &storage) != EXR_ERR_SUCCESS) return {Rule::V1, ErrorCode::Corrupt, partLabel(ctx, p) + ": unknown storage"};
        if (exr_get_chunk_count(ctx, p, &chunks) != EXR_ERR_SUCCESS || chunks < 0)
            return {Rule::V1, ErrorCode::Corrupt, partLabel(ctx, p) + ": invalid chunk count"};
        // The C++ library reads every part's offset table (8 bytes a chunk) when it opens the file.
        if (std::uintmax_t(chunks) * 8 > fileSize) {
            return {Rule::V1, ErrorCode::Corrupt,
                    partLabel(ctx, p) + " needs " + std::to_string(chunks) + " chunk offsets, more than a " +
                        std::to_string(fileSize) + "-byte file can hold"};
        }
    }
    return {};
}

// ---- chunk table -------------------------------------------------------------------------------
// Before any pixel memory is committed, the chunk table and the file size must show that the data
// can be there: every chunk inside the file, the chunks together no larger than the file, and no
// chunk declaring more unpacked bytes than its packed bytes can expand to under its compression.

// The largest unpacked / packed ratio each compression can reach (so a declared size beyond it is
// a lie), rounded up generously:
// - RLE: a 2-byte run expands to at most 128 bytes (64).
// - ZIP, ZIPS: deflate expands at most 1032 times; PXR24 also drops float32 to 24 bits (1376).
// - PIZ: Huffman with run-length codes: 256 16-bit values in >= 10 bits (~410).
// - B44, B44A: a flat 4x4 block of halves (32 bytes) in 3 bytes (~11).
// - DWAA, DWAB: DC and RLE data are zlib-compressed after a 64:1 reduction (64 x 1032 = 66048).
std::uint64_t maxExpansion(exr_compression_t c) {
    switch (c) {
        case EXR_COMPRESSION_NONE: return 1;
        case EXR_COMPRESSION_RLE: return 128;
        case EXR_COMPRESSION_ZIPS:
        case EXR_COMPRESSION_ZIP:
        case EXR_COMPRESSION_PXR24: return 2048;
        case EXR_COMPRESSION_PIZ: return 1024;
        case EXR_COMPRESSION_B44:
        case EXR_COMPRESSION_B44A: return 16;
        case EXR_COMPRESSION_DWAA:
        case EXR_COMPRESSION_DWAB: return 131072;
        default: return 0;
    }
}

const char* compressionName(exr_compression_t c) {
    static const char* const kNames[] = {"none", "rle", "zips", "zip", "piz", "pxr24", "b44", "b44a", "dwaa", "dwab"};
    return c >= 0 && c < EXR_COMPRESSION_LAST_TYPE ? kNames[c] : "unknown";
}

}  // namespace

// Level 0 of part `p` (what CoNUS reads), chunk by chunk.
Problem checkChunks(exr_const_context_t ctx, int p, std::uintmax_t fileSize) {
    const std::string label = partLabel(ctx, p);
    exr_storage_t storage = EXR_STORAGE_LAST_TYPE;
    exr_compression_t compression = EXR_COMPRESSION_LAST_TYPE;
    exr_attr_box2i_t dw{};
    if (exr_get_storage(ctx, p, &storage) != EXR_ERR_SUCCESS || exr_get_compression(ctx, p, &compression) != EXR_ERR_SUCCESS ||
        exr_get_data_window(ctx, p, &dw) != EXR_ERR_SUCCESS)
        return {Rule::V1, ErrorCode::Corrupt, label + ": unreadable storage, compression or data window"};
    const std::uint64_t ratio = maxExpansion(compression);
    if (ratio == 0) return {Rule::V1, ErrorCode::Corrupt, label + ": unknown compression"};
    const std::int64_t width = std::int64_t{dw.max.x} - dw.min.x + 1, height = std::int64_t{dw.max.y} - dw.min.y + 1;
    std::uint64_t packedTotal = 0;
    auto visit = [&](exr_result_t rv, const exr_chunk_info_t& c, const std::string& where) -> Problem {
        if (rv != EXR_ERR_SUCCESS) return {Rule::V1, ErrorCode::Corrupt, label + " " + where + ": unreadable chunk (" + exr_get_default_error_message(rv) + ")"};
        if (c.data_offset > fileSize || c.packed_size > fileSize - c.data_offset) {
            return {Rule::V1, ErrorCode::Corrupt,
                    label + " " + where + ": chunk of " + std::to_string(c.packed_size) + " bytes at offset " +
                        std::to_string(c.data_offset) + " runs past the end of the " + std::to_string(fileSize) + "-byte file"};
        }
        if (c.unpacked_size / ratio > c.packed_size) {
            return {Rule::V1, ErrorCode::Corrupt,
                    label + " " + where + ": chunk declares " + std::to_string(c.unpacked_size) + " bytes of pixels in " +
                        std::to_string(c.packed_size) + " bytes; " + compressionName(compression) + " expands at most " +
                        std::to_string(ratio) + " times"};
        }
        packedTotal += c.packed_size;
        return {};
    };
    if (storage == EXR_STORAGE_SCANLINE) {
        int32_t lines = 0;
        if (exr_get_scanlines_per_chunk(ctx, p, &lines) != EXR_ERR_SUCCESS || lines < 1)
            return {Rule::V1, ErrorCode::Corrupt, label + ": invalid scanlines per chunk"};
        for (std::int64_t y = dw.min.y; y <= dw.max.y; y += lines) {
            exr_chunk_info_t c{};
            const exr_result_t rv = exr_read_scanline_chunk_info(ctx, p, static_cast<int>(y), &c);
            if (Problem problem = visit(rv, c, "scanline " + std::to_string(y)); !problem.message.empty()) return problem;
        }
    } else if (storage == EXR_STORAGE_TILED) {
        uint32_t tw = 0, th = 0;
        exr_tile_level_mode_t level{};
        exr_tile_round_mode_t round{};
        if (exr_get_tile_descriptor(ctx, p, &tw, &th, &level, &round) != EXR_ERR_SUCCESS || tw < 1 || th < 1)
            return {Rule::V1, ErrorCode::Corrupt, label + ": invalid tile description"};
        const std::int64_t tilesX = (width + tw - 1) / tw, tilesY = (height + th - 1) / th;
        for (std::int64_t ty = 0; ty < tilesY; ++ty) {
            for (std::int64_t tx = 0; tx < tilesX; ++tx) {
                exr_chunk_info_t c{};
                const exr_result_t rv = exr_read_tile_chunk_info(ctx, p, int(tx), int(ty), 0, 0, &c);
                if (Problem problem = visit(rv, c, "tile (" + std::to_string(tx) + ", " + std::to_string(ty) + ")");
                    !problem.message.empty())
                    return problem;
            }
        }
    } else {
        return {};  // deep parts are never read; the header rules refuse them where they matter
    }
    // Chunks do not overlap: together they fit in the file.
    if (packedTotal > fileSize) {
        return {Rule::V1, ErrorCode::Corrupt,
                label + ": chunks hold " + std::to_string(packedTotal) + " bytes in all, more than the " +
                    std::to_string(fileSize) + "-byte file"};
    }
    return {};
}

// Readers 1 and 2 of the three above: the raw scan, then the C core's parse and its header-level
// checks. On success `core` holds the open context for the chunk checks.
Problem checkHeaders(const std::string& path, std::uintmax_t size, const Limits& limits, std::unique_ptr<CoreFile>& core) {
    if (const ScanResult scan = scanHeaders(path, size, limits); !scan.problem.empty())
        return {Rule::V1, scan.code, "not a readable OpenEXR file: " + scan.problem};
    core = std::make_unique<CoreFile>(path);
    if (!core->error().empty()) return {Rule::V1, ErrorCode::Corrupt, "not a readable OpenEXR file: " + core->error()};
    return checkCoreHeaders(core->ctx(), size);
}

void checkExr(const std::string& path, const Limits& limits) {
    std::error_code ec;
    const std::uintmax_t size = std::filesystem::file_size(path, ec);
    if (ec) throw Error(ErrorCode::Io, "cannot read " + path + ": " + ec.message());
    std::unique_ptr<CoreFile> core;
    Problem problem = checkHeaders(path, size, limits, core);
    int parts = 0;
    if (problem.message.empty() && exr_get_count(core->ctx(), &parts) != EXR_ERR_SUCCESS)
        problem = {Rule::V1, ErrorCode::Corrupt, "not a readable OpenEXR file: no parts"};
    for (int p = 0; p < parts && problem.message.empty(); ++p) problem = checkChunks(core->ctx(), p, size);
    if (!problem.message.empty()) throw Error(problem.code, path + ": " + problem.message, {number(problem.rule)});
}

}  // namespace conus::format::detail
