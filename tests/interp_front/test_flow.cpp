#include <gtest/gtest.h>

#include <string>

#include "fakes.hpp"
#include "interp/flow.hpp"

using namespace interp;

namespace {

struct FlowFixture : ::testing::Test {
    Variables vars;
    test::FakeMachine machine;
    ParsedLine line;

    FlowWords take(std::string_view text) {
        BlockParser p(ncstudio_dialect(), vars, machine);
        p.parse(text, SourceLoc{"f.nc", 4, 1}, line);
        return take_flow_words(line, ncstudio_dialect());
    }
    std::string error(std::string_view text) {
        try {
            take(text);
        } catch (const Error& e) {
            return e.what();
        }
        return "no error";
    }
};

}  // namespace

TEST_F(FlowFixture, G65TakesPAndL) {
    const FlowWords f = take("G91 G65 P786 L6");
    ASSERT_TRUE(f.call);
    EXPECT_EQ(f.call->program, 786);
    EXPECT_EQ(f.call->count, 6);
    EXPECT_EQ(f.call->loc.col, 5);
    EXPECT_FALSE(f.ret);
    // What is left for the executor: just G91.
    ASSERT_EQ(line.block.g.size(), 1u);
    EXPECT_EQ(line.block.g[0], 910);
    EXPECT_FALSE(line.block.has('P'));
    EXPECT_FALSE(line.block.has('L'));
}

TEST_F(FlowFixture, G65DefaultsToOneRunAndTakesNames) {
    EXPECT_EQ(take("G65 P9002").call->count, 1);
    const FlowWords f = take("G65 P\"frame\" L=1+1");
    EXPECT_EQ(*f.call->name, "frame");
    EXPECT_EQ(f.call->count, 2);
    EXPECT_EQ(take("G65 P5 L0").call->count, 0);
}

// FEATURES M98-1/C-06/SUB-1: M98 P n L k is G65; 5-8 digits without L are count+program.
TEST_F(FlowFixture, M98Formats) {
    FlowWords f = take("M98 P21");
    EXPECT_EQ(f.call->program, 21);
    EXPECT_EQ(f.call->count, 1);
    f = take("M98 P30021");
    EXPECT_EQ(f.call->program, 21);
    EXPECT_EQ(f.call->count, 3);
    f = take("M98 P20012");
    EXPECT_EQ(f.call->program, 12);
    EXPECT_EQ(f.call->count, 2);
    f = take("M98 P123 L2");
    EXPECT_EQ(f.call->program, 123);
    EXPECT_EQ(f.call->count, 2);
    f = take("M98 P12345 L1");  // with L, P is the program number as written
    EXPECT_EQ(f.call->program, 12345);
    EXPECT_EQ(f.call->count, 1);
    EXPECT_TRUE(line.block.m.empty());
}

TEST_F(FlowFixture, ReturnWords) {
    FlowWords f = take("M17");
    ASSERT_TRUE(f.ret);
    EXPECT_EQ(f.ret->m, 17);
    EXPECT_FALSE(f.ret->sequence);
    f = take("G90 M99 P120");
    EXPECT_EQ(f.ret->m, 99);
    EXPECT_EQ(*f.ret->sequence, 120);
    EXPECT_FALSE(line.block.has('P'));
    EXPECT_EQ(line.block.g.size(), 1u);
    // M17 leaves P to other codes of the block (G04 P).
    f = take("G04 P5 M17");
    EXPECT_TRUE(line.block.has('P'));
}

TEST_F(FlowFixture, OrdinaryBlockHasNoFlow) {
    const FlowWords f = take("G1 X1 P3 M3");
    EXPECT_FALSE(f.call);
    EXPECT_FALSE(f.ret);
    EXPECT_TRUE(line.block.has('P'));
}

TEST_F(FlowFixture, ErrorG65WithoutP) {
    EXPECT_EQ(error("G65 L2"), "f.nc:4:1: G65 needs P (a program number or \"name\")");
}
TEST_F(FlowFixture, ErrorG65WithArguments) {
    EXPECT_EQ(error("G65 P1 X5"),
              "f.nc:4:8: G65 takes only P and L; X is not allowed in a G65 block");
}
TEST_F(FlowFixture, ErrorTwoCalls) {
    EXPECT_EQ(error("G65 P1 M98"),
              "f.nc:4:8: G65 and M98 in one block: only one subprogram call per block");
}
TEST_F(FlowFixture, ErrorM17AndM99) {
    EXPECT_EQ(error("M17 M99"), "f.nc:4:5: M17 and M99 in one block");
}
TEST_F(FlowFixture, ErrorCallAndReturn) {
    EXPECT_EQ(error("G65 P1 M17"),
              "f.nc:4:8: a block cannot both call a subprogram and return from one");
}
TEST_F(FlowFixture, ErrorNameWithoutCall) {
    EXPECT_EQ(error("G1 P\"x\""), "f.nc:4:4: P\"name\" is only meaningful with G65 or M98");
}
TEST_F(FlowFixture, ErrorBadRepeatCount) {
    EXPECT_EQ(error("G65 P1 L-1"), "f.nc:4:8: repeat count L must not be negative");
    EXPECT_EQ(error("G65 P1 L1.5"), "f.nc:4:8: repeat count L must be an integer, got 1.5");
}
TEST_F(FlowFixture, ErrorNegativeProgramNumber) {
    EXPECT_EQ(error("G65 P-1"), "f.nc:4:5: program number P must not be negative");
}
TEST_F(FlowFixture, ErrorM98Forms) {
    EXPECT_EQ(error("M98 L2"), "f.nc:4:1: M98 needs P (a program number)");
    EXPECT_EQ(error("M98 P123456789"), "f.nc:4:5: M98 P has more than 8 digits");
}
TEST_F(FlowFixture, ErrorM98NegativeWords) {
    EXPECT_EQ(error("M98 P-3"), "f.nc:4:5: M98 P must not be negative");
    EXPECT_EQ(error("M98 P3 L-1"), "f.nc:4:5: M98 L (repeat count) must not be negative");
}
TEST_F(FlowFixture, ErrorM99NegativeTarget) {
    EXPECT_EQ(error("M99 P-5"), "f.nc:4:5: M99 P must not be negative");
}
