// LinuxCNC .tbl reader: one tool per line, words T P D X Y Z A B C U V W I J Q, ';' comment.
#include "interp/tooltable.hpp"

#include <cctype>
#include <charconv>
#include <fstream>
#include <sstream>

#include "interp/block.hpp"

namespace interp {

namespace {

// Parses one number starting at pos; advances pos.
bool read_number(const std::string& s, std::size_t& pos, double& out) {
    const char* first = s.data() + pos;
    const char* last = s.data() + s.size();
    if (first < last && *first == '+') ++first;
    auto [ptr, ec] = std::from_chars(first, last, out);
    if (ec != std::errc() || ptr == first) return false;
    pos = static_cast<std::size_t>(ptr - s.data());
    return true;
}

void parse_line(const std::string& line, std::string_view name, int line_no, ToolTable& table) {
    auto err = [&](std::size_t col, const std::string& why) {
        throw Error(SourceLoc{name, line_no, static_cast<int>(col) + 1}, why);
    };
    std::string comment;
    std::string body = line;
    if (auto semi = line.find(';'); semi != std::string::npos) {
        comment = line.substr(semi + 1);
        body = line.substr(0, semi);
        while (!comment.empty() && std::isspace(static_cast<unsigned char>(comment.front())))
            comment.erase(comment.begin());
    }
    std::optional<int> tool;
    ToolEntry e;
    e.comment = comment;
    std::size_t pos = 0;
    bool any = false;
    while (pos < body.size()) {
        const char c = static_cast<char>(std::toupper(static_cast<unsigned char>(body[pos])));
        if (std::isspace(static_cast<unsigned char>(c))) {
            ++pos;
            continue;
        }
        const std::size_t word_col = pos;
        ++pos;
        double v = 0;
        if (!read_number(body, pos, v))
            err(pos, std::string("tool table: expected a number after '") + c + "'");
        any = true;
        switch (c) {
            case 'T':
                if (v < 0 || v != static_cast<int>(v)) err(word_col, "tool table: bad tool number");
                tool = static_cast<int>(v);
                break;
            case 'P':
                e.pocket = static_cast<int>(v);
                break;
            case 'D':
                if (v < 0) err(word_col, "tool table: negative diameter");
                e.diameter_mm = v;
                break;
            case 'X':
                e.offset_mm[0] = v;
                break;
            case 'Y':
                e.offset_mm[1] = v;
                break;
            case 'Z':
                e.offset_mm[2] = v;
                break;
            // Rotary/UVW offsets and lathe orientation words exist in LinuxCNC tables; a mill's
            // offset vector has no place for them, so they are read and ignored.
            case 'A':
            case 'B':
            case 'C':
            case 'U':
            case 'V':
            case 'W':
            case 'I':
            case 'J':
            case 'Q':
                break;
            default:
                err(word_col, std::string("tool table: unknown word '") + c + "'");
        }
    }
    if (!any) return;  // blank or comment-only line
    if (!tool) err(0, "tool table: line has no T word");
    if (table.find(*tool)) err(0, "tool table: tool " + std::to_string(*tool) + " listed twice");
    table.at(*tool) = e;
}

}  // namespace

ToolTable parse_linuxcnc_tool_table(const std::string& text, const std::string& name) {
    ToolTable table;
    std::istringstream in(text);
    std::string line;
    int line_no = 0;
    while (std::getline(in, line)) {
        ++line_no;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        parse_line(line, name, line_no, table);
    }
    return table;
}

ToolTable load_linuxcnc_tool_table(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    if (!f) throw Error(SourceLoc{path, 0, 0}, "cannot open tool table");
    std::ostringstream ss;
    ss << f.rdbuf();
    return parse_linuxcnc_tool_table(ss.str(), path);
}

}  // namespace interp
