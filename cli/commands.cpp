#include "commands.h"

#include <CLI/CLI.hpp>

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

}  // namespace conus::cli
