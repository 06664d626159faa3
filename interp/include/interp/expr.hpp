#pragma once
// The expression evaluator: NcStudio "assignment expressions" (S0 §3.11, S1 §3.5). It parses
// and evaluates in one pass over the lexer's tokens with precedence climbing driven by the
// dialect's operator table, so there is no syntax tree and nothing is allocated.
//
// An expression ends at the first token that cannot continue it. Spaces: at the outermost level
// a space after a complete operand ends the expression unless the next token is a binary
// operator; inside parentheses and after an operator or function name spaces are skipped. With
// Dialect::tolerant_expr_spaces off every space inside an expression is an error instead (the
// manual's literal rule, EXP-02), and a space at the outermost level ends it.
#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

#include "interp/block.hpp"
#include "interp/dialect.hpp"
#include "interp/lexer.hpp"
#include "interp/variables.hpp"

namespace interp {

// A read position in a lexed line.
struct TokenCursor {
    const std::vector<Token>* tokens = nullptr;
    std::size_t pos = 0;
    // The lexer ends every line's tokens with one Tok::End and the cursor never moves past it,
    // so the current token needs no bounds check.
    const Token& peek() const { return (*tokens)[pos]; }
    const Token& peek(std::size_t ahead) const {
        const std::size_t i = pos + ahead;
        return i < tokens->size() ? (*tokens)[i] : tokens->back();
    }
    const Token& next() {
        const Token& t = peek();
        if (t.kind != Tok::End) ++pos;
        return t;
    }
    bool at_end() const { return peek().kind == Tok::End; }
};

// What a '#' operand refers to, resolved from its text.
struct VarRef {
    enum class Kind { Numbered, FixedCycle, Named } kind = Kind::Numbered;
    int index = 0;          // n of #n or #FCn
    std::string_view text;  // as written, for messages
};

class ExprEvaluator {
  public:
    // `file` and `line` locate errors; columns come from the tokens.
    ExprEvaluator(const Dialect& dialect, Variables& vars, MachineQuery& machine,
                  std::string_view file, int line)
        : d_(dialect), vars_(vars), machine_(machine), file_(file), line_(line) {}

    // Evaluates the expression at the cursor and leaves the cursor after it. With `dry` set the
    // syntax is checked but nothing is read from variables or the machine and no domain error
    // is raised (used for the rest of a block whose IF condition is false); the result is 0.
    double evaluate(TokenCursor& cur, bool dry = false);

    // Resolves the text after '#' (numbered, #FCn, named). Throws Error for unknown names.
    VarRef resolve(const Token& var) const;
    double read(const Token& var);

    SourceLoc loc(const Token& t) const { return SourceLoc{file_, line_, t.col}; }

  private:
    double parse_binary(TokenCursor& cur, int min_level);
    double parse_unary(TokenCursor& cur);
    double parse_primary(TokenCursor& cur);
    double call_function(const Token& name, TokenCursor& cur);
    const BinOpRule* binary_rule(const Token& t) const;
    // Operand expected here: a space before it is allowed only in tolerant mode.
    void check_operand_space(const Token& t) const;
    double checked(double v, const Token& at, const char* what) const;

    const Dialect& d_;
    Variables& vars_;
    MachineQuery& machine_;
    std::string_view file_;
    int line_;
    static constexpr int kMaxNesting = 256;
    int depth_ = 0;    // open parentheses / abs bars
    int nesting_ = 0;  // recursion depth of parse_binary
    bool dry_ = false;
};

// Rounds a value used where an integer is needed (L counts, ports, addresses; EXP-11). Throws
// Error at `loc` when it is more than 1e-6 away from an integer or outside int range.
std::int64_t to_integer(double v, const SourceLoc& loc, std::string_view what);

}  // namespace interp
