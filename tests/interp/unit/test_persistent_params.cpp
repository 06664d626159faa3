// Named parameters a program writes (#FIXEDCALI_REC, FEATURES TSET-2) persist: the whole chain
// front end -> executor -> settings listener -> atomic file write, then a fresh load.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "interp/executor.hpp"
#include "interp/interpreter.hpp"
#include "interp/persist.hpp"
#include "interp/source.hpp"

namespace interp {
namespace {

namespace fs = std::filesystem;

struct Null : CanonSink {
    void emit(const Canon&) override {}
};

fs::path settings_path(const char* test) {
    // Unique per process and test so ctest -j can run these side by side.
    fs::path d = fs::temp_directory_path() /
                 ("iback-params-" + std::to_string(::getpid()) + "-" + test);
    fs::create_directories(d);
    return d / "settings.txt";
}

// Runs `program` with the settings file at `path` saved on every change, as `cnc canon
// --settings FILE --save-settings` does. Returns the error text, or "" when it ran.
std::string run_saving(const std::string& program, const fs::path& path) {
    Null sink;
    Executor exec(sink, BackendConfig{}, load_settings(path.string()));
    exec.on_settings_changed([&](const Settings& s) { save_settings_atomic(path.string(), s); });
    Interpreter in(exec, exec);
    in.open(Source::from_string("p.nc", program));
    try {
        in.run();
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

TEST(PersistentParams, ProgramWriteSurvivesAReload) {
    const fs::path path = settings_path("reload");
    // The fixed tool-setting routine records the contact Z (work coordinates) in FIXEDCALI_REC.
    ASSERT_EQ(run_saving("G92 X0 Y0 Z0\nG01 Z-12.5 F100\n#FIXEDCALI_REC=#CURWORKPOS.Z\nM30\n",
                         path),
              "");
    const Settings back = load_settings(path.string());
    ASSERT_TRUE(back.params.contains("FIXEDCALI_REC"));
    EXPECT_DOUBLE_EQ(back.params.at("FIXEDCALI_REC"), -12.5);
    // A second program reads the stored value back.
    ASSERT_EQ(run_saving("#1=#FIXEDCALI_REC\nG01 X=#1 F60\nM30\n", path), "");
    fs::remove_all(path.parent_path());
}

TEST(PersistentParams, InchProgramStoresMillimetres) {
    const fs::path path = settings_path("inch");
    ASSERT_EQ(run_saving("G20\n#FIXEDCALI_REC=0.5\nM30\n", path), "");
    EXPECT_DOUBLE_EQ(load_settings(path.string()).params.at("FIXEDCALI_REC"), 12.7);
    fs::remove_all(path.parent_path());
}

TEST(PersistentParams, RejectedBlockWritesNothing) {
    const fs::path path = settings_path("rejected");
    // The block is rejected by the back end (G01 without any feed), so its assignment is dropped.
    EXPECT_EQ(run_saving("#FIXEDCALI_REC=3 G01 X1\n", path),
              "p.nc:1:1: no feed rate programmed (F) for a feed move");
    EXPECT_FALSE(fs::exists(path));
    fs::remove_all(path.parent_path());
}

TEST(PersistentParams, OtherNamedParametersStayReadOnly) {
    const fs::path path = settings_path("readonly");
    EXPECT_EQ(run_saving("#SAFEHEIGHT=5\n", path),
              "p.nc:1:1: named parameter #SAFEHEIGHT is read-only");
    fs::remove_all(path.parent_path());
}

}  // namespace
}  // namespace interp
