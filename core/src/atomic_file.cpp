// AtomicFile: checked writes to a temporary file, then one rename. The registry of open temporary
// files is a fixed array of slots so that the signal handler touches only async-signal-safe state.
#include "conus/core/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <regex>
#include <set>
#include <sstream>
#include <system_error>

#include "conus/core/error.h"

namespace conus {
namespace fs = std::filesystem;
namespace {

// ---- temporaries removed on signals -----------------------------------------------------------

constexpr int kSlots = 256;
constexpr std::size_t kPathBytes = 4096;
enum SlotState : int { kFree = 0, kFilling = 1, kActive = 2 };
struct Slot {
    std::atomic<int> state{kFree};
    char path[kPathBytes];
};
Slot g_slots[kSlots];

int registerTemporary(const std::string& path) {
    if (path.size() + 1 > kPathBytes) return -1;
    for (int i = 0; i < kSlots; ++i) {
        int expected = kFree;
        if (!g_slots[i].state.compare_exchange_strong(expected, kFilling)) continue;
        std::memcpy(g_slots[i].path, path.c_str(), path.size() + 1);
        g_slots[i].state.store(kActive);
        return i;
    }
    return -1;  // more than kSlots files open at once: still atomic, just not cleaned on a signal
}

void unregisterTemporary(int slot) {
    if (slot >= 0) g_slots[slot].state.store(kFree);
}

extern "C" void removeTemporariesAndDie(int signal) {
    for (Slot& slot : g_slots)
        if (slot.state.load() == kActive) ::unlink(slot.path);
    std::signal(signal, SIG_DFL);
    std::raise(signal);
}

std::atomic<unsigned> g_counter{0};

// The set of outputs this thread's commits wait in, if any (AtomicOutputs).
thread_local AtomicOutputs* t_outputs = nullptr;

std::string errnoText(int error) { return std::strerror(error); }

// The file a write to `destination` replaces: a symbolic link's target, else the path itself.
std::string targetOf(const std::string& destination) {
    std::error_code ec;
    if (fs::is_symlink(fs::symlink_status(destination, ec))) {
        const fs::path resolved = fs::canonical(destination, ec);
        if (!ec) return resolved.string();
    }
    return destination;
}

// Refuses an existing destination that a rename must not replace. Throws with `code`.
void checkReplaceable(const std::string& destination, const std::string& target, ErrorCode code) {
    struct stat st {};
    if (::stat(target.c_str(), &st) != 0) return;  // absent: it will be created
    if (S_ISDIR(st.st_mode)) throw Error(code, destination + " is a directory; give a file name");
    if (!S_ISREG(st.st_mode))
        throw Error(code, destination +
                              " is not a regular file (a device, FIFO or socket); CoNUS writes regular files only");
}

// ---- stale temporaries -------------------------------------------------------------------------

// ".<stem>.tmp-<pid>-<n><ext>": what the constructor below names a temporary.
std::string temporaryName(const fs::path& target) {
    return "." + target.stem().string() + ".tmp-" + std::to_string(::getpid()) + "-" +
           std::to_string(g_counter.fetch_add(1)) + target.extension().string();
}

// When process `pid` started, in seconds since the epoch; -1 when no such process runs.
double processStart(long pid) {
    std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
    std::string text;
    if (!std::getline(stat, text)) return ::kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM ? 0.0 : -1.0;
    // Field 22 (starttime, clock ticks after boot) follows the command name in parentheses.
    const std::size_t close = text.rfind(')');
    if (close == std::string::npos) return 0.0;
    std::istringstream fields(text.substr(close + 2));
    std::string field;
    for (int i = 3; i < 22 && fields >> field;) ++i;
    double ticks = 0;
    if (!(fields >> ticks)) return 0.0;
    std::ifstream boot("/proc/stat");
    double bootTime = 0;
    for (std::string line; std::getline(boot, line);)
        if (line.rfind("btime ", 0) == 0) bootTime = std::stod(line.substr(6));
    return bootTime + ticks / double(::sysconf(_SC_CLK_TCK));
}

}  // namespace

void removeStaleTemporaries(const std::string& folder) {
    static std::mutex mutex;
    static std::set<std::string> done;
    std::error_code ec;
    const std::string key = fs::weakly_canonical(folder.empty() ? "." : folder, ec).string();
    {
        std::lock_guard lock(mutex);
        if (!done.insert(key).second) return;
    }
    static const std::regex kName(R"(\..*\.tmp-([0-9]{1,9})-[0-9]{1,10}(\.[^.]*)?)");
    fs::directory_iterator entries(folder.empty() ? "." : folder, ec);
    if (ec) return;
    for (; entries != fs::directory_iterator(); entries.increment(ec)) {
        if (ec) return;
        const std::string name = entries->path().filename().string();
        std::smatch m;
        if (name.empty() || name[0] != '.' || !std::regex_match(name, m, kName)) continue;
        const long pid = std::stol(m[1].str());
        if (pid == ::getpid()) continue;
        struct stat st {};
        if (::lstat(entries->path().c_str(), &st) != 0 || !(S_ISREG(st.st_mode) || S_ISDIR(st.st_mode))) continue;
        const double started = processStart(pid);
        if (started >= 0 && started <= double(st.st_mtime) + 1) continue;  // its process still runs
        fs::remove_all(entries->path(), ec);
    }
}

// ---- AtomicFile --------------------------------------------------------------------------------

AtomicFile::AtomicFile(const std::string& destination) : m_destination(destination), m_target(targetOf(destination)) {
    if (destination.empty()) throw Error(ErrorCode::InvalidArgument, "no output file name given");
    checkReplaceable(m_destination, m_target, ErrorCode::Io);
    const fs::path target(m_target);
    const fs::path folder = target.parent_path().empty() ? fs::path(".") : target.parent_path();
    removeStaleTemporaries(folder.string());
    m_temporary = (folder / temporaryName(target)).string();
    // Registered before it exists, so a signal between open and registration leaves nothing.
    m_slot = registerTemporary(m_temporary);
    m_fd = ::open(m_temporary.c_str(), O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (m_fd < 0) {
        const int error = errno;
        unregisterTemporary(m_slot);
        throw Error(ErrorCode::Io, "cannot write " + m_destination + ": " + errnoText(error));
    }
    // A replaced file keeps its permissions.
    struct stat st {};
    if (::stat(m_target.c_str(), &st) == 0) ::fchmod(m_fd, st.st_mode & 07777);
    m_buffer.reserve(1 << 20);
}

AtomicFile::~AtomicFile() {
    if (m_committed) return;
    if (m_fd >= 0) ::close(m_fd);
    ::unlink(m_temporary.c_str());
    unregisterTemporary(m_slot);
}

void AtomicFile::fail(const std::string& what, int error) {
    throw Error(ErrorCode::Io, "cannot write " + m_destination + ": " + what + (error ? ": " + errnoText(error) : ""));
}

void AtomicFile::flushBuffer() {
    const unsigned char* p = m_buffer.data();
    std::size_t left = m_buffer.size();
    off_t at = static_cast<off_t>(m_size - left);
    while (left > 0) {
        const ssize_t n = ::pwrite(m_fd, p, left, at);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) fail("write failed", n < 0 ? errno : ENOSPC);
        p += n, left -= static_cast<std::size_t>(n), at += n;
    }
    m_buffer.clear();
}

void AtomicFile::write(const void* data, std::size_t size) {
    if (m_fd < 0) fail("the file is already closed", 0);
    const auto* bytes = static_cast<const unsigned char*>(data);
    if (m_buffer.size() + size > m_buffer.capacity()) {
        flushBuffer();
        if (size >= m_buffer.capacity()) {  // large writes go straight through
            writeAt(m_size, data, size);
            return;
        }
    }
    m_buffer.insert(m_buffer.end(), bytes, bytes + size);
    m_size += size;
}

void AtomicFile::writeAt(std::uint64_t offset, const void* data, std::size_t size) {
    if (m_fd < 0) fail("the file is already closed", 0);
    flushBuffer();
    const auto* p = static_cast<const unsigned char*>(data);
    std::size_t left = size;
    auto at = static_cast<off_t>(offset);
    while (left > 0) {
        const ssize_t n = ::pwrite(m_fd, p, left, at);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) fail("write failed", n < 0 ? errno : ENOSPC);
        p += n, left -= static_cast<std::size_t>(n), at += n;
    }
    m_size = std::max<std::uint64_t>(m_size, offset + size);
}

