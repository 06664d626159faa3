#include "interp/lexer.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <string>

#include "interp/text.hpp"

namespace interp {

std::string_view op_text(Op op) {
    switch (op) {
        case Op::None:
            return "";
        case Op::Plus:
            return "+";
        case Op::Minus:
            return "-";
        case Op::Star:
            return "*";
        case Op::Slash:
            return "/";
        case Op::Caret:
            return "^";
        case Op::Not:
            return "!";
        case Op::Assign:
            return "=";
        case Op::EqEq:
            return "==";
        case Op::NotEq:
            return "!=";
        case Op::Less:
            return "<";
        case Op::Greater:
            return ">";
        case Op::LessEq:
            return "<=";
        case Op::GreaterEq:
            return ">=";
        case Op::AndAnd:
            return "&&";
        case Op::OrOr:
            return "||";
        case Op::Bar:
            return "|";
        case Op::LParen:
            return "(";
        case Op::RParen:
            return ")";
        case Op::LBracket:
            return "[";
        case Op::RBracket:
            return "]";
        case Op::Comma:
            return ",";
    }
    return "?";
}

namespace {

constexpr double kPow10[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
                             1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

// What a byte can start. Letters, digits and spaces make up nearly all of a G-code line, so one
// table lookup sends them to their own branch before any of the rarer cases is considered.
enum class CharClass : std::uint8_t { Other, Space, Letter, Digit };

constexpr std::array<CharClass, 256> make_char_classes() {
    std::array<CharClass, 256> t{};
    for (int c = 0; c < 256; ++c) {
        const char ch = static_cast<char>(c);
        if (is_space(ch)) t[c] = CharClass::Space;
        if (is_alpha(ch)) t[c] = CharClass::Letter;
        if (is_digit(ch)) t[c] = CharClass::Digit;
    }
    return t;
}

constexpr std::array<CharClass, 256> kCharClass = make_char_classes();

CharClass char_class(char c) {
    return kCharClass[static_cast<unsigned char>(c)];
}

// Accumulates the decimal digits from p on into `mantissa`; returns the first non-digit.
const char* scan_digits(const char* p, const char* end, std::uint64_t& mantissa) {
    for (; p != end; ++p) {
        const unsigned d = static_cast<unsigned char>(*p) - unsigned{'0'};
        if (d > 9) break;
        mantissa = mantissa * 10 + d;
    }
    return p;
}

// Parses [digits][.digits] starting at s[i]; the caller guarantees a digit or '.' there.
// Integer mantissas below 2^53 divided by an exact power of ten round once, so the fast path is
// correctly rounded; longer literals go through from_chars.
std::size_t scan_number(std::string_view s, std::size_t i, Token& tok) {
    const char* const start = s.data() + i;
    const char* const end = s.data() + s.size();
    std::uint64_t mantissa = 0;
    const char* p = scan_digits(start, end, mantissa);
    std::ptrdiff_t digits = p - start;
    int frac_digits = 0;
    if (p != end && *p == '.') {
        tok.has_point = true;
        const char* const frac = p + 1;
        p = scan_digits(frac, end, mantissa);
        frac_digits = static_cast<int>(p - frac);
        digits += frac_digits;
    }
    tok.kind = Tok::Number;
    tok.text = std::string_view(start, static_cast<std::size_t>(p - start));
    if (digits <= 15) {
        // No division for integers: its latency is a large share of lexing a G1 line.
        tok.number = frac_digits == 0 ? static_cast<double>(mantissa)
                                      : static_cast<double>(mantissa) / kPow10[frac_digits];
    } else {
        std::string_view t = tok.text;
        std::string buf;
        if (t.front() == '.') {
            buf = "0" + std::string(t);
            t = buf;
        }
        if (t.back() == '.') t.remove_suffix(1);
        double v = 0.0;
        const auto [last, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
        // Out of double range: the caller reports it with the token's column.
        tok.number = ec == std::errc{} ? v : HUGE_VAL;
    }
    return i + tok.text.size();
}

// Two-character operators first, then single characters.
Op scan_op(std::string_view s, std::size_t i, bool abs_bars, std::size_t& len) {
    const char c = s[i];
    const char n = i + 1 < s.size() ? s[i + 1] : '\0';
    len = 2;
    if (c == '=' && n == '=') return Op::EqEq;
    if (c == '!' && n == '=') return Op::NotEq;
    if (c == '<' && n == '=') return Op::LessEq;
    if (c == '>' && n == '=') return Op::GreaterEq;
    if (c == '&' && n == '&') return Op::AndAnd;
    if (c == '|' && n == '|' && !abs_bars) return Op::OrOr;
    len = 1;
    switch (c) {
        case '+':
            return Op::Plus;
        case '-':
            return Op::Minus;
        case '*':
            return Op::Star;
        case '/':
            return Op::Slash;
        case '^':
            return Op::Caret;
        case '!':
            return Op::Not;
        case '=':
            return Op::Assign;
        case '<':
            return Op::Less;
        case '>':
            return Op::Greater;
        case '|':
            return abs_bars ? Op::Bar : Op::None;
        case '(':
            return Op::LParen;
        case ')':
            return Op::RParen;
        case '[':
            return Op::LBracket;
        case ']':
            return Op::RBracket;
        case ',':
            return Op::Comma;
        default:
            return Op::None;
    }
}

// A '(' opens a sub-expression when it follows something that needs an operand or an argument
// list; anywhere else it opens a comment (CAM output writes "(…)" comments).
bool paren_is_expression(const Token* previous, int depth, bool expression_start) {
    if (depth > 0) return true;
    if (previous == nullptr) return expression_start;
    const Token& prev = *previous;
    if (prev.kind == Tok::Word) return prev.text.size() > 1;
    if (prev.kind == Tok::Op)
        return prev.op != Op::RParen && prev.op != Op::RBracket && prev.op != Op::Bar;
    return false;
}

// Whether the executable text of the line ends at s[i], a byte that is neither a space, a letter
// nor a digit: at ';', at a ' comment, or on a '%' tape-marker line.
bool ends_executable_text(std::string_view s, std::size_t i, bool line_start, const Dialect& d) {
    const char c = s[i];
    if (c == ';') return true;
    // EXT: a '%' line (tape start/end marker in CAM output) carries nothing.
    if (c == '%' && line_start && s.find_first_not_of(" \t%", i) == std::string_view::npos)
        return true;
    // Comment quotes are ' and a UTF-8 sequence starting 0xE2: test the byte first.
    return d.quote_comments && (c == '\'' || c == '\xE2') && comment_quote_length(s.substr(i)) != 0;
}

std::string describe_byte(char c) {
    const auto u = static_cast<unsigned char>(c);
    if (u >= 0x20 && u < 0x7F) return std::string("unexpected character '") + c + "'";
    char buf[64];
    std::snprintf(buf, sizeof buf, "unexpected byte 0x%02X", u);
    return std::string(buf) +
           (u >= 0x80 ? " (non-ASCII text belongs in a ' comment or a string)" : "");
}

}  // namespace

bool Lexer::lex_plain(std::string_view s, PlainLine& out) const {
    out.count = 0;
    const char* const begin = s.data();
    const char* const end = begin + s.size();
    const char* p = begin;
    for (;;) {
        while (p != end && char_class(*p) == CharClass::Space) ++p;
        if (p == end) return true;
        // A word starts with one letter; 'O' (labels) and 'P' (P"name") have forms of their own.
        const char letter = *p;
        if (char_class(letter) != CharClass::Letter || to_upper(letter) == 'O') return false;
        const int col = static_cast<int>(p - begin) + 1;
        ++p;
        while (p != end && char_class(*p) == CharClass::Space) ++p;
        if (p == end) return false;
        double sign = 1.0;
        bool has_sign = false;
        if (*p == '-' || *p == '+') {
            has_sign = true;
            sign = *p == '-' ? -1.0 : 1.0;
            ++p;
            if (p == end) return false;
        }
        // A literal follows at once: a letter run ("GX"), '=', a space after the sign, … are the
        // general path's (keywords, expressions, errors).
        if (!is_digit(*p) && !(*p == '.' && p + 1 != end && is_digit(p[1]))) return false;
        // scan_number's fast case, inline; longer literals are left to it (general path).
        std::uint64_t mantissa = 0;
        const char* const digits_start = p;
        p = scan_digits(p, end, mantissa);
        int frac_digits = 0;
        const bool has_point = p != end && *p == '.';
        if (has_point) {
            const char* const frac = p + 1;
            p = scan_digits(frac, end, mantissa);
            frac_digits = static_cast<int>(p - frac);
        }
        if (p - digits_start - (has_point ? 1 : 0) > 15 || out.count == PlainLine::kMaxWords)
            return false;
        const double number = frac_digits == 0
                                  ? static_cast<double>(mantissa)
                                  : static_cast<double>(mantissa) / kPow10[frac_digits];
        PlainWord& w = out.words[static_cast<std::size_t>(out.count++)];
        w.letter = letter;
        w.col = col;
        w.integer_literal = !has_point;
        // As the block parser computes a signed literal, so both paths give the same bits.
        w.value = has_sign ? sign * number : number;
    }
}

void Lexer::lex(std::string_view s, const SourceLoc& loc, std::vector<Token>& out,
                bool expression_start) const {
    out.clear();
    // A line never has more tokens than bytes + End; capped so a huge line cannot ask for
    // gigabytes up front (the vector still grows if it must).
    out.reserve(std::min<std::size_t>(s.size() + 1, 1024));
    const Dialect& d = *dialect_;
    std::size_t i = 0;
    int depth = 0;
    bool space = false;
    // Columns count characters (UTF-8 code points), not bytes: `cont` is the number of UTF-8
    // continuation bytes before i. Non-ASCII text can only be skipped inside a ( ) comment or a
    // string, so only those two places count them, and ASCII lines pay nothing.
    int cont = 0;
    auto count_cont = [&](std::size_t from, std::size_t to) {
        for (std::size_t k = from; k < to && k < s.size(); ++k)
            cont += (static_cast<unsigned char>(s[k]) & 0xC0) == 0x80;
    };
    auto error = [&](std::size_t at, const std::string& msg) {
        throw Error(SourceLoc{loc.file, loc.line, static_cast<int>(at) + 1 - cont}, msg);
    };
    while (i < s.size()) {
        const char c = s[i];
        const CharClass cls = char_class(c);
        if (cls == CharClass::Space) {
            space = true;
            ++i;
            continue;
        }
        if (cls == CharClass::Other && ends_executable_text(s, i, out.empty(), d)) break;
        // Built in place: copying a finished Token into the vector stalls on store forwarding.
        Token& tok = out.emplace_back();
        tok.col = static_cast<int>(i) + 1 - cont;
        tok.space_before = space;
        space = false;
        if (cls == CharClass::Letter) {
            std::size_t j = i + 1;
            while (j < s.size() && char_class(s[j]) == CharClass::Letter) ++j;
            tok.kind = Tok::Word;
            tok.text = std::string_view(s.data() + i, j - i);
            i = j;
        } else if (cls == CharClass::Digit ||
                   (c == '.' && i + 1 < s.size() && is_digit(s[i + 1]))) {
            i = scan_number(s, i, tok);
            if (!std::isfinite(tok.number)) error(i - tok.text.size(), "number out of range");
        } else if (c == '#') {
            std::size_t j = i + 1;
            if (j < s.size() && is_digit(s[j])) {
                while (j < s.size() && is_digit(s[j])) ++j;
            } else if (j < s.size() && (is_alpha(s[j]) || s[j] == '_')) {
                while (j < s.size() && (is_alpha(s[j]) || is_digit(s[j]) || s[j] == '_')) ++j;
                // Axis suffix ".X"; S0 §4.1.1 prints "#CTP_POS. X", so a space may follow the dot.
                if (j < s.size() && s[j] == '.') {
                    std::size_t k = j + 1;
                    while (d.tolerant_expr_spaces && k < s.size() && is_space(s[k])) ++k;
                    if (k < s.size() && is_alpha(s[k])) {
                        j = k;
                        while (j < s.size() && is_alpha(s[j])) ++j;
                    }
                }
            } else {
                error(i, "expected a variable number or parameter name after '#'");
            }
            tok.kind = Tok::Var;
            tok.text = s.substr(i + 1, j - i - 1);
            i = j;
        } else if (const std::size_t q = quote_length(s.substr(i)); q != 0) {
            std::size_t j = i + q;
            while (j < s.size() && quote_length(s.substr(j)) == 0) ++j;
            if (j >= s.size()) error(i, "unterminated string (missing closing quote)");
            tok.kind = Tok::String;
            tok.text = s.substr(i + q, j - i - q);
            const std::size_t start = i;
            i = j + quote_length(s.substr(j));
            count_cont(start, i);
        } else if (c == '(' &&
                   !paren_is_expression(out.size() >= 2 ? &out[out.size() - 2] : nullptr, depth,
                                        expression_start)) {
            out.pop_back();  // not a token: a comment
            if (!d.paren_comments) error(i, "'(' comments are not allowed in this dialect");
            int nest = 0;
            std::size_t j = i;
            for (; j < s.size(); ++j) {
                if (s[j] == '(' && (nest == 0 || d.nested_paren_comments)) ++nest;
                if (s[j] == ')' && --nest == 0) break;
            }
            if (j >= s.size()) error(i, "unclosed '(' comment");
            count_cont(i, j + 1);
            i = j + 1;
            space = true;
            continue;
        } else {
            std::size_t len = 0;
            const Op op = scan_op(s, i, d.abs_bars, len);
            if (op == Op::None) error(i, describe_byte(c));
            if (op == Op::LParen) ++depth;
            if (op == Op::RParen && depth > 0) --depth;
            tok.kind = Tok::Op;
            tok.op = op;
            tok.text = s.substr(i, len);
            i += len;
        }
    }
    Token& end = out.emplace_back();
    end.col = static_cast<int>(i) + 1 - cont;
    end.space_before = true;
}

}  // namespace interp
