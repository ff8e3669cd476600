#include "commands.h"

#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>

#include "conus/core/error.h"

namespace conus::cli {

CLI::App* addSubcommand(CLI::App& parent, const std::string& name, const std::string& description,
                        std::initializer_list<const char*> examples) {
    CLI::App* command = parent.add_subcommand(name, description);
    setExamples(*command, examples);
    return command;
}

void setExamples(CLI::App& command, std::initializer_list<const char*> examples) {
    std::string footer = "Examples:";
    for (const char* example : examples) footer.append("\n  ").append(example);
    command.footer(footer);
}

Command addCommandGroup(CLI::App& parent, const std::string& name, const std::string& description,
                        std::initializer_list<CommandPart> parts) {
    CLI::App* group = parent.add_subcommand(name, description);
    group->require_subcommand(1);
    std::vector<Command> defined;
    for (const CommandPart& part : parts) defined.push_back(part(*group));
    return {group, [defined, name] {
                for (const Command& part : defined)
                    if (part.app->parsed()) return part.run();
                throw Error(ErrorCode::InvalidArgument, name + ": no subcommand given");
            }};
}

void acceptOldRenderOrder(int argc, char** argv) {
    if (argc < 3 || std::string(argv[2]) != "render") return;
    const std::string what = argv[1];
    if (what != "mesh" && what != "volume" && what != "heightfield") return;
    std::fprintf(stderr, "conus: `conus %s render` is spelled `conus render %s` now\n", what.c_str(), what.c_str());
    std::swap(argv[1], argv[2]);
}

}  // namespace conus::cli
