// conus serve: the browser viewer over HTTP (http_server.h), bound to localhost unless told
// otherwise. It answers the page and its scripts, the files of one folder, and
// GET /frame?file=NAME&focus=u,v,r,k&size=WxH: a CoNUS file of the picture NAME encoded on request
// around that focus (the filtered encode, not fitted: encode --fast), kept for the next identical
// request. The pictures themselves are kept decoded, with the box-filtered levels the encoder
// builds from them, within --memory: a new focus on a picture already asked for is an encode only.
// The page asked for with ?picture=NAME starts reading NAME and building its levels on a thread of
// their own while the browser loads the page, so that the page's first frame is mostly an encode.
// Names stay inside the folder (their canonical path is checked); a bad parameter is a 400 with
// one line, a name that is not there a 404.
#include <CLI/CLI.hpp>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <unistd.h>
#include <vector>

#include "arguments.h"
#include "backend.h"
#include "commands.h"
#include "conus/codec/builders/foci.h"
#include "conus/codec/image/encode.h"
#include "conus/core/error.h"
#include "conus/core/limits.h"
#include "conus/renderers/gpu_image.h"
#include "encoding.h"
#include "http_server.h"
#include "image_files.h"
#include "web_page.h"

namespace conus::cli {
namespace {

namespace fs = std::filesystem;

struct ServeOptions {
    std::string folder = ".";
    std::string host = "127.0.0.1";
    int port = 8080;
    int maxSide = 2048;     // the largest frame side /frame encodes
    int cacheFrames = 64;   // frames kept for repeated requests
    int memoryMiB = 4096;   // pictures kept decoded (and their encoder levels), at most this many MiB
    std::string backend = enumName(renderers::Backend::Auto);
};

// A request the server refuses: its status and one line.
// The largest file of the folder sent as it is (each is read whole into memory to be sent).
constexpr std::uintmax_t kMaxServedBytes = std::uintmax_t(1) << 30;

struct Refusal {
    int status;
    std::string line;
};

// `name` inside `root` (canonical): the file's canonical path, or the refusal (400 for a name that
// leaves the folder or is malformed, 404 for one that is not a regular file there).
fs::path confined(const fs::path& root, const std::string& name) {
    if (name.empty() || name.size() > 4096 || name.find('\0') != std::string::npos)
        throw Refusal{400, "file: a name of 1 to 4096 characters, without NUL"};
    std::error_code error;
    const fs::path path = fs::weakly_canonical(root / fs::path(name).relative_path(), error);
    if (error || fs::path(name).is_absolute()) throw Refusal{400, "file: " + name + " is outside the served folder"};
    auto r = root.begin();
    auto p = path.begin();
    for (; r != root.end(); ++r, ++p)
        if (p == path.end() || *p != *r) throw Refusal{400, "file: " + name + " is outside the served folder"};
    if (!fs::is_regular_file(path, error)) throw Refusal{404, "file: " + name + " is not a file in the served folder"};
    return path;
}

std::vector<double> numbers(const std::string& text, std::size_t count, const std::string& what) {
    std::vector<double> values;
    std::size_t at = 0;
    while (values.size() < count + 1 && at <= text.size()) {
        const std::size_t comma = std::min(text.find(',', at), text.size());
        const std::string item = text.substr(at, comma - at);
        char* end = nullptr;
        const double v = std::strtod(item.c_str(), &end);
        if (item.empty() || end != item.c_str() + item.size() || !std::isfinite(v))
            throw Refusal{400, what + ": expected " + std::to_string(count) + " finite numbers separated by commas"};
        values.push_back(v);
        at = comma + 1;
    }
    if (values.size() != count) throw Refusal{400, what + ": expected " + std::to_string(count) + " finite numbers separated by commas"};
    return values;
}

class FrameServer {
public:
    explicit FrameServer(const ServeOptions& o) : m_options(o), m_root(fs::canonical(o.folder)) {}
    ~FrameServer() {
        for (Warmer& w : m_warmers) w.thread.join();
    }
    FrameServer(const FrameServer&) = delete;
    FrameServer& operator=(const FrameServer&) = delete;

    const fs::path& root() const { return m_root; }

