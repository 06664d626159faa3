// save_settings_atomic when the file system fails it part way: at create, write and fsync (the
// rename failure is in test_persist.cpp). Every failure names the file and the cause, removes the
// temporary file and leaves the old settings (offsets, tool table, parameters) as they were. The
// failures are made so that they happen for root too (tests may run as root, which permission bits
// do not stop): the temporary name is made a link to /dev/full (write fails: ENOSPC) or /dev/null
// (fsync fails: EINVAL), or a directory stands where a file must go.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

#include "interp/block.hpp"
#include "interp/persist.hpp"

namespace interp {
namespace {

namespace fs = std::filesystem;

class SaveFailure : public ::testing::Test {
  protected:
    void SetUp() override {
        std::string tmpl = (fs::temp_directory_path() / "persist-fail.XXXXXX").string();
        ASSERT_NE(::mkdtemp(tmpl.data()), nullptr);
        dir_ = tmpl;
        path_ = (dir_ / "settings.txt").string();
        tmp_ = path_ + ".tmp";
        old_.offsets.wcs[0] = {1, 2, 3, 0, 0, 0};
        old_.tools.at(4).offset_mm = {0, 0, 25.5};
        old_.tools.at(4).diameter_mm = 8;
        old_.params["FIXEDCALI_REC"] = -40.25;
        save_settings_atomic(path_, old_);
        old_text_ = read(path_);
        changed_ = old_;
        changed_.offsets.wcs[0][0] = 99;
        changed_.tools.at(4).offset_mm[2] = 30;
    }
    void TearDown() override {
        std::error_code ec;
        fs::remove_all(dir_, ec);
    }

    static std::string read(const std::string& p) {
        std::ifstream in(p);
        std::stringstream ss;
        ss << in.rdbuf();
        return ss.str();
    }
    std::string error_of_save() {
        try {
            save_settings_atomic(path_, changed_);
        } catch (const std::runtime_error& e) {
            return e.what();
        }
        return "no error";
    }
    // The old file, byte for byte, and nothing left at the temporary name.
    void expect_old_file_intact() {
        EXPECT_EQ(read(path_), old_text_);
        EXPECT_EQ(load_settings(path_), old_);
        EXPECT_FALSE(fs::exists(fs::symlink_status(tmp_)));
    }

    fs::path dir_;
    std::string path_, tmp_, old_text_;
    Settings old_, changed_;
};

TEST_F(SaveFailure, WriteFailureKeepsTheOldFile) {
    if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
    fs::create_symlink("/dev/full", tmp_);
    EXPECT_EQ(error_of_save(), tmp_ + ": cannot write settings: No space left on device");
    expect_old_file_intact();
    EXPECT_TRUE(fs::exists("/dev/full"));  // the link went, not what it named
}

TEST_F(SaveFailure, FsyncFailureKeepsTheOldFile) {
    if (!fs::exists("/dev/null")) GTEST_SKIP() << "no /dev/null";
    fs::create_symlink("/dev/null", tmp_);
    EXPECT_EQ(error_of_save(), tmp_ + ": cannot fsync settings: Invalid argument");
    expect_old_file_intact();
    EXPECT_TRUE(fs::exists("/dev/null"));
}

TEST_F(SaveFailure, CreateFailureKeepsTheOldFile) {
    fs::create_directory(tmp_);  // open(O_WRONLY) of a directory fails even for root
    EXPECT_EQ(error_of_save(), tmp_ + ": cannot create temporary settings file: Is a directory");
    EXPECT_EQ(read(path_), old_text_);
    EXPECT_TRUE(fs::is_directory(tmp_));  // not ours to remove
}

TEST_F(SaveFailure, ParentThatIsAFileIsNamed) {
    const std::string under_file = path_ + "/inner.txt";
    try {
        save_settings_atomic(under_file, changed_);
        FAIL() << "no error";
    } catch (const std::runtime_error& e) {
        EXPECT_EQ(std::string(e.what()),
                  under_file + ".tmp: cannot create temporary settings file: Not a directory");
    }
    EXPECT_EQ(read(path_), old_text_);
}

// A settings path that names a directory is not an empty settings file.
TEST_F(SaveFailure, LoadingADirectoryIsAnError) {
    try {
        load_settings(dir_.string());
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()),
                  dir_.string() + ":0:0: settings: cannot read file: Is a directory");
    }
}

// After a failure the next save (with the obstacle gone) replaces the file as usual.
TEST_F(SaveFailure, ASaveAfterAFailureWorks) {
    if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
    fs::create_symlink("/dev/full", tmp_);
    EXPECT_NE(error_of_save(), "no error");
    save_settings_atomic(path_, changed_);
    EXPECT_EQ(load_settings(path_), changed_);
    EXPECT_FALSE(fs::exists(fs::symlink_status(tmp_)));
}

}  // namespace
}  // namespace interp
