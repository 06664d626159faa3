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

}  // namespace interp