    // GET /frame: the CoNUS file's bytes, encoded now or kept from an identical request.
    std::vector<unsigned char> frame(const HttpRequest& request) {
        const auto param = [&](const char* name) {
            const auto found = request.params.find(name);
            if (found == request.params.end()) throw Refusal{400, std::string(name) + ": missing (frame?file=NAME&focus=u,v,r,k&size=WxH)"};
            return found->second;
        };
        const fs::path picture = confined(m_root, param("file"));
        const std::vector<double> f = numbers(param("focus"), 4, "focus");
        const codec::Focus focus{f[0], f[1], f[2], f[3]};
        try {
            codec::checkFocus(focus);
        } catch (const Error& e) {
            throw Refusal{400, std::string("focus: ") + e.what()};
        }
        const std::vector<double> s = numbers(replaceX(param("size")), 2, "size (WxH)");
        const int side = m_options.maxSide;
        if (s[0] != std::floor(s[0]) || s[1] != std::floor(s[1]) || s[0] < 16 || s[1] < 16 || s[0] > side || s[1] > side)
            throw Refusal{400, "size: each side a whole number of 16 to " + std::to_string(side) + " pixels"};
        const Size size{static_cast<int>(s[0]), static_cast<int>(s[1])};
        char keyText[128];
        std::snprintf(keyText, sizeof keyText, "|%.6g,%.6g,%.6g,%.6g|%dx%d", focus.u, focus.v, focus.r, focus.k, size.width, size.height);
        const std::string key = picture.string() + keyText;
        if (auto kept = cached(key)) return *kept;

        std::lock_guard encoding(m_encodeMutex);  // one encode at a time: it uses every core
        if (auto kept = cached(key)) return *kept;
        const auto start = std::chrono::steady_clock::now();
        bool readNow = false;
        Picture& kept = sourcePicture(picture, &readNow);
        const imageio::ImageFile& source = kept.file;
        if (size.width > source.image.width || size.height > source.image.height)
            throw Refusal{400, "size: " + std::to_string(size.width) + "x" + std::to_string(size.height) + " is larger than the picture (" +
                                   std::to_string(source.image.width) + "x" + std::to_string(source.image.height) + ")"};
        codec::FociOptions fo;
        fo.aspect = double(source.image.width) / source.image.height;
        const std::vector<codec::Focus> foci{focus};
        const auto seconds = [](auto from) { return std::chrono::duration<double>(std::chrono::steady_clock::now() - from).count(); };
        char read[32] = "kept";
        if (readNow) std::snprintf(read, sizeof read, "%.2f s", seconds(start));
        const auto mapStart = std::chrono::steady_clock::now();
        const codec::SamplingMap map = codec::buildFociMap(foci, fo);
        const double mapTime = seconds(mapStart);
        const auto encodeStart = std::chrono::steady_clock::now();
        const renderers::Device device = deviceFor(m_options.backend, renderers::CpuPath::Measured, "encoding", renderers::encodeSpeedProbe());
        format::ConusFile file = encodeToConus(device, source.image, source.info.encoding, map, size,
                                               codec::toAnalytic(foci, fo.composition, fo.falloff), {}, nullptr, "",
                                               &kept.levels);
        const double encodeTime = seconds(encodeStart);
        keepWithinMemory();
        const auto writeStart = std::chrono::steady_clock::now();
        applyStorage(StorageOptions{}, file);
        std::vector<unsigned char> bytes = conusFileBytes(file);
        if (!quiet())
            std::fprintf(stderr, "frame %s focus %s size %dx%d: %zu bytes in %.2f s (picture %s, map %.2f, encode %.2f, write %.2f)\n",
                         picture.filename().c_str(), param("focus").c_str(), size.width, size.height, bytes.size(),
                         seconds(start), read, mapTime, encodeTime, seconds(writeStart));
        keep(key, bytes);
        return bytes;
    }

