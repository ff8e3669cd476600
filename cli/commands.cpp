#include "commands.h"

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

}  // namespace conus::cli
