// Persistent settings and LinuxCNC tool tables: round trips, atomic replacement, one test per
// error message; and the lock a run holds on its settings files (in this process and another).
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <memory>

#include "interp/block.hpp"
#include "interp/persist.hpp"
#include "interp/tooltable.hpp"
#include "scratch_dir.hpp"

namespace interp {
namespace {

namespace fs = std::filesystem;

std::string error_of_settings(const std::string& text) {
    try {
        parse_settings(text, "s.txt");
    } catch (const Error& e) {
        return e.what();
    }
    return "no error";
}

std::string error_of_tbl(const std::string& text) {
    try {
        parse_linuxcnc_tool_table(text, "t.tbl");
    } catch (const Error& e) {
        return e.what();
    }
    return "no error";
}

fs::path temp_dir() {
    // Unique per process so ctest -j can run this alongside other tests.
    fs::path d = fs::temp_directory_path() / ("iback-persist-" + std::to_string(::getpid()));
    fs::create_directories(d);
    return d;
}

TEST(Settings, RoundTripThroughTheFile) {
    Settings s;
    s.offsets.wcs[2] = {1.5, -2.25, 3, 0, 0, 90};
    s.offsets.common = {0, 0, -0.1, 0, 0, 0};
    s.offsets.g92 = {10, 20, 0, 0, 0, 0};
    s.tools.at(3).offset_mm = {0.1, 0.2, 12.345678901};
    s.tools.at(3).diameter_mm = 6;
    s.params["FIXEDCALI_REC"] = -12.75;
    const fs::path dir = temp_dir();
    const std::string path = (dir / "settings.txt").string();
    save_settings_atomic(path, s);
    EXPECT_FALSE(fs::exists(path + ".tmp"));
    const Settings back = load_settings(path);
    EXPECT_EQ(back, s);
    // Replacing keeps exactly one complete file.
    s.offsets.g92[0] = 11;
    save_settings_atomic(path, s);
    EXPECT_EQ(load_settings(path), s);
    fs::remove_all(dir);
}

TEST(Settings, MissingFileGivesDefaults) {
    EXPECT_EQ(load_settings("/nonexistent-dir-iback/settings.txt"), Settings{});
}

TEST(Settings, SaveIntoMissingDirectoryFailsAndNamesThePath) {
    try {
        save_settings_atomic("/nonexistent-dir-iback/settings.txt", Settings{});
        FAIL() << "no error";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("/nonexistent-dir-iback/settings.txt.tmp"),
                  std::string::npos);
    }
}

// The system-call failures name the file and the cause (strerror); the old file stays intact.
TEST(Settings, FileSystemErrorsNameThePathAndTheCause) {
    auto error_of_save = [](const std::string& path) {
        try {
            save_settings_atomic(path, Settings{});
        } catch (const std::runtime_error& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_EQ(error_of_save("/nonexistent-dir-iback/s.txt"),
              "/nonexistent-dir-iback/s.txt.tmp: cannot create temporary settings file: No such "
              "file or directory");
    // A directory in the way of the final name: rename(2) refuses, the temporary file goes.
    const fs::path dir = temp_dir();
    const fs::path target = dir / "settings.txt";
    fs::create_directories(target / "sub");
    EXPECT_EQ(error_of_save(target.string()),
              target.string() + ": cannot replace settings file: Is a directory");
    EXPECT_FALSE(fs::exists(target.string() + ".tmp"));
    EXPECT_TRUE(fs::is_directory(target / "sub"));
    fs::remove_all(dir);
}

TEST(Settings, ErrorsNameFileLineAndColumn) {
    EXPECT_EQ(error_of_settings("# ok\nwcs 1 0 0 0 0 0\n"),
              "s.txt:2:1: settings: 'wcs' needs 7 values, found 6");
    EXPECT_EQ(error_of_settings("wcs 7 0 0 0 0 0 0\n"),
              "s.txt:1:5: settings: '7' must be an integer in 1..6");
    EXPECT_EQ(error_of_settings("g92 0 0 x 0 0 0\n"), "s.txt:1:9: settings: 'x' is not a number");
    EXPECT_EQ(error_of_settings("tool 1 0 0 5 -1\n"),
              "s.txt:1:14: settings: negative tool diameter");
    EXPECT_EQ(error_of_settings("bogus 1\n"), "s.txt:1:1: settings: unknown entry 'bogus'");
}

TEST(Settings, BadFileOnDiskIsReportedAndLeftAlone) {
    const fs::path dir = temp_dir();
    const std::string path = (dir / "bad.txt").string();
    {
        std::ofstream f(path);
        f << "common 1 2 3\n";
    }
    EXPECT_THROW(load_settings(path), Error);
    std::ifstream f(path);
    std::string line;
    std::getline(f, line);
    EXPECT_EQ(line, "common 1 2 3");
    fs::remove_all(dir);
}

TEST(ToolTable, ReadsLinuxCncLines) {
    const ToolTable t = parse_linuxcnc_tool_table(
        "T1 P1 D6.0 Z12.5 ;six mm end mill\n\nt2 p2 d3 z+7 x0.5 ; drill\nT3 P3 ;\n", "t.tbl");
    ASSERT_NE(t.find(1), nullptr);
    EXPECT_DOUBLE_EQ(t.find(1)->diameter_mm, 6.0);
    EXPECT_DOUBLE_EQ(t.find(1)->offset_mm[2], 12.5);
    EXPECT_EQ(t.find(1)->comment, "six mm end mill");
    EXPECT_EQ(t.find(1)->pocket, 1);
    ASSERT_NE(t.find(2), nullptr);
    EXPECT_DOUBLE_EQ(t.find(2)->offset_mm[0], 0.5);
    EXPECT_DOUBLE_EQ(t.find(2)->offset_mm[2], 7);
    ASSERT_NE(t.find(3), nullptr);
    EXPECT_EQ(t.find(4), nullptr);
}

TEST(ToolTable, OneTestPerErrorMessage) {
    EXPECT_EQ(error_of_tbl("T1 P1 Dx\n"), "t.tbl:1:8: tool table: expected a number after 'D'");
    EXPECT_EQ(error_of_tbl("T1.5 P1\n"), "t.tbl:1:1: tool table: bad tool number");
    EXPECT_EQ(error_of_tbl("T1 D-2\n"), "t.tbl:1:4: tool table: negative diameter");
    EXPECT_EQ(error_of_tbl("T1 R2\n"), "t.tbl:1:4: tool table: unknown word 'R'");
    EXPECT_EQ(error_of_tbl("P1 D2\n"), "t.tbl:1:1: tool table: line has no T word");
    EXPECT_EQ(error_of_tbl("T1 P1\nT1 P2\n"), "t.tbl:2:1: tool table: tool 1 listed twice");
}

TEST(ToolTable, MissingFileIsAnError) {
    try {
        load_linuxcnc_tool_table("/nonexistent-dir-iback/x.tbl");
        FAIL() << "no error";
    } catch (const Error& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("/nonexistent-dir-iback/x.tbl"), std::string::npos) << what;
        EXPECT_NE(what.find("cannot open tool table"), std::string::npos) << what;
    }
}

// A settings file a person wrote: comments, blank lines, its own order and spacing.
const std::string kHandSettings =
    "# mill 3 - offsets measured 2026-11-02\n"
    "\n"
    "g92 0 0 0 0 0 0\n"
    "wcs 2   1.5 0 0 0 0 0   # fixture B\n"
    "  wcs 1 10 20 -5 0 0 0\n"
    "param FIXEDCALI_REC -40.25 # contact Z\n"
    "tool 3 0 0 45 6\n";

TEST(SettingsRewrite, UnchangedSettingsKeepEveryByte) {
    const Settings s = parse_settings(kHandSettings, "m.var");
    EXPECT_EQ(update_settings_text(kHandSettings, s, "m.var"), kHandSettings);
    EXPECT_EQ(s.offsets.wcs[1][0], 1.5);
    EXPECT_EQ(s.offsets.wcs[0][2], -5);
}

// Expected: kHandSettings with the changed entries' words written anew (by hand).
TEST(SettingsRewrite, OnlyTheChangedEntriesAreWrittenAnew) {
    Settings s = parse_settings(kHandSettings, "m.var");
    s.offsets.wcs[1][0] = 7;
    s.offsets.wcs[0][1] = 21;
    EXPECT_EQ(update_settings_text(kHandSettings, s, "m.var"),
              "# mill 3 - offsets measured 2026-11-02\n"
              "\n"
              "g92 0 0 0 0 0 0\n"
              "wcs 2 7 0 0 0 0 0   # fixture B\n"
              "  wcs 1 10 21 -5 0 0 0\n"
              "param FIXEDCALI_REC -40.25 # contact Z\n"
              "tool 3 0 0 45 6\n");
}

// What the file lacks goes at its end; an offset the file lacks only when it is not 0; a line
// for something the new settings lack (the tools, kept in a tool table) stays.
TEST(SettingsRewrite, NewEntriesAreAppendedAndLinesForOthersStay) {
    const std::string text = "# offsets\r\nwcs 1 1 2 3 0 0 0\r\ntool 3 0 0 45 6";
    Settings s = parse_settings(text, "m.var");
    s.tools = ToolTable{};
    s.offsets.common[2] = -0.5;
    s.params["FIXEDCALI_REC"] = 12.5;
    EXPECT_EQ(update_settings_text(text, s, "m.var"),
              "# offsets\r\nwcs 1 1 2 3 0 0 0\r\ntool 3 0 0 45 6\r\n"
              "common 0 0 -0.5 0 0 0\r\nparam FIXEDCALI_REC 12.5\r\n");
    EXPECT_EQ(update_settings_text("", s, "m.var"), format_settings(s));
}

TEST(SettingsRewrite, ABadFileIsRefusedWithItsLine) {
    try {
        update_settings_text("wcs 1 0 0 0 0 0 0\nwcs 9 0 0 0 0 0 0\n", Settings{}, "m.var");
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()), "m.var:2:5: settings: '9' must be an integer in 1..6");
    }
}