    // The picture `name` read and its encoder levels built now, on a thread of its own (the page
    // that will ask for its frames is loading). Nothing where the name is refused, the picture is
    // kept with its levels already, or it is being prepared; a picture that cannot be read is left
    // for /frame to refuse.
    void warm(const std::string& name) {
        fs::path path;
        try {
            path = confined(m_root, name);
        } catch (const Refusal&) {
            return;
        }
        std::lock_guard lock(m_warmMutex);
        // At most kMaxWarming pictures waiting to be read: page requests for many names do not
        // queue unbounded work. Threads that have finished are joined here.
        constexpr std::size_t kMaxWarming = 4;
        std::erase_if(m_warmers, [](Warmer& w) {
            if (!w.done->load()) return false;
            w.thread.join();
            return true;
        });
        if (m_warming.size() >= kMaxWarming || m_warming.count(path)) return;
        auto done = std::make_shared<std::atomic<bool>>(false);
        // The thread's last step takes m_warmMutex, held here until `path` is in m_warming.
        m_warmers.push_back({std::thread([this, path, done] {
            try {
                const auto start = std::chrono::steady_clock::now();
                std::lock_guard encoding(m_encodeMutex);
                Picture& kept = sourcePicture(path);
                const double read = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
                if (kept.levels.bytes() == 0) codec::buildEncodeLevels(kept.file.image, kept.levels);
                keepWithinMemory();
                if (!quiet())
                    std::fprintf(stderr, "warm %s: picture and levels ready in %.2f s (picture %.2f)\n", path.filename().c_str(),
                                 std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), read);
            } catch (...) {  // /frame says what is wrong with it
            }
            std::lock_guard finished(m_warmMutex);
            m_warming.erase(path);
            done->store(true);
        }), done});
        m_warming.insert(path);
    }

private:
    static std::string replaceX(std::string text) {
        const std::size_t x = text.find('x');
        if (x != std::string::npos) text[x] = ',';
        return text;
    }

    std::optional<std::vector<unsigned char>> cached(const std::string& key) {
        std::lock_guard lock(m_cacheMutex);
        for (auto it = m_frames.begin(); it != m_frames.end(); ++it)
            if (it->first == key) {
                m_frames.splice(m_frames.begin(), m_frames, it);  // most recent first
                return it->second;
            }
        return std::nullopt;
    }

    void keep(const std::string& key, const std::vector<unsigned char>& bytes) {
        std::lock_guard lock(m_cacheMutex);
        m_frames.emplace_front(key, bytes);
        while (static_cast<int>(m_frames.size()) > m_options.cacheFrames) m_frames.pop_back();
    }

    // A picture kept decoded, with the levels the encoder built from it.
    struct Picture {
        fs::path path;
        fs::file_time_type written;
        imageio::ImageFile file;
        codec::EncodeLevels levels;
        std::int64_t bytes() const {
            return static_cast<std::int64_t>(file.image.pixels.size()) * std::int64_t(sizeof(float)) + levels.bytes();
        }
    };

    // The picture, read once while it is unchanged (a 4096^2 photo takes longer to read than to
    // encode), the most recently asked for first. Called under m_encodeMutex.
    // `readNow`, where given, says whether it was read (not kept).
    Picture& sourcePicture(const fs::path& path, bool* readNow = nullptr) {
        std::error_code error;
        const auto written = fs::last_write_time(path, error);
        for (auto it = m_pictures.begin(); it != m_pictures.end(); ++it)
            if (it->path == path) {
                if (it->written == written) {
                    m_pictures.splice(m_pictures.begin(), m_pictures, it);
                    return m_pictures.front();
                }
                m_pictures.erase(it);  // changed on disk: read again
                break;
            }
        Picture picture{path, written, {}, {}};
        if (readNow) *readNow = true;
        try {
            picture.file = readSource(path.string(), SourceOptions{});
        } catch (const Error& e) {
            throw Refusal{400, "file: " + std::string(e.what())};
        }
        m_pictures.push_front(std::move(picture));
        return m_pictures.front();
    }

    // The least recently asked for pictures let go until the rest fit in --memory; one that does
    // not fit alone first lets go of its levels, then is not kept either.
    void keepWithinMemory() {
        const std::int64_t cap = std::int64_t(m_options.memoryMiB) << 20;
        const auto total = [&] {
            std::int64_t sum = 0;
            for (const Picture& p : m_pictures) sum += p.bytes();
            return sum;
        };
        while (m_pictures.size() > 1 && total() > cap) m_pictures.pop_back();
        if (!m_pictures.empty() && total() > cap) m_pictures.front().levels.clear();
        if (!m_pictures.empty() && total() > cap) m_pictures.clear();
    }

