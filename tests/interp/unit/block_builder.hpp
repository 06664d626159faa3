#pragma once
// Builds interp::Block values from a tiny word syntax ("G01 X10 Y-2.5 F100 M03") so the back end
// can be tested without the front end. Only letters followed by plain numbers; keywords and
// messages are set on the returned Block directly.
#include <cctype>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "interp/block.hpp"

namespace interp::test {

inline Block blk(const std::string& text, int line = 1) {
    static const std::string kFile = "test.nc";
    Block b;
    b.loc = SourceLoc{kFile, line, 1};
    std::size_t i = 0;
    while (i < text.size()) {
        if (std::isspace(static_cast<unsigned char>(text[i]))) {
            ++i;
            continue;
        }
        const int col = static_cast<int>(i) + 1;
        const char letter = static_cast<char>(std::toupper(static_cast<unsigned char>(text[i++])));
        const std::size_t start = i;
        while (i < text.size() && (std::isdigit(static_cast<unsigned char>(text[i])) ||
                                   text[i] == '.' || text[i] == '-' || text[i] == '+'))
            ++i;
        const std::string num = text.substr(start, i - start);
        if (num.empty())
            throw std::invalid_argument("blk: no number after " + std::string(1, letter));
        const double v = std::strtod(num.c_str(), nullptr);
        if (letter == 'G') {
            const int whole = static_cast<int>(v);
            const int tenth = static_cast<int>((v - whole) * 10 + 0.5);
            b.g.push_back(gcode(whole, tenth));
            b.g_col.push_back(col);
        } else if (letter == 'M') {
            b.m.push_back(static_cast<int>(v));
            b.m_col.push_back(col);
        } else if (letter == 'N') {
            b.n = static_cast<std::int64_t>(v);
        } else {
            b.words[letter_index(letter)] = v;
            b.word_col[letter_index(letter)] = col;
            if (num.find('.') == std::string::npos)
                b.integer_literal_mask |= 1u << letter_index(letter);
        }
    }
    return b;
}

}  // namespace interp::test
