#include "interp/dialect.hpp"

#include <array>
#include <string>

namespace interp {

namespace {

// S0 §3.11.2: level 1 || && (one level, as printed), 2 comparisons, 3 + -, 4 * /, 5 unary.
// >= and <= are an extension (EXP-05 EXT).
constexpr std::array kNcStudioOps{
    BinOpRule{BinOp::Or, 1, false},  BinOpRule{BinOp::And, 1, false},
    BinOpRule{BinOp::Eq, 2, false},  BinOpRule{BinOp::Ne, 2, false},
    BinOpRule{BinOp::Gt, 2, false},  BinOpRule{BinOp::Lt, 2, false},
    BinOpRule{BinOp::Ge, 2, false},  BinOpRule{BinOp::Le, 2, false},
    BinOpRule{BinOp::Add, 3, false}, BinOpRule{BinOp::Sub, 3, false},
    BinOpRule{BinOp::Mul, 4, false}, BinOpRule{BinOp::Div, 4, false},
};

// cfg:expr_c_logic (EXP-05 REC): the same operators with C's order, && above ||.
constexpr std::array kNcStudioCLogicOps{
    BinOpRule{BinOp::Or, 1, false},  BinOpRule{BinOp::And, 2, false},
    BinOpRule{BinOp::Eq, 3, false},  BinOpRule{BinOp::Ne, 3, false},
    BinOpRule{BinOp::Gt, 3, false},  BinOpRule{BinOp::Lt, 3, false},
    BinOpRule{BinOp::Ge, 3, false},  BinOpRule{BinOp::Le, 3, false},
    BinOpRule{BinOp::Add, 4, false}, BinOpRule{BinOp::Sub, 4, false},
    BinOpRule{BinOp::Mul, 5, false}, BinOpRule{BinOp::Div, 5, false},
};

// S1 §3.5 lists + - / * / / ^ / > < / ! / unary - ( ) |x| / functions. Its numbering would make
// > bind tighter than +; EXP-06 REC uses the conventional order instead: comparisons loosest,
// then + -, * /, unary, and ^ (right-associative) tightest.
constexpr std::array kNcStudioV54Ops{
    BinOpRule{BinOp::Gt, 1, false},  BinOpRule{BinOp::Lt, 1, false},
    BinOpRule{BinOp::Ge, 1, false},  BinOpRule{BinOp::Le, 1, false},
    BinOpRule{BinOp::Add, 2, false}, BinOpRule{BinOp::Sub, 2, false},
    BinOpRule{BinOp::Mul, 3, false}, BinOpRule{BinOp::Div, 3, false},
    BinOpRule{BinOp::Pow, 5, true},
};

// S0 lists M98 without a format. FEATURES M98-1/C-06: M98 P<n> L<k> is G65 P<n> L<k>, and a 5–8
// digit P without L is the Fanuc count(4 digits)+program(4 digits) form (SUB-1).
CallSpec decode_m98_fanuc(std::int64_t p, std::optional<std::int64_t> l, const SourceLoc& loc) {
    if (p < 0) throw Error(loc, "M98 P must not be negative");
    if (l) {
        if (*l < 0) throw Error(loc, "M98 L (repeat count) must not be negative");
        return CallSpec{p, *l};
    }
    if (p > 99999999) throw Error(loc, "M98 P has more than 8 digits");
    if (p > 9999) {
        const std::int64_t count = p / 10000;
        return CallSpec{p % 10000, count};
    }
    return CallSpec{p, 1};
}

Dialect make_ncstudio() {
    Dialect d;
    d.name = "ncstudio";
    d.binary_ops = kNcStudioOps;
    d.unary_level = 5;
    d.decode_m98 = decode_m98_fanuc;
    return d;
}

Dialect make_ncstudio_v54() {
    Dialect d = make_ncstudio();
    d.name = "ncstudio-v54";
    d.abs_bars = true;
    d.binary_ops = kNcStudioV54Ops;
    d.unary_level = 4;
    d.v54_named_params = true;
    return d;
}

}  // namespace

const Dialect& ncstudio_dialect() {
    static const Dialect d = make_ncstudio();
    return d;
}

const Dialect& ncstudio_c_logic_dialect() {
    static const Dialect d = [] {
        Dialect c = make_ncstudio();
        c.name = "ncstudio-c-logic";
        c.binary_ops = kNcStudioCLogicOps;
        c.unary_level = 6;
        return c;
    }();
    return d;
}

const Dialect& ncstudio_v54_dialect() {
    static const Dialect d = make_ncstudio_v54();
    return d;
}

const Dialect* find_dialect(std::string_view name) {
    if (name == "ncstudio") return &ncstudio_dialect();
    if (name == "ncstudio-v54") return &ncstudio_v54_dialect();
    if (name == "ncstudio-c-logic") return &ncstudio_c_logic_dialect();
    return nullptr;
}

}  // namespace interp
