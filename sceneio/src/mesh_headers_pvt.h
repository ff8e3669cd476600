// Private: the checks of a mesh file's text that run before Assimp reads it (PLY and OFF element
// counts), and the line reader they and the OBJ/MTL checks share.
#pragma once

#include <cstdint>
#include <fstream>
#include <string>

#include "conus/core/error.h"
#include "conus/sceneio/mesh_file.h"

namespace conus::sceneio {

// A refusal of the mesh file `path`, in one line: "mesh 'PATH': WHY".
[[noreturn]] inline void fail(ErrorCode code, const std::string& path, const std::string& why) {
    throw Error(code, "mesh '" + path + "': " + why);
}

// Assimp's text importers (PLY headers, OBJ, MTL) end a line at any of \n \r \0 \f and skip empty
// lines; the checks below read files the same way: the first `limit` bytes of `path`, a line at a
// time, streamed (a check that stops at its first statement reads no further).
class AssimpLines {
public:
    AssimpLines(const std::string& path, std::uintmax_t limit) : m_in(path, std::ios::binary), m_left(limit) {}
    bool next(std::string& line) {
        const auto end = [](int c) { return c == '\n' || c == '\r' || c == '\0' || c == '\f'; };
        line.clear();
        for (int c; m_left > 0 && (c = m_in.rdbuf()->sbumpc()) != std::ifstream::traits_type::eof(); --m_left) {
            if (!end(c)) {
                line += static_cast<char>(c);
            } else if (!line.empty()) {
                --m_left;
                return true;
            }
        }
        return !line.empty();
    }

private:
    std::ifstream m_in;
    std::uintmax_t m_left;
};

// PLY headers: their format and property lines as the spec has them, and element counts that a
// file of `bytes` can hold within the caps; a no-op for other files.
void checkPlyCounts(const std::string& path, std::uintmax_t bytes, const MeshReadOptions& options);
// OFF files, as Assimp reads them: lines within its buffer, counts the file can hold within the
// caps, and faces it keeps; a no-op for other files.
void checkOffCounts(const std::string& path, std::uintmax_t bytes, const MeshReadOptions& options);

}  // namespace conus::sceneio
