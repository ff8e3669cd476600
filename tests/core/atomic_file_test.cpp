// AtomicFile: all or nothing, checked to the last byte, and nothing left behind by a failure.
#include <gtest/gtest.h>

#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "test_dir.h"
#include "conus/core/atomic_file.h"
#include "conus/core/error.h"

namespace fs = std::filesystem;

namespace {

class AtomicFileTest : public ::testing::Test {
protected:
    std::string path(const std::string& name) const { return m_folder.file(name); }
    std::vector<std::string> entries() const { return m_folder.entries(); }
    conus::test::TestDir m_folder{"conus-atomic"};
    const fs::path& m_dir = m_folder.path();
};

std::string slurp(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

// Forks a child that installs the signal handlers and runs `work`, which ends by calling the
// function it is given: that tells this process the child is ready and waits to be killed there.
// Returns the child's pid once it is ready (-1 if it never was).
template <class Work>
pid_t readyChild(Work work) {
    int ready[2];
    if (::pipe(ready) != 0) return -1;
    const pid_t child = ::fork();
    if (child == 0) {
        conus::removeTemporariesOnSignals();
        work([&] {
            (void)!::write(ready[1], "r", 1);
            ::pause();
        });
        std::_Exit(0);
    }
    char c;
    return ::read(ready[0], &c, 1) == 1 ? child : -1;
}

// Sends SIGTERM to `child` and returns its wait status.
int terminated(pid_t child) {
    ::kill(child, SIGTERM);
    int status = 0;
    EXPECT_EQ(::waitpid(child, &status, 0), child);
    return status;
}

}  // namespace

TEST_F(AtomicFileTest, WritesAppendsAndPatchesThenRenames) {
    conus::AtomicFile file(path("out.bin"));
    EXPECT_FALSE(fs::exists(path("out.bin"))) << "nothing at the destination before commit";
    ASSERT_EQ(entries().size(), 1u);
    EXPECT_EQ(entries()[0].rfind(".out.tmp-", 0), 0u) << entries()[0];
    std::string big(3 << 20, 'x');  // past the buffer: written straight through
    file.write("head", 4);
    file.write(big.data(), big.size());
    file.writeAt(0, "HE", 2);  // a writer patching its header
    char back[4] = {};
    EXPECT_EQ(file.readAt(0, back, 4), 4u);
    EXPECT_EQ(std::string(back, 4), "HEad");
    file.write("tail", 4);
    file.commit();
    const std::string got = slurp(path("out.bin"));
    EXPECT_EQ(got.size(), 4 + big.size() + 4);
    EXPECT_EQ(got.substr(0, 4), "HEad");
    EXPECT_EQ(got.substr(got.size() - 4), "tail");
    EXPECT_EQ(entries(), std::vector<std::string>{"out.bin"});
}

TEST_F(AtomicFileTest, AnAbandonedFileLeavesTheOldDestinationAndNoTemporary) {
    { std::ofstream(path("keep.txt")) << "old"; }
    {
        conus::AtomicFile file(path("keep.txt"));
        file.write("new", 3);
    }  // destroyed without commit: a failed writer
    EXPECT_EQ(slurp(path("keep.txt")), "old");
    EXPECT_EQ(entries(), std::vector<std::string>{"keep.txt"});
}

TEST_F(AtomicFileTest, SymlinksAreWrittenThroughAndKeepTheirTargetsPermissions) {
    { std::ofstream(path("target.txt")) << "old"; }
    ::chmod(path("target.txt").c_str(), 0640);
    fs::create_symlink(path("target.txt"), path("link.txt"));
    conus::writeFileAtomically(path("link.txt"), std::vector<unsigned char>{'n', 'e', 'w'});
    EXPECT_TRUE(fs::is_symlink(path("link.txt"))) << "the link stays a link";
    EXPECT_EQ(slurp(path("target.txt")), "new");
    struct stat st {};
    ASSERT_EQ(::stat(path("target.txt").c_str(), &st), 0);
    EXPECT_EQ(st.st_mode & 0777, 0640u);
}

TEST_F(AtomicFileTest, DevicesFifosAndDirectoriesAreRefused) {
    ASSERT_EQ(::mkfifo(path("fifo").c_str(), 0600), 0);
    fs::create_directory(path("folder"));
    for (const std::string& target : {std::string("/dev/null"), path("fifo"), path("folder")}) {
        try {
            conus::AtomicFile file(target);
            FAIL() << target << " was accepted";
        } catch (const conus::Error& e) {
            EXPECT_EQ(e.code(), conus::ErrorCode::Io);
            EXPECT_NE(std::string(e.what()).find(target), std::string::npos) << e.what();
        }
        EXPECT_THROW(conus::checkOutputPath(target), conus::Error) << target;
    }
    struct stat st {};
    ASSERT_EQ(::stat("/dev/null", &st), 0);
    EXPECT_TRUE(S_ISCHR(st.st_mode)) << "the device is still a device";
}

TEST_F(AtomicFileTest, OutputThatIsAnInputIsRefusedByAnyPath) {
    { std::ofstream(path("in.png")) << "source"; }
    fs::create_symlink(path("in.png"), path("alias.png"));
    const std::string inputs[] = {path("in.png")};
    EXPECT_THROW(conus::checkOutputPath(path("alias.png"), inputs), conus::Error);
    EXPECT_THROW(conus::checkOutputPath(path("./in.png"), inputs), conus::Error);
    EXPECT_NO_THROW(conus::checkOutputPath(path("out.png"), inputs));
    EXPECT_THROW(conus::checkOutputPath(path("missing-folder/out.png")), conus::Error);
}

TEST_F(AtomicFileTest, InputsMustBeRegularFiles) {
    ASSERT_EQ(::mkfifo(path("fifo").c_str(), 0600), 0);
    EXPECT_THROW(conus::checkInputPath("/dev/zero"), conus::Error);
    EXPECT_THROW(conus::checkInputPath(path("fifo")), conus::Error);
    EXPECT_THROW(conus::checkInputPath(m_dir.string()), conus::Error);
    EXPECT_THROW(conus::checkInputPath(path("missing")), conus::Error);
    EXPECT_THROW(conus::checkInputPath("-"), conus::Error);
    EXPECT_NO_THROW(conus::checkInputPath("-", /*allowStdin=*/true));
    try {
        conus::checkInputPath("/dev/zero");
    } catch (const conus::Error& e) {
        EXPECT_NE(std::string(e.what()).find("not a regular file"), std::string::npos) << e.what();
    }
}

TEST_F(AtomicFileTest, AWritePastTheFileSizeLimitIsAFailureNamingTheDestination) {
    // In a child: the limit would stay on this process.
    const pid_t child = ::fork();
    if (child == 0) {
        conus::removeTemporariesOnSignals();  // ignores SIGXFSZ: the write fails instead of killing
        rlimit limit{64 * 1024, 64 * 1024};
        ::setrlimit(RLIMIT_FSIZE, &limit);
        int code = 3;
        try {
            conus::AtomicFile file(path("big.bin"));
            const std::vector<char> chunk(1 << 20, 'z');
            file.write(chunk.data(), chunk.size());
            file.commit();
        } catch (const conus::Error& e) {
            const std::string what = e.what();
            code = what.find(path("big.bin")) != std::string::npos && what.find(".tmp-") == std::string::npos ? 0 : 4;
        }
        std::_Exit(code);
    }
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFEXITED(status)) << "the child was killed (signal " << WTERMSIG(status) << ")";
    EXPECT_EQ(WEXITSTATUS(status), 0) << "3: the write was reported as success; 4: the message named the temporary";
    EXPECT_TRUE(entries().empty()) << "no destination and no temporary left";
}

