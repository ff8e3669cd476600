// The `conus` subcommands. Each lives in its own cmd_<name>.cpp, registers its options and help
// text on the root CLI11 app, and returns the function that runs it once parsing is done. A run
// function throws conus::Error (or std::exception) on failure; main.cpp turns that into the one
// line `conus <cmd>: <reason>` and a non-zero exit.
#pragma once

#include <functional>
#include <initializer_list>
#include <memory>
#include <string>

#include "conus/format/container.h"
#include "progress.h"

namespace CLI {
class App;
}

namespace conus::cli {

struct Command {
    CLI::App* app = nullptr;
    std::function<int()> run;  // returns the exit code (0 on success)
};

// A subcommand of `parent` with its one-line description and a help footer of examples, each
// "conus ...  # what it does" (every subcommand's --help shows two or three).
CLI::App* addSubcommand(CLI::App& parent, const std::string& name, const std::string& description,
                        std::initializer_list<const char*> examples);
void setExamples(CLI::App& command, std::initializer_list<const char*> examples);

// A (sub)command whose parsed options are one `Options` value: `declare` adds the subcommand to
// `parent` with its options bound to that value and returns it; `run` does the work once parsing is
// done. The value lives as long as the returned Command. Every such command takes --quiet.
template <class Options>
Command defineCommand(CLI::App& parent, CLI::App* (*declare)(CLI::App& parent, Options& options),
                      int (*run)(const Options& options)) {
    auto options = std::make_shared<Options>();
    CLI::App* app = declare(parent, *options);
    addQuietOption(*app);
    return {app, [options, run] { return run(*options); }};
}

// One part of a command group: a subcommand to define under the group's app (see defineCommand).
using CommandPart = std::function<Command(CLI::App& group)>;
template <class Options>
CommandPart commandPart(CLI::App* (*declare)(CLI::App& parent, Options& options), int (*run)(const Options& options)) {
    return [declare, run](CLI::App& group) { return defineCommand(group, declare, run); };
}

// A command whose work is done by exactly one of its subcommands (`conus mesh animate`, `conus render mesh | volume | ...`):
// the parts are defined under it, and running it runs the part the command line named.
Command addCommandGroup(CLI::App& parent, const std::string& name, const std::string& description,
                        std::initializer_list<CommandPart> parts);

// `conus render <what>`'s parts that live with their scene's other commands (cmd_mesh.cpp,
// cmd_volume.cpp, cmd_heightfield.cpp); cmd_render.cpp gathers them.
CommandPart meshRenderPart();
CommandPart volumeRenderPart();
CommandPart heightFieldRenderPart();

// The old word order `conus mesh|volume|heightfield render`, still taken: when argv spells it, it is
// turned into `conus render mesh|volume|heightfield` in place and the new spelling said on stderr.
void acceptOldRenderOrder(int argc, char** argv);

// The subcommands, in the order `conus --help` lists them: the one list, which declares each
// cmd_<name>.cpp's `Command add<Name>Command(CLI::App& root)` here and registers them in main.cpp.
#define CONUS_CLI_COMMANDS(X) \
    X(Encode) X(Uniform) X(Decode) X(Info) X(Validate) X(Demo) X(Map) X(HeightField) X(Mesh) X(Volume) X(Bake) X(Render) X(Web) X(Serve)
#define CONUS_CLI_DECLARE_COMMAND(Name) Command add##Name##Command(CLI::App& root);
CONUS_CLI_COMMANDS(CONUS_CLI_DECLARE_COMMAND)
#undef CONUS_CLI_DECLARE_COMMAND

// `decode --camera` of a height field as `heightfield render` does it (cmd_heightfield.cpp): the
// backend chosen, the frame (renderers::renderHeightFieldFrame) from a camera "x,y,z,lx,ly,lz,fovDeg"
// (empty: the ground map's own viewer) as a progress stage, the camera said.
Image heightFieldFrame(const format::ConusFile& file, const std::string& cameraText, int width, int height,
                       const std::string& backendName);

}  // namespace conus::cli
