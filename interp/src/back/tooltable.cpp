// LinuxCNC .tbl reader and writer: one tool per line, words T P D X Y Z A B C U V W I J Q, ';'
// comment. The writer edits the file's own text so that what the reader ignores survives.
#include "interp/tooltable.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <optional>
#include <set>
#include <sstream>
#include <vector>

#include "interp/block.hpp"
#include "text_lines.hpp"

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

// One word of a line: its letter (upper case) and where its number is, so that a rewrite can
// replace just the number.
struct Word {
    char letter;
    std::size_t num_begin;
    std::size_t num_end;
};

// A line as read: the entry it gives (the last of a repeated word wins), its words in order and
// where its comment is.
struct ParsedLine {
    std::optional<int> tool;
    ToolEntry entry;
    std::vector<Word> words;
    std::optional<std::size_t> semi;  // the ';'
    std::size_t comment_begin = 0;    // first non-blank after the ';'
};

// Throws the error of one column (0-based) of one line.
struct LineError {
    std::string_view name;
    int line_no;
    [[noreturn]] void operator()(std::size_t col, const std::string& why) const {
        throw Error(SourceLoc{name, line_no, static_cast<int>(col) + 1}, why);
    }
};

void apply_word(char c, double v, std::size_t col, ParsedLine& p, const LineError& err) {
    switch (c) {
        case 'T':
            if (v < 0 || v != static_cast<int>(v)) err(col, "tool table: bad tool number");
            p.tool = static_cast<int>(v);
            break;
        case 'P':
            p.entry.pocket = static_cast<int>(v);
            break;
        case 'D':
            if (v < 0) err(col, "tool table: negative diameter");
            p.entry.diameter_mm = v;
            break;
        case 'X':
        case 'Y':
        case 'Z':
            p.entry.offset_mm[c - 'X'] = v;
            break;
        // Rotary/UVW offsets and lathe orientation words exist in LinuxCNC tables; a mill's
        // offset vector has no place for them, so they are read, ignored and kept on rewrite.
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
            err(col, std::string("tool table: unknown word '") + c + "'");
    }
}

// `line` without its line ending.
ParsedLine parse_line(const std::string& line, std::string_view name, int line_no) {
    const LineError err{name, line_no};
    ParsedLine p;
    std::size_t body_end = line.size();
    if (auto semi = line.find(';'); semi != std::string::npos) {
        p.semi = semi;
        body_end = semi;
        p.comment_begin = semi + 1;
        while (p.comment_begin < line.size() &&
               std::isspace(static_cast<unsigned char>(line[p.comment_begin])))
            ++p.comment_begin;
        p.entry.comment = line.substr(p.comment_begin);
    }
    const std::string body = line.substr(0, body_end);
    std::size_t pos = 0;
    while (pos < body.size()) {
        const char c = static_cast<char>(std::toupper(static_cast<unsigned char>(body[pos])));
        if (std::isspace(static_cast<unsigned char>(c))) {
            ++pos;
            continue;
        }
        const std::size_t word_col = pos;
        ++pos;
        const std::size_t num_begin = pos;
        double v = 0;
        if (!read_number(body, pos, v))
            err(pos, std::string("tool table: expected a number after '") + c + "'");
        // from_chars reads "inf" and "nan": a length like that would send the machine anywhere.
        if (!std::isfinite(v)) err(num_begin, "tool table: value is not a finite number");
        p.words.push_back(Word{c, num_begin, pos});
        apply_word(c, v, word_col, p, err);
    }
    if (!p.words.empty() && !p.tool) err(0, "tool table: line has no T word");
    return p;
}

// Calls `each(line, ending, parsed)` for every line of `text` (text_lines::for_each). A bad
// line throws, so a writer never produces a table from one the reader would refuse.
template <typename Each>
void for_each_line(const std::string& text, std::string_view name, Each each) {
    std::set<int> tools;
    int line_no = 0;
    text_lines::for_each(text, [&](const std::string& line, const std::string& ending) {
        ++line_no;
        ParsedLine p = parse_line(line, name, line_no);
        if (p.tool && !tools.insert(*p.tool).second)
            throw Error(SourceLoc{name, line_no, 1},
                        "tool table: tool " + std::to_string(*p.tool) + " listed twice");
        each(line, ending, p);
    });
}

