#include "hal/ini.hpp"

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "hal/types.hpp"

namespace hal {

namespace {
std::string trim(const std::string& s) {
    auto b = s.find_first_not_of(" \t\r");
    if (b == std::string::npos) return "";
    auto e = s.find_last_not_of(" \t\r");
    return s.substr(b, e - b + 1);
}

std::string read_file(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(fmt::format("cannot open INI file '{}': {}", path, std::strerror(errno)));
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}
}  // namespace

IniFile IniFile::load(const std::string& path) {
    IniFile ini;
    ini.path_ = path;
    ini.read(read_file(path), path, 0);
    return ini;
}

IniFile IniFile::parse(const std::string& text, const std::string& name) {
    IniFile ini;
    ini.path_ = name;
    ini.read(text, name, 0);
    return ini;
}

void IniFile::read(const std::string& text, const std::string& file, int depth) {
    std::istringstream in(text);
    std::string raw, section;
    int line_no = 0;
    while (std::getline(in, raw)) {
        ++line_no;
        std::string line = trim(raw);
        if (line.rfind("#INCLUDE", 0) == 0) {
            auto target = trim(line.substr(8));
            if (target.empty()) throw Error(fmt::format("{}:{}: #INCLUDE needs a file name", file, line_no));
            if (depth > 8) throw Error(fmt::format("{}:{}: #INCLUDE nested too deep", file, line_no));
            std::filesystem::path p(target);
            if (p.is_relative()) p = std::filesystem::path(file).parent_path() / p;
            std::string included;
            try {
                included = read_file(p.string());
            } catch (const Error& e) {
                throw Error(fmt::format("{}:{}: {}", file, line_no, e.what()));
            }
            // An included file continues the including file's section.
            IniFile sub;
            sub.entries_.clear();
            std::string prefixed = "[" + section + "]\n" + included;
            sub.read(prefixed, p.string(), depth + 1);
            for (auto& e : sub.entries_) {
                --e.line;  // the section line added above is not in the file
                entries_.push_back(std::move(e));
            }
            continue;
        }
        if (line.empty() || line[0] == '#' || line[0] == ';') continue;
        if (line[0] == '[') {
            auto close = line.find(']');
            if (close != std::string::npos) section = trim(line.substr(1, close - 1));
            continue;
        }
        auto eq = line.find('=');
        if (eq == std::string::npos) continue;  // LinuxCNC ignores such lines
        Entry e{section, trim(line.substr(0, eq)), trim(line.substr(eq + 1)), file, line_no};
        while (!e.value.empty() && e.value.back() == '\\') {
            e.value.pop_back();
            e.value = trim(e.value);
            if (!std::getline(in, raw)) break;
            ++line_no;
            e.value += (e.value.empty() ? "" : " ") + trim(raw);
        }
        if (!e.key.empty()) entries_.push_back(std::move(e));
    }
}

const IniFile::Entry* IniFile::find(const std::string& section, const std::string& key) const {
    for (auto& e : entries_)
        if (e.section == section && e.key == key) return &e;
    return nullptr;
}

std::optional<std::string> IniFile::get(const std::string& section, const std::string& key, std::size_t n) const {
    for (auto& e : entries_)
        if (e.section == section && e.key == key && n-- == 0) return e.value;
    return std::nullopt;
}

std::vector<std::string> IniFile::all(const std::string& section, const std::string& key) const {
    std::vector<std::string> out;
    for (auto& e : entries_)
        if (e.section == section && e.key == key) out.push_back(e.value);
    return out;
}

std::optional<double> IniFile::get_number(const std::string& section, const std::string& key) const {
    const Entry* e = find(section, key);
    if (!e) return std::nullopt;
    char* end = nullptr;
    double v = std::strtod(e->value.c_str(), &end);
    if (e->value.empty() || *end)
        throw Error(fmt::format("{}:{}: [{}]{} = '{}' is not a number", e->file, e->line, section, key, e->value));
    return v;
}

}  // namespace hal
