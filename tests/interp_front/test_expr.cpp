#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "fakes.hpp"
#include "interp/expr.hpp"

using namespace interp;

namespace {

struct ExprFixture : ::testing::Test {
    Variables vars;
    test::FakeMachine machine;
    std::vector<Token> tokens;

    // Evaluates `text`; `rest` receives the column where evaluation stopped (0 at the end).
    double eval(std::string_view text, const Dialect& d = ncstudio_dialect(), int* rest = nullptr) {
        Lexer(d).lex(text, SourceLoc{"e.nc", 3, 0}, tokens, true);
        TokenCursor cur{&tokens, 0};
        ExprEvaluator ev(d, vars, machine, "e.nc", 3);
        const double v = ev.evaluate(cur);
        if (rest != nullptr)
            *rest = cur.at_end() ? 0 : cur.peek().col;
        else
            EXPECT_TRUE(cur.at_end()) << "unparsed text after expression in: " << text;
        return v;
    }
    std::string error(std::string_view text, const Dialect& d = ncstudio_dialect()) {
        try {
            int rest = 0;
            eval(text, d, &rest);
        } catch (const Error& e) {
            return e.what();
        }
        return "no error";
    }
};

}  // namespace

// Precedence of S0 §3.11.2 (EXP-05), each value worked out by hand.
TEST_F(ExprFixture, ArithmeticPrecedenceAndAssociativity) {
    EXPECT_EQ(eval("2+3*4"), 14.0);
    EXPECT_EQ(eval("(2+3)*4"), 20.0);
    EXPECT_EQ(eval("10-4-3"), 3.0);  // left-associative, not 10-(4-3)=9
    EXPECT_EQ(eval("24/4/2"), 3.0);  // left-associative, not 24/(4/2)=12
    EXPECT_EQ(eval("-2*3"), -6.0);
    EXPECT_EQ(eval("--2"), 2.0);
    EXPECT_EQ(eval("+5-+2"), 3.0);
    EXPECT_EQ(eval("7.5/2.5+1"), 4.0);
}

TEST_F(ExprFixture, ComparisonAndLogicPrecedence) {
    EXPECT_EQ(eval("1+2==3"), 1.0);  // + binds tighter than ==
    EXPECT_EQ(eval("2<1+2"), 1.0);
    EXPECT_EQ(eval("1+2>2"), 1.0);
    EXPECT_EQ(eval("3>2==1"), 1.0);  // one level, left to right: (3>2)==1
    EXPECT_EQ(eval("2!=2"), 0.0);
    EXPECT_EQ(eval("0.1+0.2==0.3"), 1.0);  // comparisons tolerate rounding (1e-9)
    // || and && share level 1 in S0's table: evaluated left to right.
    EXPECT_EQ(eval("1||0&&0"), 0.0);  // (1||0)&&0; C precedence would give 1
    EXPECT_EQ(eval("0&&1||1"), 1.0);
    EXPECT_EQ(eval("!0+1"), 2.0);  // unary ! binds tighter than +
    EXPECT_EQ(eval("!(0+1)"), 0.0);
    EXPECT_EQ(eval("!5"), 0.0);
    EXPECT_EQ(eval("2>=2"), 1.0);
    EXPECT_EQ(eval("3<=2"), 0.0);
}

// cfg:expr_c_logic: && binds tighter than ||, everything else as in S0.
TEST_F(ExprFixture, CLogicPrecedenceVariant) {
    const Dialect& d = ncstudio_c_logic_dialect();
    EXPECT_EQ(eval("1||0&&0", d), 1.0);  // 1||(0&&0)
    EXPECT_EQ(eval("0&&1||1", d), 1.0);
    EXPECT_EQ(eval("1+2==3&&!0", d), 1.0);
    EXPECT_EQ(eval("2+3*4", d), 14.0);
    EXPECT_EQ(eval("-2*3", d), -6.0);
    EXPECT_EQ(find_dialect("ncstudio-c-logic"), &d);
    EXPECT_EQ(find_dialect("iso"), nullptr);
}

// The manual's own examples (EX-17).
TEST_F(ExprFixture, ManualExamples) {
    EXPECT_NEAR(eval("5+sin(5+abs(-8))"), 5.420167037, 1e-9);  // 5 + sin(13 rad)
    EXPECT_NEAR(eval("4+log6"), 5.791759469, 1e-9);            // 4 + ln 6, no parentheses
    EXPECT_EQ(eval("1+2"), 3.0);
}

