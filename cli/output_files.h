// Outputs that are inputs, refused for every command in one place (main.cpp, before the work):
// each option that names a file the command writes is marked with writesFile() where it is
// declared; every other value on the command line that names an existing regular file is one of
// the command's inputs.
#pragma once

namespace CLI {
class App;
class Option;
}  // namespace CLI

namespace conus::cli {

// Marks `option` as naming a file the command writes; returns it (for chaining).
CLI::Option* writesFile(CLI::Option* option);

// Before `command` (the subcommand the command line named, with its parents) runs: protects
// every input it names (core protectInput, so that no AtomicFile of this run replaces one, however
// its path was worked out), and refuses, with "refusing to write X: it is the input Y ...", an
// output that is one of them (the same file by device and inode, links followed) or two outputs
// that are the same file. Throws conus::Error(InvalidArgument).
void checkOutputsOfCommand(const CLI::App& command);

}  // namespace conus::cli
