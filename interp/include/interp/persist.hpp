#pragma once
// Settings that survive power cycles: work offsets, the G92 shift, the tool table and the named
// parameters the manual says persist. Stored as a small line-oriented text file:
//
//   # comment
//   wcs <1..6> X Y Z A B C
//   common X Y Z A B C
//   g92 X Y Z A B C
//   tool <n> <offset X> <offset Y> <offset Z> <diameter>
//   param <NAME> <value>
//
// Written atomically (temporary file in the same directory, fsync, rename, fsync directory), so a
// crash leaves either the old or the new file, never a torn one.
#include <map>
#include <string>

#include "interp/offsets.hpp"
#include "interp/tooltable.hpp"

namespace interp {

struct Settings {
    WorkOffsets offsets;
    ToolTable tools;
    std::map<std::string, double, std::less<>> params;
    bool operator==(const Settings&) const = default;
};

// A missing file gives default settings. A malformed one throws interp::Error naming
// "file:line:col: cause", one that cannot be read (or is a directory) "file:0:0: settings:
// cannot read file: cause"; nothing is changed on disk.
Settings load_settings(const std::string& path);
Settings parse_settings(const std::string& text, const std::string& name);
std::string format_settings(const Settings& s);
// Throws std::runtime_error with the path and errno text on failure; the old file stays intact.
void save_settings_atomic(const std::string& path, const Settings& s);

// A tool table in LinuxCNC's .tbl form, one line per tool in tool order:
// "T1 P1 Z40 D6 ;comment" (X and Y only when not 0; a tool without a pocket gets P = its
// number). What load_linuxcnc_tool_table reads and ignores (A B C U V W I J Q words, comment
// lines, the order of the lines) is not written back.
std::string format_linuxcnc_tool_table(const ToolTable& t);
// Written as save_settings_atomic writes the settings, with the same guarantees and errors.
void save_tool_table_atomic(const std::string& path, const ToolTable& t);

}  // namespace interp
