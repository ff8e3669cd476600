// A folder for the scene-reader harnesses: the input is written as `model.<ext>` inside
// /dev/shm (memory; the temporary folder where there is none)/conus-fuzz-<name>-<pid>/model/, beside files it may name (a small data file, a material
// library, a texture) and traps it must not open: a FIFO (opening it blocks: a timeout), a symbolic
// link out of the folder and a file outside it (../outside.bin). Made once per process.
#pragma once

#include <sys/stat.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "conus/core/error.h"
#include "fuzz.h"

class SceneFixture {
public:
    explicit SceneFixture(const std::string& name) {
        namespace fs = std::filesystem;
        std::error_code ec;
        const fs::path base = fs::is_directory("/dev/shm", ec) ? fs::path("/dev/shm") : fs::temp_directory_path();
        const fs::path root = base / ("conus-fuzz-" + name + "-" + std::to_string(::getpid()));
        m_folder = (root / "model").string();
        fs::create_directories(m_folder);
        std::ofstream(root / "outside.bin") << std::string(4096, '\x01');
        std::ofstream(fs::path(m_folder) / "data.bin") << std::string(4096, '\x02');
        std::ofstream(fs::path(m_folder) / "m.mtl") << "newmtl a\nKd 1 0 0\nmap_Kd texture.png\n";
        fs::create_symlink(root / "outside.bin", fs::path(m_folder) / "link.bin", ec);
        ::mkfifo((fs::path(m_folder) / "fifo.bin").c_str(), 0600);
    }
    ~SceneFixture() {
        std::error_code ec;
        std::filesystem::remove_all(std::filesystem::path(m_folder).parent_path(), ec);
    }
    // Writes the input as model.<ext> and returns its path.
    std::string write(const std::string& ext, const std::uint8_t* data, std::size_t size) const {
        const std::string path = m_folder + "/model." + ext;
        std::ofstream out(path, std::ios::binary | std::ios::trunc);
        out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
        CONUS_FUZZ_CHECK(out.good(), "writing the input");
        return path;
    }
    const std::string& folder() const { return m_folder; }

private:
    std::string m_folder;
};

inline bool startsWith(const std::uint8_t* data, std::size_t size, const char* prefix) {
    const std::string p(prefix);
    return size >= p.size() && std::string(reinterpret_cast<const char*>(data), p.size()) == p;
}
