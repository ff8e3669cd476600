// Modules and system libraries loaded on first use (dlopen), so that start-up pays only for what
// every command needs.
#include "conus/core/plugin.h"

#include <dlfcn.h>

#include <filesystem>
#include <map>
#include <mutex>

#include "conus/core/error.h"

namespace conus {
namespace {

std::mutex& loaderMutex() {
    static std::mutex mutex;
    return mutex;
}

std::string loaderError() {
    const char* e = dlerror();
    return e ? e : "unknown reason";
}

// Where the shared object (or program) holding `anchor` lives.
std::filesystem::path directoryOf(const void* anchor) {
    Dl_info info{};
    if (dladdr(anchor, &info) && info.dli_fname && std::filesystem::path(info.dli_fname).is_absolute())
        return std::filesystem::path(info.dli_fname).parent_path();
    // The main program may be named as it was started (relative, or only a name on the PATH).
    std::error_code ec;
    const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
    if (ec) throw Error(ErrorCode::Unsupported, "cannot tell where this program's modules are: /proc/self/exe is unreadable");
    return self.parent_path();
}

}  // namespace

void* loadPluginSymbol(const void* anchor, const std::string& relativePath, const char* symbol) {
    const std::string path = (directoryOf(anchor) / relativePath).lexically_normal().string();
    std::lock_guard<std::mutex> lock(loaderMutex());
    // RTLD_LOCAL: a module's third-party symbols never become candidates for other lookups.
    void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) throw Error(ErrorCode::Unsupported, "cannot load the module " + path + ": " + loaderError());
    void* address = dlsym(handle, symbol);
    if (!address) throw Error(ErrorCode::Unsupported, "the module " + path + " lacks " + symbol + ": " + loaderError());
    return address;  // the handle stays open: what the module returned stays valid
}

void* loadSystemLibrary(const char* soname, std::string& reason) {
    std::lock_guard<std::mutex> lock(loaderMutex());
    void* handle = dlopen(soname, RTLD_NOW | RTLD_LOCAL);
    if (!handle) reason = std::string(soname) + " is not loadable: " + loaderError();
    return handle;
}

}  // namespace conus
