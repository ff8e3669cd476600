// AtomicFile: checked writes to a temporary file, then one rename. The registry of open temporary
// files is a fixed array of slots so that the signal handler touches only async-signal-safe state.
#include "conus/core/atomic_file.h"

#include <fcntl.h>
#include <pthread.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <optional>
#include <utility>
#include <vector>
#include <system_error>

#include "conus/core/error.h"

namespace conus {
namespace fs = std::filesystem;
namespace {

// ---- temporaries removed on signals -----------------------------------------------------------

constexpr int kSlots = 256;
constexpr std::size_t kPathBytes = 4096;
enum SlotState : int { kFree = 0, kFilling = 1, kActive = 2 };
// A temporary is known by its name and by the file it was created as (device and inode): what
// is removed is only ever that file, never whatever has been put under its name since.
struct Slot {
    std::atomic<int> state{kFree};
    char path[kPathBytes];
    dev_t device;
    ino_t inode;
};
Slot g_slots[kSlots];

int registerTemporary(const std::string& path, dev_t device, ino_t inode) {
    if (path.size() + 1 > kPathBytes) return -1;
    for (int i = 0; i < kSlots; ++i) {
        int expected = kFree;
        if (!g_slots[i].state.compare_exchange_strong(expected, kFilling)) continue;
        std::memcpy(g_slots[i].path, path.c_str(), path.size() + 1);
        g_slots[i].device = device;
        g_slots[i].inode = inode;
        g_slots[i].state.store(kActive);
        return i;
    }
    return -1;  // more than kSlots files open at once: still atomic, just not cleaned on a signal
}

void unregisterTemporary(int slot) {
    if (slot >= 0) g_slots[slot].state.store(kFree);
}

// Whether `path` is still the file this process created there (async-signal-safe).
bool isOwnTemporary(const char* path, dev_t device, ino_t inode) {
    struct stat st {};
    return ::lstat(path, &st) == 0 && S_ISREG(st.st_mode) && st.st_dev == device && st.st_ino == inode;
}

// Removes `path` when it is still that file: never anything else put under its name.
void removeOwnTemporary(const char* path, dev_t device, ino_t inode) {
    if (isOwnTemporary(path, device, inode)) ::unlink(path);
}

extern "C" void removeTemporariesAndDie(int signal) {
    for (Slot& slot : g_slots)
        if (slot.state.load() == kActive) removeOwnTemporary(slot.path, slot.device, slot.inode);
    std::signal(signal, SIG_DFL);
    std::raise(signal);
}

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

// ---- temporary names --------------------------------------------------------------------------

// ".<stem>.tmp-<12 random letters and digits><ext>": unpredictable, so that nobody can plant a
// link or a file under the name before it is created (and creation is exclusive besides).
std::string temporaryName(const fs::path& target) {
    static constexpr char kAlphabet[] = "abcdefghijklmnopqrstuvwxyz0123456789";
    unsigned char random[12];
    std::size_t got = 0;
    while (got < sizeof random) {
        const ssize_t n = ::getrandom(random + got, sizeof random - got, 0);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) throw Error(ErrorCode::Io, "cannot name a temporary file: no random numbers (" + errnoText(errno) + ")");
        got += static_cast<std::size_t>(n);
    }
    std::string name = ".";
    name += target.stem().string();
    name += ".tmp-";
    for (unsigned char r : random) name += kAlphabet[r % (sizeof kAlphabet - 1)];
    name += target.extension().string();
    return name;
}

// ---- inputs that no output may replace ---------------------------------------------------------

std::mutex g_inputsMutex;
std::vector<std::pair<std::string, std::pair<dev_t, ino_t>>> g_inputs;  // as named, and the file

// The input that `path` (followed through links) is, if any.
std::optional<std::string> protectedInputAt(const std::string& path) {
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0) return std::nullopt;
    std::lock_guard lock(g_inputsMutex);
    for (const auto& [name, file] : g_inputs)
        if (file.first == st.st_dev && file.second == st.st_ino) return name;
    return std::nullopt;
}

[[noreturn]] void refuseInput(const std::string& output, const std::string& input) {
    throw Error(ErrorCode::InvalidArgument,
                "refusing to write " + output + ": it is the input " +
                    (input == output ? std::string("file") : input + " (the same file)") + "; name another output");
}

}  // namespace