TEST_F(AtomicFileTest, SigtermRemovesTheTemporaryFile) {
    const pid_t child = readyChild([&](auto waitToBeKilled) {
        conus::AtomicFile file(path("slow.bin"));
        file.write("partial", 7);
        file.writeAt(0, "P", 1);  // on disk now
        waitToBeKilled();         // killed here, mid-write
    });
    ASSERT_GT(child, 0);
    bool sawTemporary = false;
    for (const std::string& name : entries()) sawTemporary |= name.find(".tmp-") != std::string::npos;
    EXPECT_TRUE(sawTemporary);
    const int status = terminated(child);
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM) << "ends as SIGTERM would";
    EXPECT_TRUE(entries().empty()) << "the temporary was removed";
}

TEST_F(AtomicFileTest, AFailedSetOfOutputsLeavesNoneOfThemNorTheFoldersItMade) {
    conus::writeFileAtomically(path("kept.bin"), std::vector<unsigned char>{'o', 'l', 'd'});
    {
        conus::AtomicOutputs outputs;
        outputs.makeFolder(path("made/deeper"));
        conus::writeFileAtomically(path("made/deeper/a.bin"), std::vector<unsigned char>{'a'});
        conus::writeFileAtomically(path("kept.bin"), std::vector<unsigned char>{'n', 'e', 'w'});
        EXPECT_FALSE(fs::exists(path("made/deeper/a.bin"))) << "nothing in place before the set commits";
        EXPECT_EQ(slurp(path("kept.bin")), "old");
        // The command fails here: the set is destroyed without commit().
    }
    EXPECT_EQ(entries(), std::vector<std::string>{"kept.bin"}) << "no temporary, no folder the set made";
    EXPECT_EQ(slurp(path("kept.bin")), "old");
}

