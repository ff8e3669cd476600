// The browser viewer's files (web/, embedded in the binary): what `conus web` writes into a folder
// and `conus serve` answers, so both give the same page.
#pragma once

#include <span>
#include <string>
#include <vector>

namespace conus::format {
struct ConusFile;
}

namespace conus::cli {

struct WebFile {
    std::string name;         // as the page names it: "index.html", "conus-view.js", ...
    std::string contentType;  // its HTTP media type
    std::string text;
};

// index.html (opening `defaultFile` when its URL names none; empty: none), conus-exr.js,
// conus-gl.js, conus-view.js and conus-shaders.js (renderers::viewFrameShaderEs as a script).
std::vector<WebFile> viewerFiles(const std::string& defaultFile);

// A script that hands `bytes` to the page as CONUS_FILES[name] (base64): how a page opened from
// disk (file://, where it cannot fetch) reads the CoNUS file beside it.
std::string embeddedFileScript(const std::string& name, std::span<const unsigned char> bytes);

// A file's bytes, as `conus web` copies them and `conus serve` sends them; conus::Error(Io) when
// it cannot be read.
std::vector<unsigned char> fileBytes(const std::string& path);

// `file` as the bytes of a CoNUS file, written through a private folder that only this process can
// enter (mkdtemp, 0700: no name another user can predict or plant a link at) and removed at once.
std::vector<unsigned char> conusFileBytes(const format::ConusFile& file);

}  // namespace conus::cli