// The first save edits the seed's text (the INI's own file), the next ones the file itself.
TEST(SettingsRewrite, SaveEditsTheFileOrItsSeed) {
    const cnc_test::ScratchDir scratch;
    const std::string seed = (scratch.path() / "seed.var").string();
    const std::string file = (scratch.path() / "m.var").string();
    std::ofstream(seed) << kHandSettings;
    Settings s = parse_settings(kHandSettings, "m.var");
    s.offsets.g92[0] = 2.5;
    save_settings_atomic(file, s, seed);
    std::string expected = kHandSettings;
    expected.replace(expected.find("g92 0 0"), 7, "g92 2.5 0");
    EXPECT_EQ(cnc_test::slurp(file), expected);
    EXPECT_EQ(cnc_test::slurp(seed), kHandSettings);
    s.params["FIXEDCALI_REC"] = 1;
    save_settings_atomic(file, s, seed);
    expected.replace(expected.find("-40.25 #"), 8, "1 #");
    EXPECT_EQ(cnc_test::slurp(file), expected);
}

std::string error_of_lock(const std::string& path, const std::string& lock_dir) {
    try {
        SettingsFileLock lock(path, lock_dir);
    } catch (const std::runtime_error& e) {
        return e.what();
    }
    return "no error";
}

// flock locks of two open() calls conflict even in one process, so one test process stands in
// for two runs.
TEST(SettingsLock, ASecondRunOnTheSameFileIsRefusedNamingTheFileAndTheHolder) {
    const cnc_test::ScratchDir scratch;
    const std::string locks = (scratch.path() / "locks").string();
    const std::string file = (scratch.path() / "m.var").string();
    auto held = std::make_unique<SettingsFileLock>(file, locks);
    EXPECT_EQ(error_of_lock(file, locks),
              fmt::format("{}: settings file in use by another run (pid {}); two runs on the "
                          "same settings would overwrite each other's changes",
                          file, ::getpid()));
    // Another way to the same file is the same file.
    fs::create_directory_symlink(scratch.path(), scratch.path() / "link");
    EXPECT_NE(error_of_lock((scratch.path() / "link/m.var").string(), locks).find("in use"),
              std::string::npos);
    EXPECT_NE(error_of_lock((scratch.path() / "./m.var").string(), locks).find("in use"),
              std::string::npos);
    // Another file is not held.
    EXPECT_EQ(error_of_lock((scratch.path() / "other.var").string(), locks), "no error");
    held.reset();
    EXPECT_EQ(error_of_lock(file, locks), "no error");
    // A holder that lets go removes its lock file.
    EXPECT_TRUE(fs::is_empty(locks));
}

