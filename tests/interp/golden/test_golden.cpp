// Golden cases: every directory under tests/interp/cases holds
//   program.nc   the program (its name in diagnostics is "program.nc")
//   expected     the canonical stream it must produce (native text form, or the LinuxCNC form
//                with "format linuxcnc"), then "error: <message>" if the program must fail
//   README.md    what was checked and how
//   options      optional, one per line: dialect <name> | tool-table <file> | library <file> |
//                default-feed <mm/min> | use-default-speed | optional-stop | no-g00-split |
//                format linuxcnc | settings <file> | g904-trip <X|Y|Z> <machine mm>
// The expected files were written and checked by hand or by geometry, never copied from output.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "interp/canon_print.hpp"
#include "interp/executor.hpp"
#include "interp/interpreter.hpp"
#include "interp/source.hpp"
#include "interp/tooltable.hpp"

namespace fs = std::filesystem;

namespace {

std::string read_file(const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    std::ostringstream ss;
    ss << f.rdbuf();
    return ss.str();
}

std::vector<std::string> case_names() {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(INTERP_CASES_DIR))
        if (e.is_directory() && fs::exists(e.path() / "program.nc"))
            names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
}

struct CaseOptions {
    std::string dialect = "ncstudio";
    std::string tool_table, library, settings;
    std::array<std::optional<double>, 3> g904_trip_mm{};
    double default_feed_mm_min = 0;
    bool optional_stop = false, no_split = false, linuxcnc = false, use_default_speed = false;
};

CaseOptions read_options(const fs::path& dir) {
    CaseOptions o;
    std::ifstream f(dir / "options");
    std::string key;
    while (f >> key) {
        if (key == "dialect")
            f >> o.dialect;
        else if (key == "tool-table")
            f >> o.tool_table;
        else if (key == "library")
            f >> o.library;
        else if (key == "settings")
            f >> o.settings;
        else if (key == "g904-trip") {
            char axis = 0;
            double mm = 0;
            f >> axis >> mm;
            o.g904_trip_mm[axis - 'X'] = mm;
        } else if (key == "default-feed")
            f >> o.default_feed_mm_min;
        else if (key == "use-default-speed")
            o.use_default_speed = true;
        else if (key == "optional-stop")
            o.optional_stop = true;
        else if (key == "no-g00-split")
            o.no_split = true;
        else if (key == "format") {
            std::string v;
            f >> v;
            o.linuxcnc = v == "linuxcnc";
        } else {
            ADD_FAILURE() << dir << "/options: unknown key " << key;
        }
    }
    return o;
}

// Runs the case; the stream goes through a temporary FILE so both printers are exercised
// exactly as `cnc canon` uses them.
std::string run_case(const fs::path& dir) {
    const CaseOptions o = read_options(dir);
    interp::Settings settings;
    if (!o.settings.empty()) settings = interp::load_settings((dir / o.settings).string());
    if (!o.tool_table.empty())
        settings.tools = interp::load_linuxcnc_tool_table((dir / o.tool_table).string());
    interp::BackendConfig cfg;
    cfg.v54_compat = o.dialect == "ncstudio-v54";
    cfg.t_changes_tool = !cfg.v54_compat;
    cfg.optional_stop = o.optional_stop;
    cfg.g00_z_split = !o.no_split;
    cfg.default_feed_mm_s = o.default_feed_mm_min / 60.0;
    cfg.use_default_speed = o.use_default_speed;
    cfg.g904_trip_mm = o.g904_trip_mm;
    interp::InterpreterOptions iopts;
    iopts.dialect = interp::find_dialect(o.dialect);

    std::FILE* out = std::tmpfile();
    std::string error;
    {
        interp::NativePrinter native(out);
        interp::LinuxCncPrinter lcnc(out);
        interp::CanonSink& sink = o.linuxcnc ? static_cast<interp::CanonSink&>(lcnc)
                                             : static_cast<interp::CanonSink&>(native);
        interp::Executor exec(sink, cfg, settings);
        interp::Interpreter in(exec, exec, iopts);
        try {
            // In-memory sources keep the file names in diagnostics independent of the checkout.
            if (!o.library.empty())
                in.set_library(interp::Source::from_string(o.library, read_file(dir / o.library)));
            in.open(interp::Source::from_string("program.nc", read_file(dir / "program.nc")));
            in.run();
        } catch (const interp::Error& e) {
            error = e.what();
        }
        if (o.linuxcnc) lcnc.finish();
    }
    std::rewind(out);
    std::string text;
    char buf[4096];
    std::size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, out)) > 0) text.append(buf, n);
    std::fclose(out);
    if (!error.empty()) text += "error: " + error + "\n";
    return text;
}

class Golden : public ::testing::TestWithParam<std::string> {};

TEST_P(Golden, MatchesExpected) {
    const fs::path dir = fs::path(INTERP_CASES_DIR) / GetParam();
    ASSERT_TRUE(fs::exists(dir / "expected")) << dir;
    ASSERT_TRUE(fs::exists(dir / "README.md")) << dir << ": every case explains what it checks";
    const std::string expected = read_file(dir / "expected");
    const std::string actual = run_case(dir);
    if (actual == expected) return;
    std::istringstream e(expected), a(actual);
    std::string le, la;
    for (int line = 1;; ++line) {
        const bool me = static_cast<bool>(std::getline(e, le));
        const bool ma = static_cast<bool>(std::getline(a, la));
        if (!me && !ma) break;
        if (!me || !ma || le != la) {
            ADD_FAILURE() << GetParam() << ": first difference at expected line " << line
                          << "\n  expected: " << (me ? le : "<end>")
                          << "\n  actual:   " << (ma ? la : "<end>") << "\nfull output:\n"
                          << actual;
            break;
        }
    }
}

INSTANTIATE_TEST_SUITE_P(Cases, Golden, ::testing::ValuesIn(case_names()),
                         [](const ::testing::TestParamInfo<std::string>& i) {
                             std::string s = i.param;
                             std::replace_if(
                                 s.begin(), s.end(), [](char c) { return !std::isalnum(c); }, '_');
                             return s;
                         });

}  // namespace
