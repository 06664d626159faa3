#include "interp/expr.hpp"

#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <string>

#include "interp/named_params.hpp"
#include "interp/text.hpp"

namespace interp {

namespace {

// Comparisons treat values within this distance as equal, so 0.1+0.2==0.3 holds.
constexpr double kEqualTolerance = 1e-9;

enum class Fn { Sin, Cos, Tg, Ctg, Asin, Acos, Atg, Exp, Sqrt, Log, Int, Abs };

struct FnEntry {
    std::string_view name;
    Fn fn;
};

// S0 §3.11.2 and S1 §3.5 (both editions have the same twelve functions).
constexpr FnEntry kFunctions[] = {
    {"SIN", Fn::Sin},   {"COS", Fn::Cos},   {"TG", Fn::Tg},   {"CTG", Fn::Ctg},
    {"ASIN", Fn::Asin}, {"ACOS", Fn::Acos}, {"ATG", Fn::Atg}, {"EXP", Fn::Exp},
    {"SQRT", Fn::Sqrt}, {"LOG", Fn::Log},   {"INT", Fn::Int}, {"ABS", Fn::Abs},
};

const FnEntry* find_function(std::string_view name) {
    for (const FnEntry& e : kFunctions)
        if (iequals(e.name, name)) return &e;
    return nullptr;
}

BinOp to_binop(Op op, bool& ok) {
    ok = true;
    switch (op) {
        case Op::OrOr:
            return BinOp::Or;
        case Op::AndAnd:
            return BinOp::And;
        case Op::EqEq:
            return BinOp::Eq;
        case Op::NotEq:
            return BinOp::Ne;
        case Op::Greater:
            return BinOp::Gt;
        case Op::Less:
            return BinOp::Lt;
        case Op::GreaterEq:
            return BinOp::Ge;
        case Op::LessEq:
            return BinOp::Le;
        case Op::Plus:
            return BinOp::Add;
        case Op::Minus:
            return BinOp::Sub;
        case Op::Star:
            return BinOp::Mul;
        case Op::Slash:
            return BinOp::Div;
        case Op::Caret:
            return BinOp::Pow;
        default:
            ok = false;
            return BinOp::Add;
    }
}

double truth(bool b) {
    return b ? 1.0 : 0.0;
}

}  // namespace

std::int64_t to_integer(double v, const SourceLoc& loc, std::string_view what) {
    const double r = std::nearbyint(v);
    if (!std::isfinite(v) || std::fabs(r) > 9.0e15) {
        throw Error(loc, std::string(what) + " is out of range");
    }
    if (std::fabs(v - r) > 1e-6) {
        throw Error(loc, std::string(what) + " must be an integer, got " + fmt::format("{}", v));
    }
    return static_cast<std::int64_t>(r);
}

VarRef ExprEvaluator::resolve(const Token& var) const {
    VarRef ref;
    ref.text = var.text;
    const std::string_view t = var.text;
    if (!t.empty() && is_digit(t[0])) {
        int n = 0;
        for (char c : t) {
            if (n > 1000000) break;
            n = n * 10 + (c - '0');
        }
        ref.kind = VarRef::Kind::Numbered;
        ref.index = n;
        return ref;
    }
    if (t.size() > 2 && iequals(t.substr(0, 2), "FC") && is_digit(t[2])) {
        int n = 0;
        std::size_t i = 2;
        for (; i < t.size() && is_digit(t[i]); ++i) {
            if (n > 1000000) break;
            n = n * 10 + (t[i] - '0');
        }
        if (i == t.size()) {
            ref.kind = VarRef::Kind::FixedCycle;
            ref.index = n;
            return ref;
        }
    }
    if (!find_named_param(t, d_)) {
        throw Error(loc(var), "unknown named parameter #" + std::string(t));
    }
    ref.kind = VarRef::Kind::Named;
    return ref;
}

double ExprEvaluator::read(const Token& var) {
    const VarRef ref = resolve(var);
    if (dry_) return 0.0;
    switch (ref.kind) {
        case VarRef::Kind::Numbered:
            return vars_.numbered(ref.index, loc(var));
        case VarRef::Kind::FixedCycle:
            return vars_.fixed_cycle(ref.index, loc(var));
        case VarRef::Kind::Named: {
            const auto p = find_named_param(ref.text, d_);
            // A value this block wrote is read back before it reaches the machine.
            if (auto v = vars_.pending_named(p->name))
                return p->length ? *v / machine_.mm_per_program_unit() : *v;
            return read_named_param(*p, machine_, loc(var));
        }
    }
    return 0.0;
}

double ExprEvaluator::evaluate(TokenCursor& cur, bool dry) {
    dry_ = dry;
    depth_ = 0;
    nesting_ = 0;
    return parse_binary(cur, 1);
}

const BinOpRule* ExprEvaluator::binary_rule(const Token& t) const {
    if (t.kind != Tok::Op) return nullptr;
    bool ok = false;
    const BinOp op = to_binop(t.op, ok);
    if (!ok) return nullptr;
    for (const BinOpRule& r : d_.binary_ops)
        if (r.op == op) return &r;
    return nullptr;
}

void ExprEvaluator::check_operand_space(const Token& t) const {
    if (t.space_before && !d_.tolerant_expr_spaces) {
        throw Error(loc(t), "spaces are not allowed inside an expression");
    }
}

double ExprEvaluator::checked(double v, const Token& at, const char* what) const {
    if (!dry_ && !std::isfinite(v)) {
        throw Error(loc(at), std::string(what) + " gives a value that is not a finite number");
    }
    return std::isfinite(v) ? v : 0.0;
}

double ExprEvaluator::parse_binary(TokenCursor& cur, int min_level) {
    // Bounded recursion: "((((…" or "----…1" must not overflow the stack.
    if (++nesting_ > kMaxNesting) {
        throw Error(loc(cur.peek()), "expression nested too deeply (more than " +
                                         std::to_string(kMaxNesting) + " levels)");
    }
    struct Leave {
        int& n;
        ~Leave() { --n; }
    } leave{nesting_};
    double lhs = parse_unary(cur);
    for (;;) {
        const Token& t = cur.peek();
        if (t.space_before && depth_ == 0 && !d_.tolerant_expr_spaces) return lhs;
        const BinOpRule* rule = binary_rule(t);
        if (rule == nullptr) {
            if (t.kind == Tok::Op && (t.op == Op::EqEq || t.op == Op::NotEq || t.op == Op::AndAnd ||
                                      t.op == Op::OrOr || t.op == Op::Caret)) {
                throw Error(loc(t), "operator '" + std::string(op_text(t.op)) +
                                        "' is not available in dialect " + std::string(d_.name));
            }
            return lhs;
        }
        if (t.space_before && depth_ > 0 && !d_.tolerant_expr_spaces) check_operand_space(t);
        if (rule->level < min_level) return lhs;
        const Token& op_tok = cur.next();
        const double rhs = parse_binary(cur, rule->right_assoc ? rule->level : rule->level + 1);
        switch (rule->op) {
            case BinOp::Or:
                lhs = truth(lhs != 0.0 || rhs != 0.0);
                break;
            case BinOp::And:
                lhs = truth(lhs != 0.0 && rhs != 0.0);
                break;
            case BinOp::Eq:
                lhs = truth(std::fabs(lhs - rhs) <= kEqualTolerance);
                break;
            case BinOp::Ne:
                lhs = truth(std::fabs(lhs - rhs) > kEqualTolerance);
                break;
            case BinOp::Gt:
                lhs = truth(lhs > rhs);
                break;
            case BinOp::Lt:
                lhs = truth(lhs < rhs);
                break;
            case BinOp::Ge:
                lhs = truth(lhs >= rhs);
                break;
            case BinOp::Le:
                lhs = truth(lhs <= rhs);
                break;
            case BinOp::Add:
                lhs = checked(lhs + rhs, op_tok, "addition");
                break;
            case BinOp::Sub:
                lhs = checked(lhs - rhs, op_tok, "subtraction");
                break;
            case BinOp::Mul:
                lhs = checked(lhs * rhs, op_tok, "multiplication");
                break;
            case BinOp::Div:
                if (rhs == 0.0 && !dry_) throw Error(loc(op_tok), "division by zero");
                lhs = rhs == 0.0 ? 0.0 : checked(lhs / rhs, op_tok, "division");
                break;
            case BinOp::Pow:
                lhs = checked(std::pow(lhs, rhs), op_tok, "power");
                break;
        }
    }
}

double ExprEvaluator::parse_unary(TokenCursor& cur) {
    const Token& t = cur.peek();
    if (t.kind == Tok::Op && (t.op == Op::Minus || t.op == Op::Plus || t.op == Op::Not)) {
        cur.next();
        check_operand_space(cur.peek());
        // The operand binds every operator tighter than the unary level (V5.4: -2^2 = -(2^2)).
        const double v = parse_binary(cur, d_.unary_level + 1);
        if (t.op == Op::Minus) return -v;
        if (t.op == Op::Not) return truth(v == 0.0);
        return v;
    }
    return parse_primary(cur);
}

double ExprEvaluator::parse_primary(TokenCursor& cur) {
    const Token& t = cur.next();
    switch (t.kind) {
        case Tok::Number:
            return t.number;
        case Tok::Var:
            return read(t);
        case Tok::Word:
            return call_function(t, cur);
        case Tok::Op:
            if (t.op == Op::LParen || (t.op == Op::Bar && d_.abs_bars)) {
                const Op close = t.op == Op::LParen ? Op::RParen : Op::Bar;
                ++depth_;
                check_operand_space(cur.peek());
                const double v = parse_binary(cur, 1);
                const Token& c = cur.peek();
                if (c.kind != Tok::Op || c.op != close) {
                    throw Error(loc(c), std::string("expected '") + std::string(op_text(close)) +
                                            "' in expression");
                }
                check_operand_space(c);
                cur.next();
                --depth_;
                return close == Op::Bar ? std::fabs(v) : v;
            }
            break;
        case Tok::End:
            throw Error(loc(t), "expression is incomplete at end of block");
        case Tok::String:
            break;
    }
    throw Error(loc(t), "unexpected '" + std::string(t.text) + "' in expression");
}

double ExprEvaluator::call_function(const Token& name, TokenCursor& cur) {
    const FnEntry* fn = find_function(name.text);
    if (fn == nullptr) throw Error(loc(name), "unknown function '" + std::string(name.text) + "'");
    const Token& a = cur.peek();
    check_operand_space(a);
    double x = 0.0;
    if (a.kind == Tok::Op && a.op == Op::LParen) {
        x = parse_primary(cur);
    } else if ((a.kind == Tok::Number || a.kind == Tok::Var) && !a.space_before) {
        // S0 §3.11.2 example 3: "log6" applies the function to a bare literal.
        x = parse_primary(cur);
    } else {
        throw Error(loc(a), "function '" + std::string(name.text) + "' needs an argument");
    }
    if (dry_) return 0.0;
    auto domain = [&](const char* why) {
        return Error(loc(name), std::string(name.text) + ": " + why + " (argument " +
                                    fmt::format("{}", x) + ")");
    };
    switch (fn->fn) {
        case Fn::Sin:
            return std::sin(x);
        case Fn::Cos:
            return std::cos(x);
        case Fn::Tg:
            return checked(std::tan(x), name, "tg");
        case Fn::Ctg: {
            const double tn = std::tan(x);
            if (tn == 0.0) throw domain("cotangent is undefined");
            return checked(1.0 / tn, name, "ctg");
        }
        case Fn::Asin:
            if (x < -1.0 || x > 1.0) throw domain("argument outside [-1, 1]");
            return std::asin(x);
        case Fn::Acos:
            if (x < -1.0 || x > 1.0) throw domain("argument outside [-1, 1]");
            return std::acos(x);
        case Fn::Atg:
            return std::atan(x);
        case Fn::Exp:
            return checked(std::exp(x), name, "exp");
        case Fn::Sqrt:
            if (x < 0.0) throw domain("square root of a negative number");
            return std::sqrt(x);
        case Fn::Log:
            if (x <= 0.0) throw domain("logarithm of a number that is not positive");
            return std::log(x);
        case Fn::Int:
            return std::floor(x);
        case Fn::Abs:
            return std::fabs(x);
    }
    return 0.0;
}

}  // namespace interp
