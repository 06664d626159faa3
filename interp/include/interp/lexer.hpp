#pragma once
// Splits one line into tokens. Tokens are views into the line: lexing allocates nothing once the
// caller's token buffer has grown to the longest line seen.
//
// The lexer knows just enough context to tell a '(' that opens a sub-expression (after '=', an
// operator, a function name or IF) from one that opens a comment, and to stop at ';' or a '
// comment. Letter runs are kept whole ("G", "ABS", "PLC"); the block parser decides whether a
// run is an address letter, a keyword or a function name.
#include <array>
#include <cstdint>
#include <string_view>
#include <vector>

#include "interp/block.hpp"
#include "interp/dialect.hpp"

namespace interp {

enum class Tok : std::uint8_t {
    End,     // end of the executable text of the line
    Word,    // run of ASCII letters: address letter, keyword or function name
    Number,  // unsigned literal: 12, 0., .8, 3.25
    Var,     // #1, #FC13, #CURMACHPOS.X — text holds what follows '#'
    String,  // "text" (quotes excluded)
    Op,      // operator or punctuation, see Op
};

enum class Op : std::uint8_t {
    None,
    Plus,
    Minus,
    Star,
    Slash,
    Caret,
    Not,        // !
    Assign,     // =
    EqEq,       // ==
    NotEq,      // !=
    Less,       // <
    Greater,    // >
    LessEq,     // <=
    GreaterEq,  // >=
    AndAnd,     // &&
    OrOr,       // ||
    Bar,        // | (V5.4 absolute-value bars)
    LParen,
    RParen,
    LBracket,
    RBracket,
    Comma,
};

struct Token {
    Tok kind = Tok::End;
    Op op = Op::None;
    bool space_before = false;  // whitespace separates this token from the previous one
    bool has_point = false;     // Number written with a decimal point
    int col = 0;                // 1-based column in characters (UTF-8 code points)
    std::string_view text;      // the token's characters (without quotes for String, '#' for Var)
    double number = 0.0;        // value of a Number
};

// One address word of a plain line (see Lexer::lex_plain): the letter as written, its column,
// the value with its sign applied, and whether the literal had no decimal point.
struct PlainWord {
    char letter = 0;
    bool integer_literal = false;
    int col = 0;
    double value = 0.0;
};

// The words of a plain line, in written order.
struct PlainLine {
    static constexpr int kMaxWords = 32;
    std::array<PlainWord, kMaxWords> words;
    int count = 0;
};

// Display form of an operator, for messages.
std::string_view op_text(Op op);

class Lexer {
  public:
    explicit Lexer(const Dialect& dialect) : dialect_(&dialect) {}

    // Lexes `line` into `out` (cleared first; the last token is always Tok::End). `loc` gives
    // the file and line for errors; its column is ignored. With `expression_start` the text is
    // lexed as if it followed '=' (a leading '(' opens a sub-expression, not a comment).
    void lex(std::string_view line, const SourceLoc& loc, std::vector<Token>& out,
             bool expression_start = false) const;

    // The fast path for the lines CAM output is made of: only address words, each a single
    // letter and a literal with an optional sign ("G3 Y0 I-10 J0"), separated by
    // spaces or nothing. Fills `out` and returns true for such a line; returns false (leaving
    // `out` unspecified) for anything else — comments, expressions, keywords, a sign apart from
    // its number, any byte it does not expect — which then goes through lex() and the block
    // parser's general path. It never throws: the general path reports every error, so both
    // paths must agree on every line lex_plain accepts (tests/interp_front/test_plain_line.cpp
    // checks that on random lines).
    bool lex_plain(std::string_view line, PlainLine& out) const;

  private:
    const Dialect* dialect_;
};

}  // namespace interp
