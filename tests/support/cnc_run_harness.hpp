// Runs the `cnc` command from tests: a scratch folder per test (so tests run in parallel under
// ctest -j), the whole of a file, and `cnc run ARGS` with its exit status and output.
// The including target defines CNC_BIN (the cnc executable) and CNC_SOURCE_DIR (the repo root,
// where the arguments' relative paths start).
#pragma once

#include <fmt/format.h>
#include <stdlib.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "scratch_dir.hpp"

namespace cnc_test {

namespace fs = std::filesystem;

struct RunResult {
    int exit_code = -1;
    std::string out, err;
};

// An edit of one line of a copied sim config: the line's section ("" before the first) and
// the line, which the edit may change or extend ("\n" then more lines).
using IniEdit = std::function<void(const std::string& section, std::string& line)>;

// configs/sim/NAME.ini as text, with the paths it gives relative to its folder (HALFILE,
// HALLIB, TOOL_TABLE, PARAMETER_FILE) made absolute, so the copy runs from a scratch folder,
// and `edit` applied to every line.
inline std::string sim_ini(const std::string& name, const IniEdit& edit = {}) {
    const fs::path dir = fs::path(CNC_SOURCE_DIR) / "configs/sim";
    std::istringstream in(slurp(dir / (name + ".ini")));
    std::string text, line, section;
    while (std::getline(in, line)) {
        if (line.rfind('[', 0) == 0) section = line.substr(1, line.find(']') - 1);
        for (const char* key : {"HALFILE", "HALLIB", "TOOL_TABLE", "PARAMETER_FILE"}) {
            const std::string prefix = std::string(key) + " = ";
            if (line.rfind(prefix, 0) == 0)
                line = prefix + (dir / line.substr(prefix.size())).string();
        }
        if (edit) edit(section, line);
        text += line + "\n";
    }
    return text;
}

// A HAL file for a tool setter under the spindle of a sim config with motion_xyz.hal: input 3
// (dio-in-03) closes while the commanded Z is below `z_mm`. Written into `dir`; returns its path.
inline fs::path tool_setter_hal(const fs::path& dir, double z_mm) {
    const fs::path hal = dir / "setter.hal";
    std::ofstream(hal) << "loadrt comp names=setter\n"
                          "addf setter servo-thread\n"
                          "net z-pos-cmd => setter.in0\n"
                       << fmt::format("setp setter.in1 {}\n", z_mm)
                       << "net dio-in-03 <= setter.out\n";
    return hal;
}

// `cnc run ARGS` in `cwd`; stdout and stderr go through files in `scratch`. Unless ARGS name
// one, the machine's settings file and tool table are kept in `scratch`/settings
// (--settings-dir), so a test never writes into configs/ nor sees another test's offsets.
inline RunResult run_cnc(const std::string& args, const fs::path& scratch,
                         const fs::path& cwd = CNC_SOURCE_DIR) {
    const fs::path out = scratch / "stdout.txt", err = scratch / "stderr.txt";
    const std::string settings =
        args.find("--settings-dir") == std::string::npos
            ? fmt::format(" --settings-dir '{}'", (scratch / "settings").string())
            : "";
    const std::string cmd = fmt::format("cd '{}' && '{}' run {}{} > '{}' 2> '{}'", cwd.string(),
                                        CNC_BIN, args, settings, out.string(), err.string());
    const int status = std::system(cmd.c_str());
    RunResult r;
    r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = slurp(out);
    r.err = slurp(err);
    return r;
}

// The text after "KEY: " on the summary line that starts with KEY, or "".
inline std::string summary_field(const std::string& out, const std::string& key) {
    std::istringstream in(out);
    std::string line;
    const std::string prefix = key + ": ";
    while (std::getline(in, line))
        if (line.compare(0, prefix.size(), prefix) == 0) return line.substr(prefix.size());
    return "";
}

inline double summary_number(const std::string& out, const std::string& key) {
    const std::string field = summary_field(out, key);
    return field.empty() ? NAN : std::stod(field);
}

// "x 1.0  y 2.0 ..." (or "j0 0.1  j1 0.2 ...") -> {1.0, 2.0, ...}
inline std::vector<double> summary_axes(const std::string& out, const std::string& key) {
    std::vector<double> v;
    std::istringstream in(summary_field(out, key));
    std::string name;
    double x;
    while (in >> name >> x) v.push_back(x);
    return v;
}

// A --trace CSV: the header line into `header`, then one row of numbers per line.
inline std::vector<std::vector<double>> csv_rows(const std::string& text, std::string& header) {
    std::istringstream in(text);
    std::getline(in, header);
    std::vector<std::vector<double>> rows;
    std::string line;
    while (std::getline(in, line)) {
        std::vector<double> row;
        std::istringstream cells(line);
        std::string cell;
        while (std::getline(cells, cell, ',')) row.push_back(std::stod(cell));
        rows.push_back(row);
    }
    return rows;
}

}  // namespace cnc_test
