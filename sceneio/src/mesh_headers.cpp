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
void checkOffLineLengths(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::vector<char> block(1 << 16);
    std::size_t run = 0, line = 1;
    while (in) {
        in.read(block.data(), static_cast<std::streamsize>(block.size()));
        for (std::streamsize i = 0; i < in.gcount(); ++i) {
            const char c = block[std::size_t(i)];
            if (c == '\n' || c == '\r' || c == '\f' || c == '\0') {
                if (c == '\n') ++line;
                run = 0;
            } else if (++run >= kAssimpLineBuffer) {
                fail(ErrorCode::Corrupt, path, "its line " + std::to_string(line) + " is longer than the " +
                                                   std::to_string(kAssimpLineBuffer - 1) + " characters an OFF line may have");
            }
        }
    }
}

// Assimp's OFF reader drops a face whose corner count is 0 or past 9 by lowering the mesh's face
// count and moving on: where it drops them all, the mesh has no faces and Assimp reads past its
// arrays (a fuzzer's 80-byte file crashed every command). The face lines are found as it finds
// them (the header's tokens, comment lines skipped; then one line a vertex and one a face, blank
// lines skipped) and each must start with a count of 1 to 9.
void checkOffFaceCorners(const std::string& path, std::uintmax_t bytes) {
    std::string text(static_cast<std::size_t>(bytes), '\0');
    std::ifstream(path, std::ios::binary).read(text.data(), static_cast<std::streamsize>(text.size()));
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
    const auto number = [&] {
        std::uintmax_t v = 0;
        while (at < end && *at >= '0' && *at <= '9') v = std::min<std::uintmax_t>(v * 10 + std::uintmax_t(*at++ - '0'), 1u << 31);
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
    const std::uintmax_t vertices = number();
    nextToken();
    const std::uintmax_t faces = number();
    nextToken();
    number();
    nextToken();
    if (vertices == 0 || faces == 0) return;  // Assimp refuses the file itself
    // GetNextLine: the text to the next line end, then every line end after it.
    const auto nextLine = [&] {
        if (at >= end || *at == '\0') return false;
        const char* start = at;
        while (at < end && !isLineEnd(*at)) ++at;
        const char* lineEnd = at;
        while (at < end && isLineEnd(*at) && *at != '\0') ++at;
        return lineEnd >= start;
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

// OFF files declare their vertex and face counts in the first line after the keyword, and Assimp
// allocates the faces by the count before reading one (a 139-byte file asked for 61 GB): a count no
// file of this size can hold (a vertex takes at least 6 bytes, a face 8) or one past the caps is
// refused here.
void checkOffCounts(const std::string& path, std::uintmax_t bytes, const MeshReadOptions& options) {
    std::ifstream in(path, std::ios::binary);
    std::string token;
    std::vector<std::string> tokens;
    for (std::string line; tokens.size() < 4 && std::getline(in, line) && in.tellg() < 65536;) {
        std::istringstream words(line.substr(0, line.find('#')));
        while (tokens.size() < 4 && words >> token) tokens.push_back(token);
    }
    const std::string ext = lowerExtension(path);
    const bool keyword = !tokens.empty() && tokens[0].size() >= 3 && tokens[0].compare(tokens[0].size() - 3, 3, "OFF") == 0;
    // Assimp's OFF reader also takes any file that starts with the letters, in either case.
    std::string magic = tokens.empty() ? std::string() : tokens[0].substr(0, 3);
    for (char& c : magic) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (!keyword && ext != ".off" && magic != "off") return;
    checkOffLineLengths(path);
    checkOffFaceCorners(path, bytes);
    const std::size_t first = keyword ? 1 : 0;
    if (tokens.size() < first + 2) return;  // Assimp refuses what has no counts
    long double counts[2] = {0, 0};
    for (int i = 0; i < 2; ++i) {
        std::istringstream number(tokens[first + std::size_t(i)]);
        if (!(number >> counts[i])) return;  // not a count: Assimp refuses it itself
    }
    const char* names[2] = {"vertices", "faces"};
    const long double leastBytes[2] = {6, 8};
    const std::int64_t caps[2] = {options.maxVertices, options.maxTriangles};
    for (int i = 0; i < 2; ++i) {
        if (counts[i] * leastBytes[i] > static_cast<long double>(bytes))
            fail(ErrorCode::Corrupt, path, "its OFF header declares " + numberText(double(counts[i])) + " " + names[i] +
                                               " in a file of " + std::to_string(bytes) + " bytes");
        if (counts[i] > static_cast<long double>(caps[i]))
            fail(ErrorCode::LimitExceeded, path, "its OFF header declares " + numberText(double(counts[i])) + " " +
                                                     names[i] + ", more than the limit of " + std::to_string(caps[i]));
    }
}

}  // namespace conus::sceneio
