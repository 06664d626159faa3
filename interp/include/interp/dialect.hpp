#pragma once
// A dialect is data plus a few hooks: lexical switches, the operator table of the expression
// language, the accepted named-parameter sets, the control-flow codes and their number formats.
// The interpreter reads these; it has no `if (dialect == …)`. Adding ISO/Fanuc means adding one
// more table and, where a rule differs in shape rather than in data, one more hook function.
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

#include "interp/block.hpp"

namespace interp {

enum class BinOp : std::uint8_t { Or, And, Eq, Ne, Gt, Lt, Ge, Le, Add, Sub, Mul, Div, Pow };

// One binary operator of the expression language. Higher level binds tighter.
struct BinOpRule {
    BinOp op;
    int level;
    bool right_assoc;
};

// What an M98 (or G65) P/L pair means: which program, how many times.
struct CallSpec {
    std::int64_t program = 0;
    std::int64_t count = 1;
};

struct Dialect {
    std::string_view name;

    // Lexical rules.
    bool quote_comments = true;         // ' (and ’) starts a comment to end of line (LEX-30)
    bool paren_comments = true;         // ( … ) outside an expression is a comment (LEX-34)
    bool nested_paren_comments = true;  // "(a (b) c)" is one comment (LEX-31)
    bool abs_bars = false;              // |x| is absolute value (V5.4); otherwise || is OR
    bool tolerant_expr_spaces = true;   // spaces allowed where unambiguous (EXP-02 REC)

    // Expression language: binary operators and the level of unary + - !.
    std::span<const BinOpRule> binary_ops;
    int unary_level = 0;

    // Named parameters: the 6th-edition table and/or the V5.4 #SS… names.
    bool v6_named_params = true;
    bool v54_named_params = false;

    // Control flow.
    std::int64_t custom_m_base = 200;  // public.dat: M n runs O(base+n) (CUS-2)
    std::int64_t custom_g_base = 600;  // public.dat: G n runs O(base+n)
    int custom_code_max = 99;          // custom codes exist for n = 0 … max
    int max_call_depth = 64;           // nested calls beyond this are an error (SUB-5)
    int sub_end_m = 17;                // M17 ends a subprogram; M99 too (C-07)
    // Decodes M98's P (and optional L) into program and count. Throws Error at `loc` on a
    // malformed pair.
    CallSpec (*decode_m98)(std::int64_t p, std::optional<std::int64_t> l,
                           const SourceLoc& loc) = nullptr;
};

// NcStudio 6th edition (S0), the default.
const Dialect& ncstudio_dialect();
// NcStudio with the V5.4 (S1) differences (cfg:ncstudio_v54_compat).
const Dialect& ncstudio_v54_dialect();
// NcStudio with C's precedence for && and || (cfg:expr_c_logic, EXP-05 REC).
const Dialect& ncstudio_c_logic_dialect();
// By name: "ncstudio", "ncstudio-v54", "ncstudio-c-logic". nullptr when unknown.
const Dialect* find_dialect(std::string_view name);

}  // namespace interp