TEST_F(AtomicFileTest, ACommittedSetRenamesEveryOutputAndNestedSetsJoinTheOuterOne) {
    conus::AtomicOutputs outputs;
    outputs.makeFolder(path("out"));
    conus::writeFileAtomically(path("out/a.bin"), std::vector<unsigned char>{'a'});
    {
        conus::AtomicOutputs inner;
        conus::writeFileAtomically(path("b.bin"), std::vector<unsigned char>{'b'});
        inner.commit();
    }
    EXPECT_FALSE(fs::exists(path("b.bin"))) << "the inner set's file waits for the outer set";
    outputs.commit();
    EXPECT_EQ(slurp(path("out/a.bin")), "a");
    EXPECT_EQ(slurp(path("b.bin")), "b");
    std::vector<std::string> names = entries();
    std::sort(names.begin(), names.end());
    EXPECT_EQ(names, (std::vector<std::string>{"b.bin", "out"}));
    // Once the set is committed, a commit renames at once again.
    conus::writeFileAtomically(path("c.bin"), std::vector<unsigned char>{'c'});
    EXPECT_TRUE(fs::exists(path("c.bin")));
}

TEST_F(AtomicFileTest, SigtermRemovesTheOutputsWaitingInASet) {
    const pid_t child = readyChild([&](auto waitToBeKilled) {
        conus::AtomicOutputs outputs;
        conus::writeFileAtomically(path("first.bin"), std::vector<unsigned char>{'1'});
        waitToBeKilled();  // killed while the command's second output is being made
    });
    ASSERT_GT(child, 0);
    EXPECT_EQ(entries().size(), 1u) << "the finished first output waits as a temporary";
    terminated(child);
    EXPECT_TRUE(entries().empty()) << "the signal removed it";
}

// The one temporary entry in the test folder besides `except`.
static std::string onlyTemporary(const std::vector<std::string>& names) {
    std::string found;
    for (const std::string& n : names)
        if (n.find(".tmp-") != std::string::npos) {
            EXPECT_TRUE(found.empty()) << "two temporaries: " << found << ", " << n;
            found = n;
        }
    return found;
}

TEST_F(AtomicFileTest, TemporaryNamesAreUnpredictableAndCarryNoProcessId) {
    std::vector<std::unique_ptr<conus::AtomicFile>> files;
    std::set<std::string> names;
    for (int i = 0; i < 20; ++i) {
        files.push_back(std::make_unique<conus::AtomicFile>(path("same.exr")));
        for (const std::string& n : entries()) names.insert(n);
    }
    EXPECT_EQ(names.size(), 20u) << "twenty writers of one destination, twenty names";
    const std::string pid = std::to_string(::getpid());
    for (const std::string& n : names) {
        EXPECT_EQ(n.rfind(".same.tmp-", 0), 0u) << n;
        EXPECT_EQ(n.size(), std::string(".same.tmp-").size() + 12 + 4) << n;
        EXPECT_EQ(n.find(pid), std::string::npos) << n;
        EXPECT_EQ(n.substr(n.size() - 4), ".exr") << "the destination's extension, for libraries that look at it";
    }
    files.clear();
    EXPECT_TRUE(entries().empty()) << "each removed its own";
}

