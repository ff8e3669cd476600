// Modules loaded on first use. A library whose dependencies are heavy (OpenImageIO's 260 shared
// libraries, OpenCV's detectors, Mesa's LLVM) keeps them out of every process's start-up by
// putting the code that calls them into a module (a CMake MODULE library) that sits beside the
// library or program needing it, and asks for it here when a command first needs it.
//
// How a new heavy library is added: its calls go into one .cpp built as a MODULE (see
// imageio/CMakeLists.txt, cli/CMakeLists.txt), which exports one extern "C" function returning a
// table; the loading side calls loadPluginSymbol once (a function-local static) and calls through
// the table. The module is linked with the conus libraries it uses, so conus::Error thrown inside it
// reaches the caller unchanged.
#pragma once

#include <string>

namespace conus {

// The address of `symbol` in the module at `relativePath` (relative to the directory of the shared
// object or program that holds `anchor`, any function of the caller's own library), loaded once
// and kept for the life of the process. Throws conus::Error(Unsupported), naming the file and the
// loader's reason, when the module is missing or lacks the symbol.
void* loadPluginSymbol(const void* anchor, const std::string& relativePath, const char* symbol);

// A system library (e.g. "libOSMesa.so.8") by its SONAME, loaded once and kept; nullptr and
// `reason` filled when it is not installed.
void* loadSystemLibrary(const char* soname, std::string& reason);

}  // namespace conus
