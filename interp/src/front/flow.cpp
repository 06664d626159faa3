#include "interp/flow.hpp"

#include <string>

#include "interp/expr.hpp"

namespace interp {

namespace {

constexpr int kG65 = 650;

// Removes the word and returns its value, if present.
std::optional<double> take_word(Block& b, char letter) {
    const int i = letter_index(letter);
    std::optional<double> v = b.words[i];
    b.words[i].reset();
    b.word_col[i] = 0;
    b.integer_literal_mask &= ~(1u << i);
    return v;
}

// Removes code `code` from a code list and its parallel column list; returns its column or 0.
int take_code(StaticVec<int, Block::kMaxCodes>& codes, StaticVec<int, Block::kMaxCodes>& cols,
              int code) {
    for (std::size_t i = 0; i < codes.size(); ++i) {
        if (codes[i] == code) {
            const int col = cols[i];
            codes.erase_at(i);
            cols.erase_at(i);
            return col;
        }
    }
    return 0;
}

std::int64_t repeat_count(Block& b, const SourceLoc& at) {
    const SourceLoc lloc = b.loc_of('L');
    const std::optional<double> l = take_word(b, 'L');
    if (!l) return 1;
    const std::int64_t n = to_integer(*l, lloc, "repeat count L");
    if (n < 0) throw Error(lloc, "repeat count L must not be negative");
    return n;
}

CallRequest take_g65(ParsedLine& line, int col) {
    Block& b = line.block;
    CallRequest call;
    call.loc = SourceLoc{b.loc.file, b.loc.line, col};
    const SourceLoc ploc = b.loc_of('P');
    if (line.p_name) {
        call.name = std::move(line.p_name);
        line.p_name.reset();
    } else if (const auto p = take_word(b, 'P')) {
        call.program = to_integer(*p, ploc, "program number P");
        if (call.program < 0) throw Error(ploc, "program number P must not be negative");
    } else {
        throw Error(call.loc, "G65 needs P (a program number or \"name\")");
    }
    call.count = repeat_count(b, call.loc);
    // S0 documents no argument syntax for G65 (ARG-8): any other address is a mistake.
    for (int i = 0; i < 26; ++i) {
        if (b.words[i]) {
            throw Error(b.loc_of(static_cast<char>('A' + i)),
                        std::string("G65 takes only P and L; ") + static_cast<char>('A' + i) +
                            " is not allowed in a G65 block");
        }
    }
    return call;
}

CallRequest take_m98(ParsedLine& line, int col, const Dialect& d) {
    Block& b = line.block;
    CallRequest call;
    call.loc = SourceLoc{b.loc.file, b.loc.line, col};
    const SourceLoc ploc = b.loc_of('P');
    if (line.p_name) {
        call.name = std::move(line.p_name);
        line.p_name.reset();
        call.count = repeat_count(b, call.loc);
        return call;
    }
    const auto p = take_word(b, 'P');
    if (!p) throw Error(call.loc, "M98 needs P (a program number)");
    const std::int64_t pn = to_integer(*p, ploc, "M98 P");
    std::optional<std::int64_t> l;
    const SourceLoc lloc = b.loc_of('L');
    if (const auto lv = take_word(b, 'L')) l = to_integer(*lv, lloc, "repeat count L");
    const CallSpec spec = d.decode_m98(pn, l, ploc);
    call.program = spec.program;
    call.count = spec.count;
    return call;
}

}  // namespace

std::string program_label(std::int64_t number, const std::optional<std::string>& name) {
    if (name) return "O\"" + *name + "\"";
    return "O" + std::to_string(number);
}

FlowWords take_flow_words(ParsedLine& line, const Dialect& d) {
    FlowWords flow;
    Block& b = line.block;
    // Most blocks carry no control word: skip the searches below for them.
    if (b.m.empty() && !b.g.contains(kG65) && !line.p_name) return flow;
    const int g65_col = take_code(b.g, b.g_col, kG65);
    const int m98_col = take_code(b.m, b.m_col, 98);
    const int m17_col = take_code(b.m, b.m_col, d.sub_end_m);
    const int m99_col = take_code(b.m, b.m_col, 99);
    if (g65_col != 0 && m98_col != 0) {
        throw Error(SourceLoc{b.loc.file, b.loc.line, m98_col},
                    "G65 and M98 in one block: only one subprogram call per block");
    }
    if (m17_col != 0 && m99_col != 0) {
        throw Error(SourceLoc{b.loc.file, b.loc.line, m99_col}, "M17 and M99 in one block");
    }
    const int call_col = g65_col != 0 ? g65_col : m98_col;
    const int ret_col = m17_col != 0 ? m17_col : m99_col;
    if (call_col != 0 && ret_col != 0) {
        throw Error(SourceLoc{b.loc.file, b.loc.line, ret_col},
                    "a block cannot both call a subprogram and return from one");
    }
    if (g65_col != 0) flow.call = take_g65(line, g65_col);
    if (m98_col != 0) flow.call = take_m98(line, m98_col, d);
    if (ret_col != 0) {
        ReturnRequest ret;
        ret.m = m17_col != 0 ? d.sub_end_m : 99;
        ret.loc = SourceLoc{b.loc.file, b.loc.line, ret_col};
        if (m99_col != 0) {
            const SourceLoc ploc = b.loc_of('P');
            if (const auto p = take_word(b, 'P')) {
                ret.sequence = to_integer(*p, ploc, "M99 P (sequence number)");
                if (*ret.sequence < 0) throw Error(ploc, "M99 P must not be negative");
            }
        }
        flow.ret = ret;
    }
    if (line.p_name) {
        throw Error(SourceLoc{b.loc.file, b.loc.line, line.p_name_col},
                    "P\"name\" is only meaningful with G65 or M98");
    }
    return flow;
}

}  // namespace interp