TEST_F(AtomicFileTest, ALinkPutUnderTheTemporarysNameIsNeitherWrittenNorRenamedNorRemoved) {
    { std::ofstream(path("victim.txt")) << "precious"; }
    conus::AtomicFile file(path("out.tif"));
    const std::string temporary = onlyTemporary(entries());
    ASSERT_FALSE(temporary.empty());
    // Someone with write access to the folder swaps the temporary for a link to another file.
    ASSERT_EQ(::unlink(path(temporary).c_str()), 0);
    fs::create_symlink(path("victim.txt"), path(temporary));
    // A library that writes by name (as OpenImageIO's TIFF writer and ffmpeg do) writes the file
    // the AtomicFile created, not the link.
    EXPECT_EQ(file.temporaryPath().find(temporary), std::string::npos) << file.temporaryPath();
    { std::ofstream(file.temporaryPath(), std::ios::binary | std::ios::trunc) << "library bytes"; }
    EXPECT_EQ(slurp(path("victim.txt")), "precious");
    EXPECT_THROW(file.commit(), conus::Error) << "what is under the name now is not the file written";
    EXPECT_FALSE(fs::exists(path("out.tif")));
    EXPECT_TRUE(fs::is_symlink(path(temporary))) << "the stranger's link is left alone";
    EXPECT_EQ(slurp(path("victim.txt")), "precious");
}

TEST_F(AtomicFileTest, AFailedWriterRemovesOnlyTheFileItMade) {
    auto file = std::make_unique<conus::AtomicFile>(path("out.exr"));
    const std::string temporary = onlyTemporary(entries());
    ASSERT_FALSE(temporary.empty());
    ASSERT_EQ(::unlink(path(temporary).c_str()), 0);
    { std::ofstream(path(temporary)) << "someone else's"; }
    file.reset();  // destroyed without commit
    EXPECT_EQ(slurp(path(temporary)), "someone else's") << "a file this process did not make is never removed";
}

TEST_F(AtomicFileTest, LookAlikeTemporariesOfOtherProcessesAreNeverRemoved) {
    // Names of the old "<pid>-<counter>" kind, of processes that are not running, a folder among them.
    fs::create_directory(path(".photos.tmp-999999-1"));
    { std::ofstream(path(".photos.tmp-999999-1/keep.txt")) << "keep"; }
    { std::ofstream(path(".notes.tmp-424242-7.txt")) << "notes"; }
    { std::ofstream(path(".out.tmp-999998-0.exr")) << "mine"; }
    conus::writeFileAtomically(path("out.exr"), std::vector<unsigned char>{'x'});
    EXPECT_EQ(slurp(path(".photos.tmp-999999-1/keep.txt")), "keep");
    EXPECT_EQ(slurp(path(".notes.tmp-424242-7.txt")), "notes");
    EXPECT_EQ(slurp(path(".out.tmp-999998-0.exr")), "mine");
}

TEST_F(AtomicFileTest, AProtectedInputIsNeverReplacedByAnyPath) {
    { std::ofstream(path("input.exr")) << "input"; }
    fs::create_symlink(path("input.exr"), path("soft.exr"));
    fs::create_hard_link(path("input.exr"), path("hard.exr"));
    // In a child: the protection lasts as long as the process (and inodes are reused later).
    const auto child = [&] {
        conus::protectInput(path("input.exr"));
        int wrong = 0;
        for (const char* name : {"input.exr", "soft.exr", "hard.exr", "./input.exr"}) {
            try {
                conus::AtomicFile file(path(name));
                std::fprintf(stderr, "%s was opened for writing\n", name), ++wrong;
            } catch (const conus::Error& e) {
                if (std::string(e.what()).rfind("refusing to write " + path(name) + ": it is the input", 0) != 0)
                    std::fprintf(stderr, "%s\n", e.what()), ++wrong;
            }
            try {
                conus::checkNotAnInput(path(name));
                std::fprintf(stderr, "%s passed checkNotAnInput\n", name), ++wrong;
            } catch (const conus::Error&) {
            }
        }
        conus::writeFileAtomically(path("other.exr"), std::vector<unsigned char>{'o'});
        std::exit(wrong);
    };
    EXPECT_EXIT(child(), ::testing::ExitedWithCode(0), "");
    EXPECT_EQ(slurp(path("input.exr")), "input");
    EXPECT_EQ(slurp(path("other.exr")), "o") << "other files are written as ever";
}
