// The one way CoNUS writes a file: all or nothing.
//
// Rules shared by everything here:
// - Bytes go to a temporary file beside the destination (".<stem>.tmp-<12 random letters and
//   digits><ext>"), created exclusively and never through a symbolic link (O_CREAT | O_EXCL |
//   O_NOFOLLOW), so a name planted in advance is never opened. Every write is checked, and commit() flushes, syncs and closes
//   the file, checking each step, before it renames the file over the destination. A reader never
//   sees a half-written file, and an existing destination survives any failure.
// - A destination that is a symbolic link is written through: the link's target is replaced.
// - A destination that exists and is not a regular file (directory, device, FIFO, socket) is
//   refused before anything is written.
// - Errors are conus::Error(Io) and name the destination the user gave, never the temporary file.
// - CoNUS removes only the temporaries this process created, each known by its name and its file
//   (device and inode): on failure, and on SIGINT, SIGTERM or SIGHUP once the program has called
//   removeTemporariesOnSignals() (libraries never install handlers). Nothing else in a folder is
//   ever removed, whatever its name looks like: what SIGKILL or a power cut leaves (a dot-file
//   ".<stem>.tmp-...") stays for the user to delete.
// - A destination that is one of the inputs protectInput() named (the same file by device and
//   inode, through links) is refused.
#pragma once

#include <sys/types.h>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

namespace conus {

class AtomicFile {
public:
    // Creates the temporary file. Throws conus::Error(Io) when the destination cannot be written.
    explicit AtomicFile(const std::string& destination);
    ~AtomicFile();  // removes the temporary file unless commit() succeeded
    AtomicFile(const AtomicFile&) = delete;
    AtomicFile& operator=(const AtomicFile&) = delete;

    const std::string& destination() const { return m_destination; }
    // Where a library (or a program) that only writes by path may write instead, until commit():
    // /proc/<pid>/fd/<n>, which reopens the very file created, whatever is put under its name
    // meanwhile (the temporary's name itself where /proc is missing).
    const std::string& temporaryPath() const { return m_openPath; }

    // Appends at the current end (sequential writers) or writes at an offset (writers that seek
    // back to fill in a table). Both throw conus::Error(Io) naming the destination on failure.
    void write(const void* data, std::size_t size);
    void writeAt(std::uint64_t offset, const void* data, std::size_t size);
    std::uint64_t size() const { return m_size; }
    // Reads back what was written (writers that patch a header read it first); returns the bytes read.
    std::size_t readAt(std::uint64_t offset, void* data, std::size_t size);

    // Flushes, syncs and closes the temporary file, then renames it over the destination (inside
    // an AtomicOutputs, when the set is committed).
    void commit();

private:
    void flushBuffer();
    [[noreturn]] void fail(const std::string& what, int error);

    std::string m_destination;  // as the user gave it, for messages
    std::string m_target;       // the file the rename replaces (a symlink's target)
    std::string m_temporary;
    std::string m_openPath;  // temporaryPath()
    int m_fd = -1;
    dev_t m_device = 0;  // the temporary file as created: only that file is ever removed
    ino_t m_inode = 0;
    int m_slot = -1;  // in the registry of temporaries removed on signals
    std::uint64_t m_size = 0;
    std::vector<unsigned char> m_buffer;  // pending sequential bytes, written at m_size - pending
    bool m_committed = false;
};

// Writes `bytes` to `destination` through an AtomicFile.
void writeFileAtomically(const std::string& destination, std::span<const unsigned char> bytes);

// Checks before any work is done that `output` can be written (its folder exists; it is not a
// directory, device, FIFO or socket) and that it is none of `inputs` nor of the protected inputs
// (checkNotAnInput). Throws conus::Error(InvalidArgument) naming the output.
void checkOutputPath(const std::string& output, std::span<const std::string> inputs = {});

// Names a file the running program reads, which no AtomicFile of this process may then replace
// (kept by device and inode: any other path to it, a symbolic or hard link, is refused too).
// Paths that name no regular file, and "-", are ignored.
void protectInput(const std::string& path);

// Throws conus::Error(InvalidArgument) "refusing to write <output>: it is the input <input> ..."
// when `output` exists and is the same file (device and inode, links followed) as one of
// `inputs` or of the protected inputs.
void checkNotAnInput(const std::string& output, std::span<const std::string> inputs = {});

// Checks that `input` names a regular file that exists (not a directory, device or FIFO, which
// could be read forever). "-" (standard input) is accepted when allowStdin. Throws conus::Error(Io).
void checkInputPath(const std::string& input, bool allowStdin = false);

// Installs handlers for SIGINT, SIGTERM and SIGHUP that remove every open temporary file and
// then end the process as the signal would have. Also ignores SIGXFSZ, so that a write past a
// file-size limit fails with an error instead of killing the process mid-file.
void removeTemporariesOnSignals();

// The outputs of one command, all or none. While an AtomicOutputs lives, each AtomicFile its
// thread commits is finished (written, synced, closed, checked) but stays a temporary; commit()
// then renames them all into place, in the order they were finished. One destroyed without
// commit() (the command failed) removes those temporaries and the folders its makeFolder made
// (when they are empty), so a command that fails leaves none of its outputs. Signals remove the
// waiting temporaries as they remove open ones. A file written inside the set cannot be read back
// under its own name before commit(). Sets nest: an inner set's commit() hands its files to the
// outer one.
class AtomicOutputs {
public:
    AtomicOutputs();
    ~AtomicOutputs();
    AtomicOutputs(const AtomicOutputs&) = delete;
    AtomicOutputs& operator=(const AtomicOutputs&) = delete;

    // Makes `folder` and its missing parents; throws conus::Error(Io) naming it when it cannot.
    void makeFolder(const std::string& folder);
    // Renames every waiting file into place; files committed afterwards are renamed at once (or
    // wait in the outer set). A rename that fails throws conus::Error(Io) naming its destination;
    // the files renamed before it stay, the rest are removed.
    void commit();

private:
    friend class AtomicFile;
    struct Waiting {
        std::string destination, target, temporary;
        dev_t device = 0;
        ino_t inode = 0;
        int slot = -1;
    };
    std::vector<Waiting> m_waiting;
    std::vector<std::string> m_madeFolders;  // deepest last
    AtomicOutputs* m_outer = nullptr;
    bool m_committed = false;
};

}  // namespace conus