    ServeOptions m_options;
    fs::path m_root;
    std::mutex m_encodeMutex, m_cacheMutex;
    std::list<std::pair<std::string, std::vector<unsigned char>>> m_frames;
    std::list<Picture> m_pictures;
    std::mutex m_warmMutex;
    std::set<fs::path> m_warming;        // pictures being prepared by warm()
    struct Warmer {
        std::thread thread;
        std::shared_ptr<std::atomic<bool>> done;  // set as its last step: join() returns at once
    };
    std::vector<Warmer> m_warmers;  // joined as they finish, and when the server goes
};

std::string contentTypeOf(const fs::path& path) {
    const std::string e = path.extension().string();
    if (e == ".html") return "text/html; charset=utf-8";
    if (e == ".js") return "text/javascript; charset=utf-8";
    if (e == ".png") return "image/png";
    if (e == ".jpg" || e == ".jpeg") return "image/jpeg";
    return "application/octet-stream";
}

int runServe(const ServeOptions& o) {
    if (!fs::is_directory(o.folder)) throw Error(ErrorCode::InvalidArgument, o.folder + ": not a folder");
    FrameServer frames(o);
    const std::vector<WebFile> page = viewerFiles("");
    const auto text = [](int status, const std::string& line) { return HttpReply{status, "text/plain; charset=utf-8", line + "\n"}; };
    const HttpHandler handler = [&](const HttpRequest& request) -> HttpReply {
        try {
            const std::string name = request.path == "/" ? "index.html" : request.path.substr(1);
            if (name == "index.html" && request.params.count("picture")) frames.warm(request.params.at("picture"));
            for (const WebFile& f : page)
                if (f.name == name) return {200, f.contentType, f.text};
            if (name == "frame") {
                const std::vector<unsigned char> bytes = frames.frame(request);
                return {200, "image/x-exr", std::string(bytes.begin(), bytes.end())};
            }
            // Any other name: a file of the folder.
            const fs::path path = confined(frames.root(), name);
            std::error_code ec;
            if (fs::file_size(path, ec) > kMaxServedBytes && !ec)
                throw Refusal{413, name + ": larger than " + std::to_string(kMaxServedBytes >> 20) + " MiB, which conus serve does not send"};
            const std::vector<unsigned char> bytes = fileBytes(path.string());
            return {200, contentTypeOf(path), std::string(bytes.begin(), bytes.end())};
        } catch (const Refusal& r) {
            return text(r.status, r.line);
        } catch (const std::exception& e) {
            return text(500, e.what());
        }
    };
    serveHttp(o.host, o.port, handler, [&](int port) {
        std::printf("serving %s at http://%s:%d/ (Ctrl-C stops)\n", frames.root().c_str(), o.host.c_str(), port);
        std::fflush(stdout);
    });
    return 0;
}

CLI::App* declareServe(CLI::App& root, ServeOptions& options) {
    CLI::App* command = addSubcommand(root, "serve", "Serve the browser viewer and CoNUS frames encoded on request around where one looks",
        {"conus serve site --port 8080            # http://127.0.0.1:8080/?file=photo.exr: a file written by conus web",
         "conus serve photos --port 8080          # http://127.0.0.1:8080/?picture=big.jpg: frames sharp where you double-click",
         "conus serve photos --port 0             # any free port (the line it prints names it)"});
    command->add_option("folder", options.folder, "folder whose files are served (default: the current one)");
    command->add_option("--port", options.port, "port to listen on (0: any free one)")->check(CLI::Range(0, 65535));
    command->add_option("--host", options.host, "address to listen on (default 127.0.0.1: this machine only)");
    command->add_option("--max-side", options.maxSide, "the largest side of a frame /frame encodes")->check(CLI::Range(16, 8192));
    command->add_option("--cache", options.cacheFrames, "frames kept for repeated requests")->check(CLI::Range(0, 4096));
    command->add_option("--memory", options.memoryMiB,
                        "MiB of pictures kept decoded between requests, with the levels the encoder builds from them "
                        "(a new focus on a kept picture is an encode only)")
        ->capture_default_str()
        ->check(CLI::Range(0, 1 << 20));
    addBackendOption(*command, options.backend);
    return command;
}

}  // namespace

Command addServeCommand(CLI::App& root) { return defineCommand(root, declareServe, runServe); }

}  // namespace conus::cli