// Every function of S0 §3.11.2, radians, against hand-checked values.
TEST_F(ExprFixture, Functions) {
    EXPECT_NEAR(eval("sin(0.5)"), 0.479425538604203, 1e-15);
    EXPECT_NEAR(eval("cos(0.5)"), 0.877582561890373, 1e-15);
    EXPECT_NEAR(eval("tg(0.5)"), 0.546302489843790, 1e-15);
    EXPECT_NEAR(eval("ctg(0.5)"), 1.830487721712452, 1e-14);
    EXPECT_NEAR(eval("asin(0.5)"), M_PI / 6, 1e-15);
    EXPECT_NEAR(eval("acos(0.5)"), M_PI / 3, 1e-15);
    EXPECT_NEAR(eval("atg(1)"), M_PI / 4, 1e-15);
    EXPECT_NEAR(eval("exp(1)"), 2.718281828459045, 1e-15);
    EXPECT_NEAR(eval("sqrt(2)"), 1.414213562373095, 1e-15);
    EXPECT_NEAR(eval("log(10)"), 2.302585092994046, 1e-15);
    EXPECT_EQ(eval("int(2.7)"), 2.0);
    EXPECT_EQ(eval("int(-2.5)"), -3.0);  // rounds down, not toward zero
    EXPECT_EQ(eval("int(-3)"), -3.0);
    EXPECT_EQ(eval("abs(-3.5)"), 3.5);
    EXPECT_EQ(eval("ABS(-1)+Int(1.5)"), 2.0);                // case-insensitive names
    EXPECT_NEAR(eval("sin(3.14159265358979)"), 0.0, 1e-12);  // radians, not degrees
    EXPECT_EQ(eval("sqrt16*2"), 8.0);                        // bare-literal call binds before *
}

TEST_F(ExprFixture, VariablesAndNamedParameters) {
    vars.set_numbered(1, 30, {});
    vars.set_numbered(3, 4, {});
    vars.set_fixed_cycle(13, 1, {});
    machine.machine_mm = {10, 20, -5, 0, 0, 0};
    machine.settings["FIXEDCYCLE_BACK"] = 1.5;
    EXPECT_EQ(eval("-#1*#3"), -120.0);
    EXPECT_EQ(eval("!#FC13"), 0.0);
    EXPECT_EQ(eval("#FC7"), 0.0);  // fixed-cycle variables start at zero
    EXPECT_EQ(eval("#CURMACHPOS.Y+#curmachpos.z"), 15.0);
    EXPECT_EQ(eval("#FIXEDCYCLE_BACK*2"), 3.0);
}

// S0 §4.1.1 example 2 writes spaces inside an expression: tolerated by default.
TEST_F(ExprFixture, TolerantSpacesOfManualExample) {
    vars.set_fixed_cycle(4, 2, {});
    vars.set_fixed_cycle(3, -10, {});
    vars.set_fixed_cycle(5, 3, {});
    EXPECT_EQ(eval("INT(ABS(#FC4-#FC3) /ABS (#FC5)) -1"), 3.0);  // int(12/3)-1
}

TEST_F(ExprFixture, ExpressionEndsAtSpaceBeforeNextWord) {
    vars.set_numbered(2, 5, {});
    int rest = 0;
    EXPECT_EQ(eval("#2*2 Y=1", ncstudio_dialect(), &rest), 10.0);
    EXPECT_EQ(rest, 6);
    EXPECT_EQ(eval("1+2#1=4", ncstudio_dialect(), &rest), 3.0);
    EXPECT_EQ(rest, 4);
}

TEST_F(ExprFixture, StrictSpacesWhenToleranceIsOff) {
    Dialect strict = ncstudio_dialect();
    strict.tolerant_expr_spaces = false;
    int rest = 0;
    EXPECT_EQ(eval("1+2 -1", strict, &rest), 3.0);  // the space ends the expression
    EXPECT_EQ(rest, 5);
    EXPECT_EQ(error("ABS (1)", strict), "e.nc:3:5: spaces are not allowed inside an expression");
}

// V5.4 operator set (EXP-06 REC): ^ right-associative above unary minus, |x| bars.
TEST_F(ExprFixture, V54Operators) {
    const Dialect& d = ncstudio_v54_dialect();
    EXPECT_EQ(eval("-2^2", d), -4.0);
    EXPECT_EQ(eval("2^3^2", d), 512.0);  // 2^(3^2)
    EXPECT_EQ(eval("2*3^2", d), 18.0);
    EXPECT_EQ(eval("|-3|+1", d), 4.0);
    EXPECT_EQ(eval("|1-|2-5||", d), 2.0);  // nested bars: |1-3|
    EXPECT_EQ(eval("1+2>2", d), 1.0);      // comparisons below +, not above
    EXPECT_EQ(eval("!0", d), 1.0);
}

