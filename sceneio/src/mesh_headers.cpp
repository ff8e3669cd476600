// The checks of a mesh file's text before Assimp reads it: PLY and OFF headers declare their
// element counts up front, and Assimp allocates by them.
#include <algorithm>
#include <cctype>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "conus/core/limits.h"
#include "extension_pvt.h"
#include "mesh_headers_pvt.h"

namespace conus::sceneio {
namespace {

// A PLY header's format and property lines as the spec has them: Assimp's reader loops on a list
// whose type it does not know, and on a format it does not know.
void checkPlyLine(const std::string& path, const std::string& keyword, std::istringstream& words) {
    static const std::set<std::string> kTypes = {"char",  "uchar",  "short", "ushort", "int",    "uint",
                                                 "float", "double", "int8",  "uint8",  "int16",  "uint16",
                                                 "int32", "uint32", "float32", "float64"};
    std::string a, b, c, d;
    words >> a >> b >> c >> d;
    const bool ok = keyword == "format"
                        ? (a == "ascii" || a == "binary_little_endian" || a == "binary_big_endian") && b == "1.0" && c.empty()
                        : a == "list" ? kTypes.count(b) && kTypes.count(c) && !d.empty() : kTypes.count(a) && !b.empty() && c.empty();
    if (!ok) fail(ErrorCode::Corrupt, path, "its PLY header has a " + keyword + " line the format does not define");
}

// Assimp's OFF reader copies each line into a buffer of kAssimpLineBuffer characters and ends it
// one past the end; the rest of a longer line is read as the next lines (a 13 KB vertex line made
// it read faces out of the vertex text and crash). Its line ends are CR, LF, form feed and NUL.
constexpr std::size_t kAssimpLineBuffer = 4096;
void checkOffLineLengths(const std::string& path, const std::string& text) {
    std::size_t run = 0, line = 1;
    for (const char c : text) {
        if (c == '\n' || c == '\r' || c == '\f' || c == '\0') {
            if (c == '\n') ++line;
            run = 0;
        } else if (++run >= kAssimpLineBuffer) {
            fail(ErrorCode::Corrupt, path, "its line " + std::to_string(line) + " is longer than the " +
                                               std::to_string(kAssimpLineBuffer - 1) + " characters an OFF line may have");
        }
    }
}

// An OFF file read as Assimp reads it: the header's tokens (comment lines skipped; letters before
// "OFF", and counts glued to it, as it takes them; each count an unsigned 32-bit number that wraps),
// then one line a vertex and one a face (blank lines skipped). Its counts must fit the file and the
// caps, and each face line must start with a corner count of 1 to 9: Assimp drops other faces by
// lowering the mesh's face count, and where it drops them all it reads past its arrays (a fuzzer's
// 80-byte file crashed every command).
void checkOffBody(const std::string& path, const std::string& text, const MeshReadOptions& options) {
    const std::uintmax_t bytes = text.size();
    const char* at = text.c_str();
    const char* end = at + text.size();
    const auto isLineEnd = [](char c) { return c == '\r' || c == '\n' || c == '\0' || c == '\f'; };
    const auto skipLine = [&] {
        while (at < end && *at != '\r' && *at != '\n' && *at != '\0') ++at;
        while (at < end && (*at == '\r' || *at == '\n')) ++at;
    };
    const auto nextToken = [&] {
        while (at < end && (*at == ' ' || *at == '\t' || *at == '\r' || *at == '\n')) ++at;
        while (at < end && (*at == '#' || *at == '\n' || *at == '\r')) {
            skipLine();
            while (at < end && (*at == ' ' || *at == '\t' || *at == '\r' || *at == '\n')) ++at;
        }
    };
    const auto number = [&] {  // strtoul10: an unsigned 32-bit value, wrapping as it goes
        std::uint32_t v = 0;
        while (at < end && *at >= '0' && *at <= '9') v = v * 10u + std::uint32_t(*at++ - '0');
        return v;
    };
    nextToken();
    if (end - at > 2 && at[0] == 'S' && at[1] == 'T') at += 2;
    for (const char letter : {'C', 'N', '4'})
        if (end - at > 1 && *at == letter) ++at;
    const bool dimension = end - at > 1 && *at == 'n';
    if (dimension) ++at;
    if (end - at > 3 && std::equal(at, at + 3, "OFF")) at += 3;
    nextToken();
    if (dimension) {
        number();
        nextToken();
    }
    nextToken();
    const std::uint32_t vertices = number();
    nextToken();
    const std::uint32_t faces = number();
    nextToken();
    number();
    nextToken();
    if (vertices == 0 || faces == 0) return;  // Assimp refuses the file itself
    // Assimp allocates by the counts before reading a vertex (a 139-byte file asked for 61 GB): a
    // count no file of this size can hold (a vertex takes at least 6 bytes, a face 8) or one past
    // the caps is refused first.
    const char* names[2] = {"vertices", "faces"};
    const std::uintmax_t counts[2] = {vertices, faces}, leastBytes[2] = {6, 8};
    const std::int64_t caps[2] = {options.maxVertices, options.maxTriangles};
    for (int i = 0; i < 2; ++i) {
        if (counts[i] * leastBytes[i] > bytes)
            fail(ErrorCode::Corrupt, path, "its OFF header declares " + std::to_string(counts[i]) + " " + names[i] +
                                               " in a file of " + std::to_string(bytes) + " bytes");
        if (counts[i] > std::uintmax_t(caps[i]))
            fail(ErrorCode::LimitExceeded, path, "its OFF header declares " + std::to_string(counts[i]) + " " + names[i] +
                                                     ", more than the limit of " + std::to_string(caps[i]));
    }
    // GetNextLine: the text to the next line end, then every line end after it.
    const auto nextLine = [&] {
        if (at >= end || *at == '\0') return false;
        while (at < end && !isLineEnd(*at)) ++at;
        while (at < end && isLineEnd(*at) && *at != '\0') ++at;
        return true;
    };
    for (std::uintmax_t v = 0; v < vertices; ++v)
        if (!nextLine()) return;  // too few lines: Assimp says so
    for (std::uintmax_t f = 0; f < faces; ++f) {
        const char* line = at;
        if (!nextLine()) return;
        const char* sz = line;
        while (*sz == ' ' || *sz == '\t') ++sz;
        std::uintmax_t corners = 0;
        while (*sz >= '0' && *sz <= '9' && corners < 10) corners = corners * 10 + std::uintmax_t(*sz++ - '0');
        if (corners == 0 || corners > 9)
            fail(ErrorCode::Corrupt, path, "its OFF face " + std::to_string(f + 1) +
                                               " does not start with a corner count of 1 to 9");
    }
}

}  // namespace

// PLY headers declare their element counts up front and Assimp reserves memory for them before
// reading a single vertex; a count no file of this size can hold (every element takes at least a
// byte) or one past the caps is refused here, before Assimp sees the file.
void checkPlyCounts(const std::string& path, std::uintmax_t bytes, const MeshReadOptions& options) {
    // Assimp takes a file whose first line starts with the three letters ("ply@" included) as a
    // PLY whatever its name: a .glb or .gltf its own importer refuses is tried as one.
    AssimpLines lines(path, std::min<std::uintmax_t>(bytes, 1 << 20));
    std::string line;
    if (!lines.next(line) || line.size() < 3) return;
    std::string magic = line.substr(0, 3);
    for (char& c : magic) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (magic != "ply") return;
    for (int n = 0; n < 10000 && lines.next(line); ++n) {
        while (!line.empty() && std::isspace(static_cast<unsigned char>(line.back()))) line.pop_back();
        if (line == "end_header") return;
        std::istringstream words(line);
        std::string keyword, element;
        long double count = 0;
        // Assimp's ASCII reader loops forever on some malformed headers: only the spec's lines pass.
        words >> keyword;
        if (keyword != "format" && keyword != "element" && keyword != "property" && keyword != "comment" &&
            keyword != "obj_info")
            fail(ErrorCode::Corrupt, path, "its PLY header has a line that is not format, element, property, comment "
                                           "or end_header");
        if (keyword == "format" || keyword == "property") checkPlyLine(path, keyword, words);
        if (!(words >> element >> count) || keyword != "element") continue;
        const std::int64_t cap = element == "vertex" ? options.maxVertices : element == "face" ? options.maxTriangles : -1;
        if (count > static_cast<long double>(bytes))
            fail(ErrorCode::Corrupt, path, "its header declares " + numberText(double(count)) + " " + element +
                                               " elements in a file of " + std::to_string(bytes) + " bytes");
        if (cap >= 0 && count > static_cast<long double>(cap))
            fail(ErrorCode::LimitExceeded, path, "its header declares " + numberText(double(count)) + " " + element +
                                                     " elements, more than the limit of " + std::to_string(cap));
    }
    // Assimp's ASCII PLY reader loops forever on a header that never ends.
    fail(ErrorCode::Corrupt, path, "its PLY header has no end_header line");
}

// OFF files: Assimp's reader takes any file whose name ends in .off or whose first token ends in
// OFF (or starts with the letters, in either case); those are checked as it reads them.
void checkOffCounts(const std::string& path, std::uintmax_t bytes, const MeshReadOptions& options) {
    std::ifstream in(path, std::ios::binary);
    std::string first;
    for (std::string line; first.empty() && std::getline(in, line) && in.tellg() < 65536;) {
        std::istringstream words(line.substr(0, line.find('#')));
        words >> first;
    }
    std::string magic = first.substr(0, 3);
    for (char& c : magic) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    const bool keyword = first.size() >= 3 && first.compare(first.size() - 3, 3, "OFF") == 0;
    if (!keyword && lowerExtension(path) != ".off" && magic != "off") return;
    // The whole file, once (Assimp reads it whole too), for both checks.
    std::string text(static_cast<std::size_t>(bytes), '\0');
    std::ifstream(path, std::ios::binary).read(text.data(), static_cast<std::streamsize>(text.size()));
    checkOffLineLengths(path, text);
    checkOffBody(path, text, options);
}

}  // namespace conus::sceneio
