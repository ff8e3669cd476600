// The `conus` subcommands. Each lives in its own cmd_<name>.cpp, registers its options and help
// text on the root CLI11 app, and returns the function that runs it once parsing is done. A run
// function throws conus::Error (or std::exception) on failure; main.cpp turns that into the one
// line `conus <cmd>: <reason>` and a non-zero exit.
#pragma once

#include <functional>

namespace CLI {
class App;
}

namespace conus::cli {

struct Command {
    CLI::App* app = nullptr;
    std::function<int()> run;  // returns the exit code (0 on success)
};

Command addEncodeCommand(CLI::App& root);
Command addUniformCommand(CLI::App& root);
Command addDecodeCommand(CLI::App& root);
Command addInfoCommand(CLI::App& root);
Command addValidateCommand(CLI::App& root);
Command addDemoCommand(CLI::App& root);
Command addMapCommand(CLI::App& root);
Command addHeightFieldCommand(CLI::App& root);

}  // namespace conus::cli