std::size_t AtomicFile::readAt(std::uint64_t offset, void* data, std::size_t size) {
    if (m_fd < 0) fail("the file is already closed", 0);
    flushBuffer();
    auto* p = static_cast<unsigned char*>(data);
    std::size_t done = 0;
    while (done < size) {
        const ssize_t n = ::pread(m_fd, p + done, size - done, static_cast<off_t>(offset + done));
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) fail("cannot read back what was written", errno);
        if (n == 0) break;
        done += static_cast<std::size_t>(n);
    }
    return done;
}

void AtomicFile::commit() {
    if (m_fd < 0) fail("the file is already closed", 0);
    flushBuffer();
    if (::fsync(m_fd) != 0 && errno != EINVAL && errno != EROFS) fail("cannot flush it to disk", errno);
    const int fd = m_fd;
    m_fd = -1;
    if (::close(fd) != 0) fail("cannot close it", errno);
    if (t_outputs) {  // finished; renamed with the rest of the command's outputs
        t_outputs->m_waiting.push_back({m_destination, m_target, m_temporary, m_slot});
        m_committed = true;
        return;
    }
    // Refused again at the last moment: something may have appeared at the destination meanwhile.
    checkReplaceable(m_destination, m_target, ErrorCode::Io);
    if (::rename(m_temporary.c_str(), m_target.c_str()) != 0) fail("cannot move the finished file into place", errno);
    m_committed = true;
    unregisterTemporary(m_slot);
}

