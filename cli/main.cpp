// conus: encode, decode, inspect and validate CoNUS files. See `conus --help`.
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "commands.h"
#include "conus/cli/option_checks.h"
#include "conus/core/atomic_file.h"
#include "conus/core/error.h"
#include "conus/format/container.h"
#include "output_files.h"
#include "progress.h"


int main(int argc, char** argv) {
    CLI::App app{"conus: coherent non-uniform sampling images (flexible pinhole camera)", "conus"};
    app.require_subcommand(1);
    app.footer(
        "Exit codes: 0 success; 1 failure (a file that cannot be read or written, an invalid file); 2 usage\n"
        "(an unknown option, a value out of range). Errors print one line: conus <command>: <reason>.\n"
        "`conus <command> --help` shows each command's options and examples.");
    conus::removeTemporariesOnSignals();
    app.set_version_flag("--version", std::string(conus::format::kSoftwareName) + " (CoNUS file format version " +
                                           std::to_string(conus::format::kFormatVersion) + ")");

#define CONUS_CLI_ADD_COMMAND(Name) conus::cli::add##Name##Command(app),
    std::vector<conus::cli::Command> commands{CONUS_CLI_COMMANDS(CONUS_CLI_ADD_COMMAND)};
#undef CONUS_CLI_ADD_COMMAND

    conus::cli::acceptOldRenderOrder(argc, argv);
    std::string name;
    // CLI11 would only say "a subcommand is required"; name the word it did not know instead.
    std::string known;
    bool isKnown = false;
    for (const auto& command : commands) {
        known += (known.empty() ? "" : ", ") + command.app->get_name();
        isKnown |= argc > 1 && command.app->get_name() == argv[1];
    }
    if (argc > 1 && argv[1][0] != '-' && !isKnown) {
        std::fprintf(stderr, "conus: unknown command '%s' (commands: %s; see --help)\n", argv[1], known.c_str());
        return 2;
    }
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        for (CLI::App* sub : app.get_subcommands()) name = sub->get_name();
        CLI::App* deepest = &app;  // the (sub)command whose options were being read
        while (!deepest->get_subcommands().empty()) deepest = deepest->get_subcommands().front();
        std::string reason = dynamic_cast<const CLI::ExtrasError*>(&e) ? conus::cli::unknownOptionLine(deepest, argc, argv) : "";
        if (reason.empty()) reason = conus::oneLine(e.what());
        std::fprintf(stderr, "conus%s%s: %s (see --help)\n", name.empty() ? "" : " ", name.c_str(), reason.c_str());
        return 2;
    }

    for (auto& command : commands) {
        if (!command.app->parsed()) continue;
        name = command.app->get_name();
        conus::cli::beginCommand(name);
        try {
            conus::cli::checkOutputsOfCommand(*command.app);
            const int code = command.run();
            if (code == 0) conus::cli::printTotal();
            return code;
        } catch (const conus::Error& e) {
            std::fprintf(stderr, "conus %s: %s\n", name.c_str(), e.what());
            return e.code() == conus::ErrorCode::InvalidArgument ? 2 : 1;
        } catch (const std::exception& e) {
            std::fprintf(stderr, "conus %s: %s\n", name.c_str(), conus::oneLine(e.what()).c_str());
            return 1;
        }
    }
    return 2;
}
