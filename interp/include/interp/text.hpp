#pragma once
// Character helpers shared by the source indexer and the lexer. ASCII-only classification on
// purpose: the G-code grammar is ASCII; other bytes only appear inside comments and strings.
#include <cstddef>
#include <string>
#include <string_view>

namespace interp {

constexpr bool is_digit(char c) {
    return c >= '0' && c <= '9';
}
constexpr bool is_alpha(char c) {
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z');
}
constexpr bool is_space(char c) {
    return c == ' ' || c == '\t' || c == '\v' || c == '\f';
}
constexpr char to_upper(char c) {
    return (c >= 'a' && c <= 'z') ? static_cast<char>(c - 32) : c;
}

inline std::string to_upper(std::string_view s) {
    std::string out(s);
    for (char& c : out) c = to_upper(c);
    return out;
}

// Case-insensitive equality of ASCII text.
constexpr bool iequals(std::string_view a, std::string_view b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i)
        if (to_upper(a[i]) != to_upper(b[i])) return false;
    return true;
}

// Length in bytes of a double-quote character at the start of s: '"' and the typographic
// quotes U+201C and U+201D (the manuals print both). 0 when s does not start with one.
constexpr std::size_t quote_length(std::string_view s) {
    if (!s.empty() && s[0] == '"') return 1;
    if (s.size() >= 3 && s[0] == '\xE2' && s[1] == '\x80' && (s[2] == '\x9C' || s[2] == '\x9D'))
        return 3;
    return 0;
}

// Length in bytes of a comment quote at the start of s: '\'' and U+2019 (S1 prints ’). 0 if none.
constexpr std::size_t comment_quote_length(std::string_view s) {
    if (!s.empty() && s[0] == '\'') return 1;
    if (s.size() >= 3 && s[0] == '\xE2' && s[1] == '\x80' && s[2] == '\x99') return 3;
    return 0;
}

}  // namespace interp
