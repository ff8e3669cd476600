// conus web: a folder that shows one CoNUS file in a browser (web/: the page reads the file and
// reconstructs its frames with Equation 1 in WebGL2), with no build step and no network.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <unistd.h>
#include <vector>

#include "commands.h"
#include "conus/core/atomic_file.h"
#include "conus/core/error.h"
#include "conus/format/container.h"
#include "conus/format/names.h"
#include "output_files.h"
#include "progress.h"
#include "web_page.h"

namespace conus::cli {
namespace {

struct WebOptions {
    std::string input, output;
};

// The file's bytes as the page reads them: as they are when stored uncompressed or with zip (the
// compressions the page decodes), else the same file written again with zip.
std::vector<unsigned char> pageBytes(const std::string& input, const format::ConusFile& file) {
    if (file.compression == format::Compression::None || file.compression == format::Compression::Zip) return fileBytes(input);
    format::ConusFile zipped = file;
    zipped.compression = format::Compression::Zip;
    return conusFileBytes(zipped);
}

int runWeb(const WebOptions& o) {
    checkInputPath(o.input);
    const std::string name = std::filesystem::path(o.input).filename().string();
    const std::filesystem::path copy = std::filesystem::path(o.output) / name;
    std::error_code same;
    if (std::filesystem::equivalent(copy, o.input, same))
        throw Error(ErrorCode::InvalidArgument, o.input + " is in " + o.output + " already; give another folder for the page");
    Progress reading("read " + o.input);
    const format::ConusFile file = format::readConusFile(o.input);  // a file the page would refuse is refused here
    reading.done();
    const std::vector<unsigned char> bytes = pageBytes(o.input, file);

    AtomicOutputs outputs;  // the page, its scripts and the file, all or none
    outputs.makeFolder(o.output);
    const std::filesystem::path folder(o.output);
    const auto write = [&](const std::string& fileName, std::span<const unsigned char> data) {
        writeFileAtomically((folder / fileName).string(), data);
    };
    const auto asBytes = [](const std::string& text) {
        return std::span<const unsigned char>(reinterpret_cast<const unsigned char*>(text.data()), text.size());
    };
    for (const WebFile& f : viewerFiles(name)) write(f.name, asBytes(f.text));
    write(name, bytes);
    write(name + ".js", asBytes(embeddedFileScript(name, bytes)));
    outputs.commit();
    if (!quiet())
        std::printf("wrote %s: the viewer of %s (a %dx%d CoNUS image of a %dx%d frame); open it in a browser, or run "
                    "`conus serve %s`\n",
                    (folder / "index.html").string().c_str(), name.c_str(), file.image.width, file.image.height,
                    file.sourceWidth, file.sourceHeight, o.output.c_str());
    return 0;
}

CLI::App* declareWeb(CLI::App& root, WebOptions& options) {
    CLI::App* command = addSubcommand(root, "web", "Write a folder whose index.html shows a CoNUS file in a browser (WebGL2, no network)",
        {"conus web photo.exr -o photo-web          # open photo-web/index.html: drag to pan, wheel to zoom",
         "conus web photo.exr -o site && conus serve site --port 8080   # the same page over HTTP"});
    command->add_option("input", options.input, "CoNUS file (.exr)")->required();
    writesFile(command->add_option("-o,--output", options.output, "folder to write (made if missing): index.html, its scripts, a copy of the file"))
        ->required();
    return command;
}

}  // namespace

Command addWebCommand(CLI::App& root) { return defineCommand(root, declareWeb, runWeb); }

}  // namespace conus::cli