TEST_F(ExprFixture, ErrorDivisionByZero) {
    EXPECT_EQ(error("1/(2-2)"), "e.nc:3:2: division by zero");
}
TEST_F(ExprFixture, ErrorSqrtNegative) {
    EXPECT_EQ(error("sqrt(-4)"), "e.nc:3:1: sqrt: square root of a negative number (argument -4)");
}
TEST_F(ExprFixture, ErrorLogNotPositive) {
    EXPECT_EQ(error("2+log(0)"),
              "e.nc:3:3: log: logarithm of a number that is not positive (argument 0)");
}
TEST_F(ExprFixture, ErrorAsinAcosDomain) {
    EXPECT_EQ(error("asin(2)"), "e.nc:3:1: asin: argument outside [-1, 1] (argument 2)");
    EXPECT_EQ(error("acos(-1.5)"), "e.nc:3:1: acos: argument outside [-1, 1] (argument -1.5)");
}
TEST_F(ExprFixture, ErrorCtgZero) {
    EXPECT_EQ(error("ctg(0)"), "e.nc:3:1: ctg: cotangent is undefined (argument 0)");
}
TEST_F(ExprFixture, ErrorExpOverflow) {
    EXPECT_EQ(error("exp(1000)"), "e.nc:3:1: exp gives a value that is not a finite number");
}
TEST_F(ExprFixture, ErrorUnknownFunction) {
    EXPECT_EQ(error("foo(1)"), "e.nc:3:1: unknown function 'foo'");
}
TEST_F(ExprFixture, ErrorFunctionWithoutArgument) {
    EXPECT_EQ(error("sin+1"), "e.nc:3:4: function 'sin' needs an argument");
}
TEST_F(ExprFixture, ErrorMissingCloseParen) {
    EXPECT_EQ(error("(1+2"), "e.nc:3:5: expected ')' in expression");
}
TEST_F(ExprFixture, ErrorIncompleteExpression) {
    EXPECT_EQ(error("1+"), "e.nc:3:3: expression is incomplete at end of block");
}
TEST_F(ExprFixture, ErrorUnexpectedToken) {
    EXPECT_EQ(error("1+)"), "e.nc:3:3: unexpected ')' in expression");
}
TEST_F(ExprFixture, ErrorOperatorNotInDialect) {
    EXPECT_EQ(error("2^2"), "e.nc:3:2: operator '^' is not available in dialect ncstudio");
    EXPECT_EQ(error("1==1", ncstudio_v54_dialect()),
              "e.nc:3:2: operator '==' is not available in dialect ncstudio-v54");
}
TEST_F(ExprFixture, ErrorNestedTooDeeply) {
    EXPECT_EQ(error(std::string(300, '(') + "1" + std::string(300, ')')),
              "e.nc:3:257: expression nested too deeply (more than 256 levels)");
    EXPECT_EQ(error(std::string(100000, '-') + "1"),
              "e.nc:3:257: expression nested too deeply (more than 256 levels)");
    EXPECT_EQ(eval(std::string(200, '(') + "1" + std::string(200, ')')), 1.0);
}
TEST_F(ExprFixture, ErrorUnsetVariable) {
    EXPECT_EQ(error("#7+1"), "e.nc:3:1: variable #7 is used before it is set");
}
TEST_F(ExprFixture, ErrorVariableOutOfRange) {
    EXPECT_EQ(error("#1000"), "e.nc:3:1: variable #1000 is out of range (#1…#999)");
    EXPECT_EQ(error("#FC51"), "e.nc:3:1: fixed-cycle variable #FC51 is out of range (#FC1…#FC50)");
}
TEST_F(ExprFixture, ErrorUnknownNamedParameter) {
    EXPECT_EQ(error("#NOSUCH.X"), "e.nc:3:1: unknown named parameter #NOSUCH.X");
}
TEST_F(ExprFixture, ErrorUnconfiguredSetting) {
    EXPECT_EQ(error("#SAFEHEIGHT"),
              "e.nc:3:1: named parameter #SAFEHEIGHT is not configured on this machine");
}

// The per-block undo log: every write of a rejected block is undone, newest first, including
// "was never set".
TEST(Variables, RollbackRestoresValuesAndUnsetState) {
    Variables v;
    v.set_numbered(1, 10, {});
    v.set_fixed_cycle(5, 3, {});
    v.begin();
    v.set_numbered(1, 20, {});
    v.set_numbered(1, 30, {});
    v.set_numbered(2, 40, {});
    v.set_fixed_cycle(5, 9, {});
    v.rollback();
    EXPECT_EQ(*v.numbered_if_set(1), 10.0);
    EXPECT_FALSE(v.numbered_if_set(2));
    EXPECT_EQ(v.fixed_cycle(5, {}), 3.0);
    v.begin();
    v.set_numbered(2, 7, {});
    v.commit();
    v.rollback();  // nothing left to undo after a commit
    EXPECT_EQ(*v.numbered_if_set(2), 7.0);
    v.clear();
    EXPECT_FALSE(v.numbered_if_set(1));
    EXPECT_EQ(v.fixed_cycle(5, {}), 0.0);
}

TEST(ToInteger, RoundsNearAndRejectsFractions) {
    EXPECT_EQ(to_integer(2.9999999, {}, "L"), 3);
    EXPECT_EQ(to_integer(-4.0000001, {}, "L"), -4);
    try {
        to_integer(2.5, SourceLoc{"f", 1, 2}, "repeat count L");
        FAIL();
    } catch (const Error& e) {
        EXPECT_STREQ(e.what(), "f:1:2: repeat count L must be an integer, got 2.5");
    }
    try {
        to_integer(1e300, SourceLoc{"f", 1, 2}, "PLC address");
        FAIL();
    } catch (const Error& e) {
        EXPECT_STREQ(e.what(), "f:1:2: PLC address is out of range");
    }
}
