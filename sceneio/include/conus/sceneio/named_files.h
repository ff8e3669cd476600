// The one policy for files a scene file names on its own behalf (a glTF buffer or image, an OBJ
// material library or texture, an NRRD data file, anything Assimp or teem opens for the file):
// - a name is resolved relative to the naming file's own folder; an absolute name is refused;
// - the file it resolves to, symbolic links followed, lies inside that folder, or inside a folder
//   the caller allowed explicitly (`--allow-dir DIR`, Python's `allow_dirs=`);
// - it is a regular file (no FIFO, device, socket or directory, which could block or never end),
//   and it exists.
// A converter fed uploaded models thus never reads its own files back as picture data. A refusal
// is conus::Error(Io), one line naming the scene file and the name it gave. A file let through is
// an input of the run (core protectInput): no output of the process may replace it.
#pragma once

#include <string>
#include <vector>

namespace conus::sceneio {

// The folders a scene file may name files in: its own (canonical) folder plus `allowedDirs`
// (canonical; a folder that does not exist is refused with InvalidArgument).
class NamedFiles {
public:
    // `what` names the scene file in messages ("mesh 'model.gltf'").
    NamedFiles(const std::string& sceneFile, const std::vector<std::string>& allowedDirs, std::string what);

    // `name` as the scene file wrote it: refused when absolute; else resolved in the scene
    // file's folder and checked. Returns the canonical path to open.
    std::string resolve(const std::string& name) const;
    // A path already joined by a library (Assimp's importers prepend the scene's folder): checked
    // as it stands. Returns the canonical path to open.
    std::string check(const std::string& path) const;

    const std::string& folder() const { return m_folder; }

private:
    std::string m_what;
    std::string m_folder;
    std::vector<std::string> m_allowed;  // m_folder first
};

}  // namespace conus::sceneio
