// The lines of a file a person may have written, with what ended each, for the writers that
// edit such a file (the tool table, the settings file) and must give back every byte they do
// not change.
#pragma once

#include <string>

namespace interp::text_lines {

// Calls each(line, ending) for every line of `text`: `line` without its ending, `ending` what
// ended it ("\r\n", "\n", or "" for a last line without one).
template <typename Each>
void for_each(const std::string& text, Each each) {
    std::size_t start = 0;
    while (start < text.size()) {
        const std::size_t nl = text.find('\n', start);
        const std::size_t end = nl == std::string::npos ? text.size() : nl;
        std::string line = text.substr(start, end - start);
        std::string ending = nl == std::string::npos ? "" : "\n";
        if (!line.empty() && line.back() == '\r') {
            line.pop_back();
            ending.insert(ending.begin(), '\r');
        }
        each(line, ending);
        start = end == text.size() ? end : end + 1;
    }
}

// Lines added to `text` end as its first line does (a file written on Windows keeps "\r\n").
inline std::string ending_of(const std::string& text) {
    const std::size_t nl = text.find('\n');
    return nl != std::string::npos && nl > 0 && text[nl - 1] == '\r' ? "\r\n" : "\n";
}

// Appends `line` to `out` as a line of its own, ending it with `ending`.
inline void append_line(std::string& out, const std::string& line, const std::string& ending) {
    if (!out.empty() && out.back() != '\n') out += ending;
    out += line + ending;
}

}  // namespace interp::text_lines
