// Files a scene file names: resolved in its folder, kept inside it (or an allowed folder), regular.
#include "conus/sceneio/named_files.h"

#include <filesystem>
#include <system_error>
#include <utility>

#include "conus/core/atomic_file.h"
#include "conus/core/error.h"

namespace conus::sceneio {
namespace {

namespace fs = std::filesystem;

bool inside(const fs::path& path, const fs::path& folder) {
    const fs::path relative = path.lexically_relative(folder);
    return !relative.empty() && *relative.begin() != "..";
}

}  // namespace

NamedFiles::NamedFiles(const std::string& sceneFile, const std::vector<std::string>& allowedDirs, std::string what)
    : m_what(std::move(what)) {
    std::error_code ec;
    const fs::path parent = fs::absolute(fs::path(sceneFile), ec).parent_path();
    m_folder = fs::canonical(parent, ec).string();
    if (ec) throw Error(ErrorCode::Io, m_what + ": cannot resolve its folder (" + ec.message() + ")");
    m_allowed.push_back(m_folder);
    for (const std::string& dir : allowedDirs) {
        const fs::path canonical = fs::canonical(dir, ec);
        if (ec || !fs::is_directory(canonical))
            throw Error(ErrorCode::InvalidArgument, "allowed folder '" + dir + "' is not a folder");
        m_allowed.push_back(canonical.string());
    }
}

std::string NamedFiles::resolve(const std::string& name) const {
    if (name.empty()) throw Error(ErrorCode::Io, m_what + ": names an empty file name");
    if (fs::path(name).is_absolute())
        throw Error(ErrorCode::Io, m_what + ": names '" + name +
                                       "', an absolute path (a scene file may name files in its own folder only)");
    return check((fs::path(m_folder) / name).string());
}

std::string NamedFiles::check(const std::string& path) const {
    const std::string what = m_what + ": names '" + path + "'";
    std::error_code ec;
    const fs::path canonical = fs::canonical(path, ec);
    if (ec) throw Error(ErrorCode::Io, what + ", which cannot be opened (" + ec.message() + ")");
    bool allowed = false;
    for (const std::string& folder : m_allowed) allowed = allowed || inside(canonical, folder);
    if (!allowed)
        throw Error(ErrorCode::Io, what + ", outside its folder " + m_folder +
                                       " (a scene file may name files in its own folder; --allow-dir allows another)");
    const fs::file_status status = fs::status(canonical, ec);
    if (ec || !fs::is_regular_file(status)) throw Error(ErrorCode::Io, what + ", not a regular file");
    // An input of this run like the files its command line names: no output may replace it.
    protectInput(canonical.string());
    return canonical.string();
}

}  // namespace conus::sceneio