// Replaces `erase` characters at `at` with `text`.
struct Edit {
    std::size_t at;
    std::size_t erase;
    std::string text;
};

// `line` holding `now` in place of what `was` parsed from it (see update_linuxcnc_tool_table).
std::string updated_line(std::string line, const ParsedLine& was, const ToolEntry& now) {
    std::vector<Edit> edits;
    std::string added;  // words the line lacks, written after its last word
    auto sync = [&](char letter, bool same, const std::string& text) {
        if (same) return;
        auto it = std::find_if(was.words.rbegin(), was.words.rend(),
                               [&](const Word& w) { return w.letter == letter; });
        if (it != was.words.rend())
            edits.push_back(Edit{it->num_begin, it->num_end - it->num_begin, text});
        else
            added += fmt::format(" {}{}", letter, text);
    };
    sync('P', was.entry.pocket == now.pocket, fmt::format("{}", now.pocket));
    for (int a = 0; a < 3; ++a)
        sync(static_cast<char>('X' + a), was.entry.offset_mm[a] == now.offset_mm[a],
             fmt::format("{}", now.offset_mm[a]));
    sync('D', was.entry.diameter_mm == now.diameter_mm, fmt::format("{}", now.diameter_mm));
    if (!added.empty()) edits.push_back(Edit{was.words.back().num_end, 0, added});
    if (was.entry.comment != now.comment) {
        if (was.semi)
            edits.push_back(Edit{was.comment_begin, line.size() - was.comment_begin, now.comment});
        else
            edits.push_back(Edit{line.size(), 0, " ;" + now.comment});
    }
    // Back to front, so every edit's position is still where it was parsed.
    std::sort(edits.begin(), edits.end(), [](const Edit& a, const Edit& b) { return a.at > b.at; });
    for (const Edit& e : edits) line.replace(e.at, e.erase, e.text);
    return line;
}

std::string new_line(int n, const ToolEntry& e) {
    // A tool the program created (G923) has no pocket: it gets its own number, as a LinuxCNC
    // sim table numbers them.
    std::string out = fmt::format("T{} P{}", n, e.pocket != 0 ? e.pocket : n);
    // X and Y only when set, as LinuxCNC writes them; a mill's length (Z) always.
    if (e.offset_mm[0] != 0) out += fmt::format(" X{}", e.offset_mm[0]);
    if (e.offset_mm[1] != 0) out += fmt::format(" Y{}", e.offset_mm[1]);
    out += fmt::format(" Z{} D{}", e.offset_mm[2], e.diameter_mm);
    if (!e.comment.empty()) out += " ;" + e.comment;
    return out;
}

}  // namespace

ToolTable parse_linuxcnc_tool_table(const std::string& text, const std::string& name) {
    ToolTable table;
    for_each_line(text, name, [&](const std::string&, const std::string&, const ParsedLine& p) {
        if (p.tool) table.at(*p.tool) = p.entry;
    });
    return table;
}

ToolTable load_linuxcnc_tool_table(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    if (!f) throw Error(SourceLoc{path, 0, 0}, "cannot open tool table");
    std::ostringstream ss;
    ss << f.rdbuf();
    return parse_linuxcnc_tool_table(ss.str(), path);
}

std::string format_linuxcnc_tool_table(const ToolTable& t) {
    return update_linuxcnc_tool_table("", t, "");
}

std::string update_linuxcnc_tool_table(const std::string& old_text, const ToolTable& t,
                                       const std::string& name) {
    std::string out;
    std::set<int> listed;
    for_each_line(old_text, name,
                  [&](const std::string& line, const std::string& ending, const ParsedLine& p) {
                      const ToolEntry* now = p.tool ? t.find(*p.tool) : nullptr;
                      out += now ? updated_line(line, p, *now) : line;
                      out += ending;
                      if (p.tool) listed.insert(*p.tool);
                  });
    const std::string ending = text_lines::ending_of(old_text);
    for (const auto& [n, e] : t.entries())
        if (!listed.count(n)) text_lines::append_line(out, new_line(n, e), ending);
    return out;
}

}  // namespace interp
