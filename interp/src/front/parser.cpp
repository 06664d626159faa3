#include "interp/parser.hpp"

#include <fmt/format.h>

#include <cmath>
#include <string>

#include "interp/named_params.hpp"
#include "interp/text.hpp"

namespace interp {

void ParsedLine::reset() {
    block.clear(letters_set);
    letters_set = 0;
    is_label = false;
    label_number = -1;
    label_name.clear();
    p_name.reset();
    p_name_col = 0;
    block_delete = false;
    if_false = false;
}

struct BlockParser::Ctx {
    TokenCursor cur;
    ExprEvaluator eval;
    ParsedLine& out;
    SourceLoc loc;
    bool dry = false;  // after a false IF: check syntax, store nothing
    Block& block() { return out.block; }
    SourceLoc at(const Token& t) const { return SourceLoc{loc.file, loc.line, t.col}; }
};

namespace {

std::string quoted(std::string_view s) {
    return "'" + std::string(s) + "'";
}

// Per-axis keyword: "FX" -> 0, "FY" -> 1, "FZ" -> 2 when the first letter matches.
int axis_keyword(std::string_view w, char first) {
    if (w.size() != 2 || to_upper(w[0]) != first) return -1;
    const char a = to_upper(w[1]);
    if (a == 'X') return 0;
    if (a == 'Y') return 1;
    if (a == 'Z') return 2;
    return -1;
}

int to_int32(double v, const SourceLoc& loc, std::string_view what) {
    const std::int64_t i = to_integer(v, loc, what);
    if (i < -2147483647 || i > 2147483647) throw Error(loc, std::string(what) + " is out of range");
    return static_cast<int>(i);
}

// store_word for G, M, N and for a letter already present (the repeat error).
void store_coded_word(ParsedLine& out, const SourceLoc& loc, char L, int col, double v,
                      bool integer_literal) {
    Block& b = out.block;
    const auto at = [&] { return SourceLoc{loc.file, loc.line, col}; };
    switch (L) {
        case 'G': {
            const double scaled = v * 10.0;
            const double r = std::nearbyint(scaled);
            if (std::fabs(scaled - r) > 1e-6) {
                throw Error(at(), "G code G" + fmt::format("{}", v) + " has more than one decimal");
            }
            if (r < 0 || r > 1e7) throw Error(at(), "G code out of range");
            if (!b.g.push_back(static_cast<int>(r)) || !b.g_col.push_back(col)) {
                throw Error(at(), "too many G codes in one block");
            }
            return;
        }
        case 'M': {
            const int m = to_int32(v, at(), "M code");
            if (m < 0) throw Error(at(), "M code must not be negative");
            if (!b.m.push_back(m) || !b.m_col.push_back(col)) {
                throw Error(at(), "too many M codes in one block");
            }
            return;
        }
        case 'N': {
            if (b.n) throw Error(at(), "a block can have only one sequence number N");
            const std::int64_t n = to_integer(v, at(), "sequence number N");
            if (n < 0) throw Error(at(), "sequence number N must not be negative");
            b.n = n;
            return;
        }
        default: {
            const int i = letter_index(L);
            if (b.words[i] || (L == 'P' && out.p_name)) {
                throw Error(at(), std::string("word ") + L + " appears twice in one block");
            }
            b.words[i] = v;
            b.word_col[i] = col;
            out.letters_set |= 1u << i;
            if (integer_literal) b.integer_literal_mask |= 1u << i;
            return;
        }
    }
}

// Stores the value of address letter L (upper case) written at column `col` of the line at `loc`;
// throws what a bad or repeated word deserves. Shared by the general path and the plain-line fast
// path, so both store and reject alike. The common case, a first X, Y, F…, is kept small enough
// to inline.
inline void store_word(ParsedLine& out, const SourceLoc& loc, char L, int col, double v,
                       bool integer_literal) {
    const int i = letter_index(L);
    Block& b = out.block;
    if (L == 'G' || L == 'M' || L == 'N' || b.words[i] || (L == 'P' && out.p_name))
        return store_coded_word(out, loc, L, col, v, integer_literal);
    b.words[i] = v;
    b.word_col[i] = col;
    out.letters_set |= 1u << i;
    if (integer_literal) b.integer_literal_mask |= 1u << i;
}

}  // namespace

void BlockParser::parse(std::string_view line, const SourceLoc& loc, ParsedLine& out) {
    out.reset();
    out.block.loc = loc;
    // Most lines of a CAM program are plain words: they skip the tokens and the token walk.
    if (lexer_.lex_plain(line, plain_)) {
        if (plain_.count > 0) out.block.loc.col = plain_.words[0].col;
        for (int i = 0; i < plain_.count; ++i) {
            const PlainWord& w = plain_.words[static_cast<std::size_t>(i)];
            store_word(out, loc, to_upper(w.letter), w.col, w.value, w.integer_literal);
        }
        return;
    }
    lexer_.lex(line, loc, tokens_);
    Ctx c{TokenCursor{&tokens_, 0}, ExprEvaluator(*dialect_, vars_, machine_, loc.file, loc.line),
          out, loc};
    if (!tokens_.empty() && tokens_.front().kind != Tok::End) {
        out.block.loc.col = tokens_.front().col;
        c.loc.col = tokens_.front().col;
    }
    const Token& first = c.cur.peek();
    if (first.kind == Tok::Op && first.op == Op::Slash) {
        out.block_delete = true;
        c.cur.next();
    }
    while (!c.cur.at_end()) parse_word(c);
}

void BlockParser::parse_word(Ctx& c) {
    const Token& t = c.cur.next();
    switch (t.kind) {
        case Tok::Word:
            if (t.text.size() == 1) {
                parse_letter(c, t);
            } else {
                parse_keyword(c, t);
            }
            return;
        case Tok::Var:
            parse_assignment(c, t);
            return;
        case Tok::String:
            // V5.4 writes M801 "text" without MSG (S1 §3.4).
            if (c.dry) return;
            if (c.block().msg) throw Error(c.at(t), "a block can carry only one message string");
            c.block().msg = std::string(t.text);
            return;
        case Tok::Number:
            throw Error(c.at(t), "number " + quoted(t.text) + " without an address letter");
        case Tok::Op:
            throw Error(c.at(t), "unexpected " + quoted(t.text) + " where a word should start");
        case Tok::End:
            return;
    }
}

double BlockParser::parse_value(Ctx& c, const Token& address, bool* integer_literal) {
    const Token& t = c.cur.peek();
    if (t.kind == Tok::Number) {  // most words: a plain literal right after the letter
        c.cur.next();
        if (integer_literal != nullptr) *integer_literal = !t.has_point;
        return t.number;
    }
    return parse_signed_or_expression(c, address, integer_literal);
}

double BlockParser::parse_signed_or_expression(Ctx& c, const Token& address,
                                               bool* integer_literal) {
    const Token& t = c.cur.peek();
    if (t.kind == Tok::Op && t.op == Op::Assign) {
        c.cur.next();
        const Token& e = c.cur.peek();
        if (e.kind == Tok::End) throw Error(c.at(e), "expression expected after '='");
        if (e.space_before && !dialect_->tolerant_expr_spaces) {
            throw Error(c.at(e), "spaces are not allowed inside an expression");
        }
        return c.eval.evaluate(c.cur, c.dry);
    }
    double sign = 1.0;
    if (t.kind == Tok::Op && (t.op == Op::Minus || t.op == Op::Plus)) {
        sign = t.op == Op::Minus ? -1.0 : 1.0;
        c.cur.next();
        const Token& n = c.cur.peek();
        if (n.kind == Tok::Number && n.space_before) {
            throw Error(c.at(n), "space between a sign and its number");
        }
    }
    const Token& n = c.cur.peek();
    if (n.kind != Tok::Number) {
        throw Error(c.at(n.kind == Tok::End ? address : n),
                    "expected a number or '=' after " + std::string(address.text));
    }
    c.cur.next();
    if (integer_literal != nullptr) *integer_literal = !n.has_point;
    return sign * n.number;
}

void BlockParser::parse_letter(Ctx& c, const Token& letter) {
    const char L = to_upper(letter.text[0]);
    Block& b = c.block();
    if (L == 'O') {
        const Token& t = c.cur.next();
        if (t.kind == Tok::String) {
            for (char ch : t.text) {
                if (!is_alpha(ch) && !is_digit(ch) && ch != '_') {
                    throw Error(c.at(t), "subprogram name " + quoted(t.text) +
                                             " may only contain letters, digits and '_'");
                }
            }
            if (t.text.empty()) throw Error(c.at(t), "empty subprogram name");
            c.out.label_name = std::string(t.text);
        } else if (t.kind == Tok::Number && !t.has_point) {
            c.out.label_number = to_integer(t.number, c.at(t), "program number");
        } else {
            throw Error(c.at(letter), "O must be followed by a program number or a \"name\"");
        }
        const Token& rest = c.cur.peek();
        if (rest.kind != Tok::End || !b.empty() || b.n || letter.col != c.loc.col) {
            throw Error(rest.kind != Tok::End ? c.at(rest) : c.at(letter),
                        "a subprogram label O… must stand alone on its line");
        }
        c.out.is_label = true;
        return;
    }
    if (L == 'P' && c.cur.peek().kind == Tok::String) {
        const Token& t = c.cur.next();
        if (c.dry) return;
        if (c.out.p_name || b.has('P'))
            throw Error(c.at(letter), "word P appears twice in one block");
        c.out.p_name = std::string(t.text);
        c.out.p_name_col = letter.col;
        return;
    }
    bool integer_literal = false;
    const double v = parse_value(c, letter, &integer_literal);
    if (c.dry) return;
    store_word(c.out, c.loc, L, letter.col, v, integer_literal);
}

int BlockParser::parse_plc_address(Ctx& c, const Token& keyword) {
    const Token& t = c.cur.peek();
    if (t.kind == Tok::Op && t.op == Op::LBracket) {
        c.cur.next();
        const Token& n = c.cur.next();
        if (n.kind != Tok::Number || n.has_point) {
            throw Error(c.at(n), std::string(keyword.text) + "[…] needs an integer PLC address");
        }
        const Token& close = c.cur.next();
        if (close.kind != Tok::Op || close.op != Op::RBracket) {
            throw Error(c.at(close), "expected ']' after the PLC address");
        }
        return to_int32(n.number, c.at(n), "PLC address");
    }
    const double v = parse_value(c, keyword, nullptr);
    if (c.dry) return 0;
    return to_int32(v, c.at(keyword), std::string(keyword.text) + " address");
}

void BlockParser::parse_keyword(Ctx& c, const Token& word) {
    const std::string_view w = word.text;
    const SourceLoc at = c.at(word);
    Block& b = c.block();
    auto once = [&](bool present) {
        if (present && !c.dry) {
            throw Error(at, "word " + to_upper(w) + " appears twice in one block");
        }
    };
    if (iequals(w, "IF")) {
        const Token& open = c.cur.next();
        if (open.kind != Tok::Op || open.op != Op::LParen) {
            throw Error(c.at(open), "IF must be followed by '(' condition ')'");
        }
        const double cond = c.eval.evaluate(c.cur, c.dry);
        const Token& close = c.cur.next();
        if (close.kind != Tok::Op || close.op != Op::RParen) {
            throw Error(c.at(close), "expected ')' to close the IF condition");
        }
        if (!c.dry && cond == 0.0) {
            c.dry = true;
            c.out.if_false = true;
        }
        return;
    }
    if (iequals(w, "PLC")) {
        once(b.kw.plc.has_value());
        const int addr = parse_plc_address(c, word);
        if (!c.dry) b.kw.plc = addr;
        return;
    }
    if (iequals(w, "LEVEL")) {
        once(b.kw.level.has_value());
        const double v = parse_value(c, word, nullptr);
        if (!c.dry) b.kw.level = to_int32(v, at, "LEVEL");
        return;
    }
    if (iequals(w, "MSG")) {
        const Token& s = c.cur.next();
        if (s.kind != Tok::String) throw Error(c.at(s), "MSG must be followed by a \"string\"");
        once(b.msg.has_value());
        if (!c.dry) b.msg = std::string(s.text);
        return;
    }
    if (const int a = axis_keyword(w, 'F'); a >= 0) {
        once(b.kw.f_axis[a].has_value());
        const double v = parse_value(c, word, nullptr);
        if (!c.dry) b.kw.f_axis[a] = v;
        return;
    }
    if (const int a = axis_keyword(w, 'P'); a >= 0) {
        once(b.kw.p_axis[a].has_value());
        const int addr = parse_plc_address(c, word);
        if (!c.dry) b.kw.p_axis[a] = addr;
        return;
    }
    if (const int a = axis_keyword(w, 'L'); a >= 0) {
        once(b.kw.l_axis[a].has_value());
        const double v = parse_value(c, word, nullptr);
        if (!c.dry) b.kw.l_axis[a] = to_int32(v, at, std::string(w) + " level");
        return;
    }
    throw Error(at, "unknown word " + quoted(w));
}

void BlockParser::parse_assignment(Ctx& c, const Token& var) {
    const VarRef ref = c.eval.resolve(var);
    const Token& eq = c.cur.next();
    if (eq.kind != Tok::Op || eq.op != Op::Assign) {
        throw Error(c.at(var), "#" + std::string(var.text) +
                                   " on its own is not a word (did you mean #" +
                                   std::string(var.text) + "=…?)");
    }
    std::optional<NamedParam> named;
    if (ref.kind == VarRef::Kind::Named) {
        named = find_named_param(var.text, *dialect_);
        if (!named || !named->writable)
            throw Error(c.at(var), "named parameter #" + std::string(var.text) + " is read-only");
    }
    const Token& e = c.cur.peek();
    if (e.kind == Tok::End) throw Error(c.at(e), "expression expected after '='");
    const double v = c.eval.evaluate(c.cur, c.dry);
    if (c.dry) return;
    if (named) {
        if (!machine_.can_write_setting(named->name))
            throw Error(c.at(var), "named parameter #" + std::string(named->name) +
                                       " cannot be stored on this machine (no settings file)");
        const double to_mm = named->length ? machine_.mm_per_program_unit() : 1.0;
        vars_.set_named(named->name, v * to_mm, c.at(var));
    } else if (ref.kind == VarRef::Kind::Numbered) {
        vars_.set_numbered(ref.index, v, c.at(var));
    } else {
        vars_.set_fixed_cycle(ref.index, v, c.at(var));
    }
}

}  // namespace interp
