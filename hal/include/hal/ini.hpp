// INI files as LinuxCNC writes them, for [SECTION]KEY substitution and machine configs.
//
// LinuxCNC's format is looser than what INI libraries accept, and its users' files rely on
// that: keys may be indented, a line without '=' is ignored, a value may continue on the
// next line after a trailing '\', a key may repeat (HALFILE = …) and keeps its order,
// `#INCLUDE file` pulls in another file. Whole-line comments start with '#' or ';'.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace hal {

class IniFile {
public:
    struct Entry {
        std::string section;
        std::string key;
        std::string value;
        std::string file;  // where it was written, for error messages
        int line;
    };
    // Throws hal::Error (`file:line: cause`) for a missing file or a bad #INCLUDE.
    static IniFile load(const std::string& path);
    static IniFile parse(const std::string& text, const std::string& name = "<string>");

    // The first value of a key, or the n-th when it repeats.
    std::optional<std::string> get(const std::string& section, const std::string& key, std::size_t n = 0) const;
    std::vector<std::string> all(const std::string& section, const std::string& key) const;
    const Entry* find(const std::string& section, const std::string& key) const;
    // A number, with an error naming file, line, section and key when the value is not one.
    std::optional<double> get_number(const std::string& section, const std::string& key) const;
    const std::string& path() const noexcept { return path_; }
    const std::vector<Entry>& entries() const noexcept { return entries_; }

private:
    void read(const std::string& text, const std::string& file, int depth);
    std::string path_;
    std::vector<Entry> entries_;
};

}  // namespace hal