TEST(SettingsLock, ALockFolderThatCannotBeMadeIsNamed) {
    const cnc_test::ScratchDir scratch;
    std::ofstream(scratch.path() / "plain") << "x";
    const std::string locks = (scratch.path() / "plain/locks").string();
    const std::string file = (scratch.path() / "m.var").string();
    EXPECT_EQ(error_of_lock(file, locks),
              fmt::format("{}: cannot lock settings file: {}: Not a directory", file,
                          SettingsFileLock::lock_file_of(file, locks)));
}

TEST(SettingsLock, TheLockFileIsNamedAfterTheSettingsFile) {
    const std::string lock = SettingsFileLock::lock_file_of("/no-such-dir-iback/m.var", "/L");
    EXPECT_EQ(lock.rfind("/L/m.var-", 0), 0u) << lock;
    EXPECT_EQ(lock.size(), std::string("/L/m.var-0123456789abcdef.lock").size()) << lock;
    EXPECT_NE(lock, SettingsFileLock::lock_file_of("/no-such-dir-iback2/m.var", "/L"));
}

// Another process holding the lock: the refusal names its process id, and once it has ended
// (the kernel drops its lock) the file can be locked again.
TEST(SettingsLock, AnotherProcessHoldingTheLockIsNamed) {
    const cnc_test::ScratchDir scratch;
    const std::string locks = (scratch.path() / "locks").string();
    const std::string file = (scratch.path() / "m.var").string();
    int locked[2];
    int release[2];
    ASSERT_EQ(::pipe(locked), 0);
    ASSERT_EQ(::pipe(release), 0);
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
        // Holds the lock until the parent writes; _exit so nothing of the test runs twice.
        char c = 0;
        try {
            const SettingsFileLock held(file, locks);
            if (::write(locked[1], "l", 1) != 1) ::_exit(2);
            if (::read(release[0], &c, 1) != 1) ::_exit(3);
        } catch (...) {
            ::_exit(1);
        }
        ::_exit(0);
    }
    char c = 0;
    ASSERT_EQ(::read(locked[0], &c, 1), 1);
    EXPECT_EQ(error_of_lock(file, locks),
              fmt::format("{}: settings file in use by another run (pid {}); two runs on the "
                          "same settings would overwrite each other's changes",
                          file, child));
    ASSERT_EQ(::write(release[1], "r", 1), 1);
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << status;
    EXPECT_EQ(error_of_lock(file, locks), "no error");
    for (int fd : {locked[0], locked[1], release[0], release[1]}) ::close(fd);
}

// A lock file that outlived its holder (the process was killed before removing it) keeps
// nobody out: the kernel dropped the lock with the process.
TEST(SettingsLock, ALeftOverLockFileIsTakenOver) {
    const cnc_test::ScratchDir scratch;
    const std::string locks = (scratch.path() / "locks").string();
    const std::string file = (scratch.path() / "m.var").string();
    fs::create_directories(locks);
    const std::string lock_file = SettingsFileLock::lock_file_of(file, locks);
    std::ofstream(lock_file) << "999999999\n";
    {
        const SettingsFileLock lock(file, locks);
        EXPECT_EQ(cnc_test::slurp(lock_file), fmt::format("{}\n", ::getpid()));
    }
    EXPECT_FALSE(fs::exists(lock_file));
}

}  // namespace
}  // namespace interp
