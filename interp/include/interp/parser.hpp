#pragma once
// The block parser: one line of tokens -> one Block with every value evaluated, plus what the
// control-flow layer needs (an O label, a P"name", whether IF or '/' skipped the block).
// Variable assignments (#1=…, #FC50=…) are performed here, in written order, through Variables'
// undo log; the caller brackets each line with Variables::begin()/commit()/rollback().
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "interp/block.hpp"
#include "interp/dialect.hpp"
#include "interp/expr.hpp"
#include "interp/lexer.hpp"
#include "interp/variables.hpp"

namespace interp {

struct ParsedLine {
    Block block;
    // A subprogram label line: O1234 or O"name" (nothing else may stand on it).
    bool is_label = false;
    std::int64_t label_number = -1;  // -1 for a named label
    std::string label_name;
    // G65 P"name" / M98 P"name"
    std::optional<std::string> p_name;
    int p_name_col = 0;
    bool block_delete = false;  // the line starts with '/'
    bool if_false = false;      // an IF(…) in the line was false: the words after it are dropped
    std::uint32_t letters_set = 0;  // letters the parser stored in block.words (for reset)

    void reset();
};

class BlockParser {
  public:
    BlockParser(const Dialect& dialect, Variables& vars, MachineQuery& machine)
        : dialect_(&dialect), lexer_(dialect), vars_(vars), machine_(machine) {}

    void set_dialect(const Dialect& dialect) {
        dialect_ = &dialect;
        lexer_ = Lexer(dialect);
    }

    // Throws Error (file:line:col) on any syntax or evaluation error. `out` is reset first.
    // A line of plain address words (Lexer::lex_plain) skips the tokens and the token walk; it
    // gets the same block and the same errors as through the general path.
    void parse(std::string_view line, const SourceLoc& loc, ParsedLine& out);

  private:
    struct Ctx;
    void parse_word(Ctx& c);
    void parse_letter(Ctx& c, const Token& letter);
    void parse_keyword(Ctx& c, const Token& word);
    void parse_assignment(Ctx& c, const Token& var);
    double parse_value(Ctx& c, const Token& address, bool* integer_literal);
    double parse_signed_or_expression(Ctx& c, const Token& address, bool* integer_literal);
    int parse_plc_address(Ctx& c, const Token& keyword);

    const Dialect* dialect_;
    Lexer lexer_;
    Variables& vars_;
    MachineQuery& machine_;
    std::vector<Token> tokens_;
    PlainLine plain_;  // the words of a line lex_plain accepted
};

}  // namespace interp
