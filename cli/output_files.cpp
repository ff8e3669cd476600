#include "output_files.h"

#include <sys/stat.h>

#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "conus/core/atomic_file.h"
#include "conus/core/error.h"
#include "conus/sceneio/volume_file.h"

namespace conus::cli {
namespace {

std::set<const CLI::Option*>& outputOptions() {
    static std::set<const CLI::Option*> options;
    return options;
}

struct Output {
    std::string path, option;  // the option that names it, for messages
};

struct Given {
    std::vector<std::string> inputs;
    std::vector<Output> outputs;
};

void collect(const CLI::App& app, Given& given) {
    for (const CLI::Option* option : app.get_options()) {
        if (option->count() == 0) continue;
        const bool writes = outputOptions().count(option) > 0;
        for (const std::string& value : option->results()) {
            if (value.empty()) continue;
            if (writes) {
                given.outputs.push_back({value, option->get_name()});
                continue;
            }
            // A raw volume's path is inside its specification ("raw:WxHxD:type[:spacing]:path").
            std::string path = value;
            if (value.rfind("raw:", 0) == 0) try {
                    path = sceneio::parseRawSpec(value).path;
                } catch (const Error&) {  // not a raw spec after all: the reader says so
                }
            struct stat st {};
            if (path != "-" && ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode)) given.inputs.push_back(path);
        }
    }
    for (const CLI::App* sub : app.get_subcommands()) collect(*sub, given);
}

// What a write to `path` replaces: the existing file (by device and inode), else the full path
// the new file will have.
std::string identityOf(const std::string& path) {
    struct stat st {};
    if (::stat(path.c_str(), &st) == 0) return "file " + std::to_string(st.st_dev) + ":" + std::to_string(st.st_ino);
    std::error_code ec;
    const std::filesystem::path full = std::filesystem::weakly_canonical(std::filesystem::absolute(path, ec), ec);
    return "path " + (ec ? path : full.string());
}

}  // namespace

CLI::Option* writesFile(CLI::Option* option) {
    outputOptions().insert(option);
    return option;
}

void checkOutputsOfCommand(const CLI::App& command) {
    const CLI::App* root = &command;
    while (root->get_parent()) root = root->get_parent();
    Given given;
    collect(*root, given);
    for (const std::string& input : given.inputs) protectInput(input);
    for (std::size_t i = 0; i < given.outputs.size(); ++i) {
        const Output& output = given.outputs[i];
        checkNotAnInput(output.path, given.inputs);
        for (std::size_t j = 0; j < i; ++j)
            if (identityOf(output.path) == identityOf(given.outputs[j].path))
                throw Error(ErrorCode::InvalidArgument, "refusing to write " + output.path + ": " + output.option + " and " +
                                                            given.outputs[j].option + " name the same file; name another output");
    }
}

}  // namespace conus::cli