void protectInput(const std::string& path) {
    if (path.empty() || path == "-") return;
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return;
    std::lock_guard lock(g_inputsMutex);
    // Once per file: a long-running process (a server, a fuzzer) reads the same files again.
    for (const auto& entry : g_inputs)
        if (entry.second.first == st.st_dev && entry.second.second == st.st_ino) return;
    g_inputs.push_back({path, {st.st_dev, st.st_ino}});
}

void checkNotAnInput(const std::string& output, std::span<const std::string> inputs) {
    if (const auto input = protectedInputAt(output)) refuseInput(output, *input);
    struct stat out {};
    if (::stat(output.c_str(), &out) != 0) return;  // absent (or unreachable): replaces nothing
    for (const std::string& input : inputs) {
        struct stat in {};
        if (input.empty() || input == "-" || ::stat(input.c_str(), &in) != 0) continue;
        if (in.st_dev == out.st_dev && in.st_ino == out.st_ino) refuseInput(output, input);
    }
}

// ---- AtomicFile --------------------------------------------------------------------------------

AtomicFile::AtomicFile(const std::string& destination) : m_destination(destination), m_target(targetOf(destination)) {
    if (destination.empty()) throw Error(ErrorCode::InvalidArgument, "no output file name given");
    checkReplaceable(m_destination, m_target, ErrorCode::Io);
    if (const auto input = protectedInputAt(m_target)) refuseInput(m_destination, *input);
    const fs::path target(m_target);
    const fs::path folder = target.parent_path().empty() ? fs::path(".") : target.parent_path();
    // Signals wait until the new file is registered, so that one arriving in between leaves nothing.
    sigset_t blocked, previous;
    sigemptyset(&blocked);
    for (int signal : {SIGINT, SIGTERM, SIGHUP}) sigaddset(&blocked, signal);
    ::pthread_sigmask(SIG_BLOCK, &blocked, &previous);
    int error = 0;
    for (int attempt = 0; attempt < 100 && m_fd < 0; ++attempt) {
        m_temporary = (folder / temporaryName(target)).string();
        // Exclusive and not through a link: a name someone else made (a file, a link) is never
        // opened, and the next random name is tried.
        m_fd = ::open(m_temporary.c_str(), O_RDWR | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
        error = errno;
        if (m_fd < 0 && error != EEXIST) break;
    }
    struct stat made {};
    if (m_fd >= 0 && ::fstat(m_fd, &made) == 0) {
        m_device = made.st_dev;
        m_inode = made.st_ino;
        m_slot = registerTemporary(m_temporary, m_device, m_inode);
    } else if (m_fd >= 0) {
        error = errno;
        ::close(m_fd);
        m_fd = -1;  // never stat'ed: not known to be ours, so left where it is
    }
    ::pthread_sigmask(SIG_SETMASK, &previous, nullptr);
    if (m_fd < 0) throw Error(ErrorCode::Io, "cannot write " + m_destination + ": " + errnoText(error));
    // Libraries that open by name reopen this very file through /proc, whatever is put under the
    // temporary's name meanwhile.
    m_openPath = "/proc/" + std::to_string(::getpid()) + "/fd/" + std::to_string(m_fd);
    struct stat viaProc {};
    if (::stat(m_openPath.c_str(), &viaProc) != 0 || viaProc.st_dev != m_device || viaProc.st_ino != m_inode)
        m_openPath = m_temporary;  // no /proc: the exclusively created name
    // A replaced file keeps its permissions.
    struct stat st {};
    if (::stat(m_target.c_str(), &st) == 0) ::fchmod(m_fd, st.st_mode & 07777);
    m_buffer.reserve(1 << 20);
}

AtomicFile::~AtomicFile() {
    if (m_committed) return;
    if (m_fd >= 0) ::close(m_fd);
    removeOwnTemporary(m_temporary.c_str(), m_device, m_inode);
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
        t_outputs->m_waiting.push_back({m_destination, m_target, m_temporary, m_device, m_inode, m_slot});
        m_committed = true;
        return;
    }
    // Refused again at the last moment: something may have appeared at the destination meanwhile,
    // or something else under the temporary's name.
    checkReplaceable(m_destination, m_target, ErrorCode::Io);
    if (!isOwnTemporary(m_temporary.c_str(), m_device, m_inode)) fail("the temporary file was replaced", 0);
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
    checkNotAnInput(output, inputs);
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
        removeOwnTemporary(w.temporary.c_str(), w.device, w.inode);
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
            if (!isOwnTemporary(w.temporary.c_str(), w.device, w.inode))
                throw Error(ErrorCode::Io, "cannot write " + w.destination + ": the temporary file was replaced");
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