void writeFileAtomically(const std::string& destination, std::span<const unsigned char> bytes) {
    AtomicFile file(destination);
    file.write(bytes.data(), bytes.size());
    file.commit();
}

// ---- path checks -------------------------------------------------------------------------------

void checkOutputPath(const std::string& output, std::span<const std::string> inputs) {
    if (output.empty()) throw Error(ErrorCode::InvalidArgument, "no output file name given");
    const std::string target = targetOf(output);
    checkReplaceable(output, target, ErrorCode::InvalidArgument);
    const fs::path folder = fs::path(target).parent_path();
    std::error_code ec;
    if (!folder.empty() && !fs::is_directory(folder, ec))
        throw Error(ErrorCode::InvalidArgument, output + ": the folder " + folder.string() + " does not exist");
    for (const std::string& input : inputs) {
        if (input.empty() || input == "-") continue;
        if (fs::equivalent(input, output, ec))
            throw Error(ErrorCode::InvalidArgument, "the output " + output + " is the input file " + input +
                                                        "; writing it would destroy the input");
    }
}

void checkInputPath(const std::string& input, bool allowStdin) {
    if (input == "-") {
        if (allowStdin) return;
        throw Error(ErrorCode::Io, "this input cannot be read from standard input ('-')");
    }
    struct stat st {};
    if (::stat(input.c_str(), &st) != 0) {
        const int error = errno;
        throw Error(ErrorCode::Io, input + ": " + (error == ENOENT ? std::string("no such file") : errnoText(error)));
    }
    if (S_ISDIR(st.st_mode)) throw Error(ErrorCode::Io, input + " is a directory, not a file");
    if (!S_ISREG(st.st_mode))
        throw Error(ErrorCode::Io, input + " is not a regular file (a device, FIFO or socket), which could be read "
                                           "forever; CoNUS reads regular files" +
                                       std::string(allowStdin ? " or standard input ('-')" : ""));
}

void removeTemporariesOnSignals() {
    struct sigaction action {};
    action.sa_handler = &removeTemporariesAndDie;
    sigemptyset(&action.sa_mask);
    action.sa_flags = SA_RESETHAND;
    for (int signal : {SIGINT, SIGTERM, SIGHUP}) ::sigaction(signal, &action, nullptr);
    std::signal(SIGXFSZ, SIG_IGN);
}

// ---- AtomicOutputs -----------------------------------------------------------------------------

AtomicOutputs::AtomicOutputs() : m_outer(t_outputs) { t_outputs = this; }

AtomicOutputs::~AtomicOutputs() {
    if (t_outputs == this) t_outputs = m_outer;
    if (m_committed) return;
    for (const Waiting& w : m_waiting) {
        ::unlink(w.temporary.c_str());
        unregisterTemporary(w.slot);
    }
    std::error_code ec;
    for (auto folder = m_madeFolders.rbegin(); folder != m_madeFolders.rend(); ++folder)
        if (fs::is_empty(*folder, ec)) fs::remove(*folder, ec);
}

void AtomicOutputs::makeFolder(const std::string& folder) {
    std::vector<fs::path> missing;
    std::error_code ec;
    fs::path deepest = fs::path(folder).lexically_normal();
    if (deepest.filename().empty()) deepest = deepest.parent_path();  // "out/"
    for (fs::path p = deepest; !p.empty() && !fs::exists(p, ec); p = p.parent_path()) {
        missing.push_back(p);
        if (p == p.parent_path()) break;
    }
    fs::create_directories(folder, ec);
    if (ec || !fs::is_directory(folder, ec))
        throw Error(ErrorCode::Io, "cannot make the folder " + folder + (ec ? ": " + ec.message() : ": a file has that name"));
    for (auto p = missing.rbegin(); p != missing.rend(); ++p) m_madeFolders.push_back(p->string());
}

void AtomicOutputs::commit() {
    if (m_committed) return;
    if (t_outputs == this) t_outputs = m_outer;  // what is written from now on is not this set's
    if (m_outer) {
        m_outer->m_waiting.insert(m_outer->m_waiting.end(), m_waiting.begin(), m_waiting.end());
        m_outer->m_madeFolders.insert(m_outer->m_madeFolders.end(), m_madeFolders.begin(), m_madeFolders.end());
        m_committed = true;
        return;
    }
    for (std::size_t renamed = 0; renamed < m_waiting.size(); ++renamed) {
        const Waiting& w = m_waiting[renamed];
        try {
            checkReplaceable(w.destination, w.target, ErrorCode::Io);
            if (::rename(w.temporary.c_str(), w.target.c_str()) != 0) {
                const int error = errno;
                throw Error(ErrorCode::Io, "cannot write " + w.destination + ": cannot move the finished file into place: " +
                                               errnoText(error));
            }
        } catch (const Error&) {
            m_waiting.erase(m_waiting.begin(), m_waiting.begin() + std::ptrdiff_t(renamed));  // in place already
            throw;
        }
        unregisterTemporary(w.slot);
    }
    m_waiting.clear();
    m_committed = true;
}

}  // namespace conus
