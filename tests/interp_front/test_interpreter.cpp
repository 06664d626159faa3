#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <string>
#include <vector>

#include "fakes.hpp"
#include "interp/interpreter.hpp"

using namespace interp;

namespace {

struct InterpFixture : ::testing::Test {
    test::FakeMachine machine;
    test::RecordingExecutor exec;
    InterpreterOptions options;
    std::unique_ptr<Interpreter> interp;

    Interpreter& start(std::string text, bool with_library = false) {
        interp = std::make_unique<Interpreter>(exec, machine, options);
        if (with_library) interp->load_library(INTERP_FRONT_DATA_DIR "/public.dat");
        interp->open(Source::from_string("main.nc", std::move(text)));
        return *interp;
    }
    void run(std::string text, bool with_library = false) {
        start(std::move(text), with_library).run();
    }
    std::string run_error(std::string text, bool with_library = false) {
        try {
            run(std::move(text), with_library);
        } catch (const Error& e) {
            return e.what();
        }
        return "no error";
    }
    // Runs to the end like `cnc check`: every error is collected and interpretation continues.
    std::vector<std::string> check(std::string text) {
        std::vector<std::string> errors;
        Interpreter& in = start(std::move(text));
        for (int guard = 0; guard < 10000; ++guard) {
            try {
                if (!in.step()) break;
            } catch (const Error& e) {
                errors.push_back(e.what());
            }
        }
        return errors;
    }
    std::vector<std::string> files() const {
        std::vector<std::string> out;
        for (const Block& b : exec.blocks) out.emplace_back(b.loc.file);
        return out;
    }
};

struct WarningList : WarningSink {
    std::vector<std::string> text;
    void warning(const SourceLoc& loc, const std::string& t) override {
        text.push_back(std::string(loc.file) + ":" + std::to_string(loc.line) + ":" +
                       std::to_string(loc.col) + ": " + t);
    }
};

using Lines = std::vector<int>;
using Values = std::vector<double>;

}  // namespace

TEST_F(InterpFixture, RunsBlocksInOrderAndStopsAtM30) {
    run("G0 X1\n' comment\n\nG1 X2 F100\nM30\nG0 X99\n");
    EXPECT_EQ(exec.lines(), (Lines{1, 4, 5}));
    EXPECT_EQ(exec.values('X'), (Values{1, 2}));
    EXPECT_TRUE(exec.ends.empty());  // M30 is a normal end passed as a block
    EXPECT_TRUE(interp->finished());
    EXPECT_FALSE(interp->step());
}

TEST_F(InterpFixture, M02EndsTheProgram) {
    run("G0 X1\nM02\nG0 X2\n");
    EXPECT_EQ(exec.lines(), (Lines{1, 2}));
}

TEST_F(InterpFixture, EndOfFileWithoutM30CallsEndOfInput) {
    run("G0 X1\nG0 X2");
    EXPECT_EQ(exec.lines(), (Lines{1, 2}));
    ASSERT_EQ(exec.ends.size(), 1u);
    EXPECT_EQ(exec.ends[0].line, 3);
}

TEST_F(InterpFixture, LeadingLabelNamesTheMainProgram) {
    run("O0001\nG1 X1\nM30\n");
    EXPECT_EQ(exec.lines(), (Lines{2, 3}));
}

TEST_F(InterpFixture, MainProgramEndsAtFirstSubprogramLabel) {
    run("G1 X1\nO10\nG1 X2\nM17\n");
    EXPECT_EQ(exec.lines(), (Lines{1}));
    ASSERT_EQ(exec.ends.size(), 1u);
    EXPECT_EQ(exec.ends[0].line, 2);
}

TEST_F(InterpFixture, G65RepeatsSubprogramLTimes) {
    run("G0 X0\nG65 P9001 L3\nG0 X9\nM30\nO9001\nG91 G1 X1\nM17\n");
    EXPECT_EQ(exec.lines(), (Lines{1, 6, 6, 6, 3, 4}));
}

TEST_F(InterpFixture, G65LZeroCallsNothing) {
    run("G65 P9001 L0\nM30\nO9001\nG1 X1\nM17\n");
    EXPECT_EQ(exec.lines(), (Lines{2}));
}

TEST_F(InterpFixture, OtherCodesOfACallBlockRunFirst) {
    run("G91 G65 P5\nM30\nO5\nG1 X1\nM17\n");
    ASSERT_EQ(exec.blocks.size(), 3u);
    EXPECT_EQ(exec.blocks[0].g[0], 910);  // G91 before the body
    EXPECT_EQ(exec.blocks[1].loc.line, 4);
}

// Nested repeats multiply: O2 runs 2 times and calls O3 3 times each run (S0 §3.5.1 G992 arrays).
TEST_F(InterpFixture, NestedRepeatsMultiply) {
    run("G65 P2 L2\nM30\nO2\nG65 P3 L=1+2\nG0 Y1\nM17\nO3\nG0 X1\nM17\n");
    EXPECT_EQ(exec.lines(), (Lines{8, 8, 8, 5, 8, 8, 8, 5, 2}));
}

TEST_F(InterpFixture, NamedSubprogram) {
    run("G65 P\"Frame\" L2\nM30\nO\"frame\"\nG1 X1\nM17\n");
    EXPECT_EQ(exec.lines(), (Lines{4, 4, 2}));
}

TEST_F(InterpFixture, SubprogramVariablesAreProgramGlobal) {
    run("#1=30 #3=2\nG65 P3456 L=#3\nG0 X=#1\nM30\nO3456\n#1=#1+1\nM17\n");
    EXPECT_EQ(exec.values('X'), (Values{32}));
}

TEST_F(InterpFixture, M98CallsWithFanucCountForm) {
    run("M98 P30021\nM30\nO21\nG1 X1\nM99\n");
    EXPECT_EQ(exec.lines(), (Lines{4, 4, 4, 2}));
}

TEST_F(InterpFixture, M99WithSequenceReturnsToThatBlockOfTheCaller) {
    // Forward from the call: N30 is after the calling block, N20 is skipped.
    run("N10 G65 P7\nN20 G0 X20\nN30 G0 X30\nM30\nO7\nG1 X7\nM99 P30\n");
    EXPECT_EQ(exec.values('X'), (Values{7, 30}));
    EXPECT_EQ(exec.lines(), (Lines{6, 3, 4}));
}

TEST_F(InterpFixture, M99SequenceSearchWrapsToProgramStart) {
    // N5 lies before the call: found by the second search from the start (SUB-7).
    run("#1=0\nN5 #1=#1+1\nIF(#1>2) M30\nG65 P7\nM30\nO7\nG1 X=#1\nM99 P5\n");
    EXPECT_EQ(exec.values('X'), (Values{1, 2}));
    EXPECT_EQ(exec.lines(), (Lines{7, 7, 3}));
}

TEST_F(InterpFixture, M99InMainRestartsTheProgram) {
    options.main_m99_loops = true;
    Interpreter& in = start("G1 X1\nG1 X2 M99\nG1 X3\n");
    for (int i = 0; i < 6; ++i) in.step();
    EXPECT_EQ(exec.lines(), (Lines{1, 2, 1, 2, 1, 2}));
    EXPECT_FALSE(in.finished());
}

TEST_F(InterpFixture, M99InMainEndsWhenLoopingIsOff) {
    options.main_m99_loops = false;
    run("G1 X1\nM99\nG1 X3\n");
    EXPECT_EQ(exec.lines(), (Lines{1}));
    EXPECT_EQ(exec.ends.size(), 1u);
}

TEST_F(InterpFixture, M99WithSequenceInMainJumps) {
    Interpreter& in = start("N1 G1 X1\nN2 G1 X2\nM99 P2\n");
    for (int i = 0; i < 6; ++i) in.step();  // N1, N2, M99, N2, M99, N2
    EXPECT_EQ(exec.lines(), (Lines{1, 2, 2, 2}));
}

TEST_F(InterpFixture, M02InsideSubprogramEndsEverything) {
    run("G65 P1\nG0 X9\nM30\nO1\nG1 X1\nM02\nM17\n");
    EXPECT_EQ(exec.lines(), (Lines{5, 6}));
    EXPECT_EQ(interp->call_depth(), 0);
}

TEST_F(InterpFixture, BlockDeleteSkipsSlashLinesWhenOn) {
    options.block_delete = true;
    run("G1 X1\n/G1 X2 #1=5\nG1 X3\n");
    EXPECT_EQ(exec.values('X'), (Values{1, 3}));
    EXPECT_FALSE(interp->variables().numbered_if_set(1));
    options.block_delete = false;
    exec.blocks.clear();
    run("G1 X1\n/G1 X2\n");
    EXPECT_EQ(exec.values('X'), (Values{1, 2}));
}

TEST_F(InterpFixture, IfFalseSkipsBlock) {
    run("#1=0\nIF(#1) G1 X1\nIF(!#1) G1 X2\n");
    EXPECT_EQ(exec.values('X'), (Values{2}));
}

// A block the back end rejects changes no state: its assignments are rolled back, and the
// interpreter continues with the next line when asked to.
TEST_F(InterpFixture, RejectedBlockChangesNoState) {
    exec.reject_line = 2;
    Interpreter& in = start("#1=1\n#1=5 G1 X=#1\nG1 Y=#1\n");
    EXPECT_TRUE(in.step());
    EXPECT_THROW(in.step(), Error);
    EXPECT_EQ(*in.variables().numbered_if_set(1), 1.0);
    EXPECT_TRUE(in.step() || in.finished());
    EXPECT_EQ(exec.values('Y'), (Values{1}));
}

TEST_F(InterpFixture, CheckModeReportsEveryError) {
    const auto errors = check("G1 X1\nG1 X=1/0\nG1 X2\nG65 P404\nG1 Y2 Y3\nM30\n");
    EXPECT_EQ(errors, (std::vector<std::string>{"main.nc:2:7: division by zero",
                                                "main.nc:4:1: subprogram O404 not found",
                                                "main.nc:5:7: word Y appears twice in one block"}));
    EXPECT_EQ(exec.lines(), (Lines{1, 3, 6}));
}

TEST_F(InterpFixture, ErrorSubprogramNotFound) {
    EXPECT_EQ(run_error("G0 X1\nG65 P\"nope\"\n"), "main.nc:2:1: subprogram O\"nope\" not found");
    EXPECT_EQ(exec.lines(), (Lines{1}));  // the failing block did not run its other words
}

TEST_F(InterpFixture, ErrorCustomGWithCall) {
    EXPECT_EQ(run_error("G86 G65 P\"helper\"\n", true),
              "main.nc:1:1: custom G86 and a subprogram call in one block");
}

// M17-1 REC: M17 in the main program ends it as M30, with a warning; later lines do not run.
TEST_F(InterpFixture, M17InMainProgramEndsItAsM30WithAWarning) {
    WarningList w;
    options.warnings = &w;
    run("G0 X1\nM17\nG0 X2\n");
    ASSERT_EQ(exec.blocks.size(), 2u);
    EXPECT_TRUE(exec.blocks[1].has_m(30));
    EXPECT_EQ(exec.blocks[1].loc.line, 2);
    EXPECT_TRUE(exec.ends.empty());
    EXPECT_EQ(w.text, (std::vector<std::string>{
                          "main.nc:2:1: M17 in the main program ends it as M30 does"}));
}

TEST_F(InterpFixture, ErrorSubprogramRunsIntoNextLabel) {
    EXPECT_EQ(run_error("G65 P1\nM30\nO1\nG1 X1\nO2\nM17\n"),
              "main.nc:5:1: subprogram O1 runs into the next label without M17");
}

TEST_F(InterpFixture, ErrorSubprogramEndsWithoutM17) {
    EXPECT_EQ(run_error("G65 P1\nM30\nO1\nG1 X1\n"), "main.nc:5:1: subprogram O1 ends without M17");
    EXPECT_TRUE(interp->finished());
}

TEST_F(InterpFixture, ErrorRecursionTooDeep) {
    EXPECT_EQ(run_error("G65 P1\nM30\nO1\nG65 P1\nM17\n"),
              "main.nc:4:1: subprogram calls nested deeper than 64 levels");
}

TEST_F(InterpFixture, ErrorM99TargetMissing) {
    EXPECT_EQ(run_error("G65 P7\nM30\nO7\nM99 P44\n"),
              "main.nc:4:1: M99 P44: no block N44 in the calling program");
    EXPECT_EQ(run_error("G1 X1\nM99 P44\n"),
              "main.nc:2:1: M99 P44: no block N44 in the main program");
}

// S0 §4.2 custom M codes from public.dat (EX-26): M03 runs O203 after the block's motion; M05
// and M08 run O205 and O208 in written order; M07 has no subprogram and stays a plain code.
TEST_F(InterpFixture, PublicDatCustomMCodes) {
    run("G0 X1 M03\nM07\nM05 M08\nM30\n", true);
    std::vector<std::string> seen;
    for (const Block& b : exec.blocks) {
        std::string s = std::string(b.loc.file == "main.nc" ? "main" : "lib") + ":";
        for (int m : b.m) s += "M" + std::to_string(m) + " ";
        for (int g : b.g) s += "G" + std::to_string(g / 10) + " ";
        if (b.has('H')) s += "H" + std::to_string(static_cast<int>(b.get('H'))) + " ";
        if (b.has('P')) s += "P" + std::to_string(static_cast<int>(b.get('P')));
        seen.push_back(s);
    }
    EXPECT_EQ(seen, (std::vector<std::string>{
                        "main:G0 ",        // the block's motion first
                        "lib:M901 H2 P1",  // O203
                        "lib:G4 P5",
                        "lib:M3 ",  // M03 inside O203 is the built-in code
                        "main:M7 ",
                        "lib:M901 H2 P0",  // O205, then O208 in written order
                        "lib:G4 P5",
                        "lib:M901 H24 P1",
                        "lib:G4 P5",
                        "main:M30 ",
                    }));
}

// S0 §4.1.1 example 2 (EX-25): custom G86 with retract. G90 G99 G86 X10 Y10 Z-10 R2 Q3 F300
// with FIXEDCYCLE_BACK=1 must rapid to (10,10), rapid to R2, feed to -1, then
// int(|2-(-10)|/3)-1 = 3 times {rapid +1, rapid -1, feed -3}, feed to -10, M05, rapid to R2,
// stay at R (G99) and M03.
TEST_F(InterpFixture, PublicDatCustomG86WithRetract) {
    machine.settings["FIXEDCYCLE_BACK"] = 1.0;
    machine.return_to_r = true;   // G99, as the back end would report after the block's G99
    machine.incremental = false;  // G90
    machine.work_mm[2] = 10.0;    // initial Z
    run("G90 G99 G86 X10 Y10 Z-10 R2 Q3 F300\nM30\n", true);
    ASSERT_GE(exec.blocks.size(), 2u);
    const Block& first = exec.blocks[0];
    EXPECT_EQ(first.g.size(), 2u);  // G90 G99 act first; X Y Z R Q F went to #FC1…#FC7
    EXPECT_FALSE(first.has('X'));
    EXPECT_EQ(exec.values('Z'), (Values{2, -1, 1, -1, -3, 1, -1, -3, 1, -1, -3, -10, 2}));
    EXPECT_EQ(exec.values('X'), (Values{10}));
    EXPECT_EQ(exec.values('F'), (Values{300, 300, 300, 300, 300}));
    std::vector<int> ms;
    for (const Block& b : exec.blocks)
        for (int m : b.m) ms.push_back(m);
    // M05 and M03 inside O786 are themselves custom codes of this library: O205 and O203 run
    // (M901 each), and the M03 inside O203 is the built-in code.
    EXPECT_EQ(ms, (std::vector<int>{901, 901, 3, 30}));
    EXPECT_EQ(interp->variables().fixed_cycle(14, {}), 10.0);
    EXPECT_EQ(interp->variables().fixed_cycle(11, {}), 1.0);  // no K: one run
}

// The same custom G86 under G91 (#FC13=1) takes the O686 branch that calls O786 #FC11 (K) times
// and leaves G91 active at the end.
TEST_F(InterpFixture, PublicDatCustomG86UnderG91) {
    machine.settings["FIXEDCYCLE_BACK"] = 1.0;
    machine.incremental = true;
    run("G91 G99 G86 X10 Y10 Z-10 R2 Q3 F300 K2\nM30\n", true);
    int g91_blocks = 0, xy_moves = 0;
    for (const Block& b : exec.blocks) {
        if (b.g.size() == 1 && b.g[0] == 910 && !b.has('Z')) ++g91_blocks;
        if (b.has('X') && b.get('X') == 10.0 && b.get('Y') == 10.0) ++xy_moves;
    }
    EXPECT_EQ(xy_moves, 2);        // O786 ran K2 times
    EXPECT_EQ(g91_blocks, 1 + 2);  // O686's G91 before the call, O786's final IF(#FC13)G91 twice
    EXPECT_EQ(interp->variables().fixed_cycle(11, {}), 2.0);
}

// Two custom codes in one block run one after the other; a code only queued behind the running
// one is not "inside" it, so M05 within O203 still runs O205.
TEST_F(InterpFixture, QueuedCustomCodeIsNotActiveYet) {
    interp = std::make_unique<Interpreter>(exec, machine, options);
    interp->set_library(Source::from_string("lib.dat", "O203\nM05\nM17\nO205\nG1 X5\nM17\n"));
    interp->open(Source::from_string("main.nc", "M03 M05\nM30\n"));
    interp->run();
    EXPECT_EQ(exec.values('X'), (Values{5, 5}));
    EXPECT_EQ(exec.lines(), (Lines{5, 5, 2}));
}

// cfg:s_hook_prog: the configured subprogram runs after each block with S, before the block's
// custom M codes, and an S inside it does not re-enter it.
TEST_F(InterpFixture, SHookRunsAfterBlocksWithS) {
    options.s_hook_program = 202;
    run("G0 X1 S1000 M03\nG0 X2\nS2000\nM30\nO202\nG04 P7\nS1\nM17\n", true);
    // Lines of main.nc as positive numbers, public.dat lines as 0: block 1, the hook (6, 7), then
    // O203 for M03 (three library blocks), block 2, block 3 with the hook again, M30.
    std::vector<int> lines;
    for (const Block& b : exec.blocks) lines.push_back(b.loc.file == "main.nc" ? b.loc.line : 0);
    EXPECT_EQ(lines, (Lines{1, 6, 7, 0, 0, 0, 2, 3, 6, 7, 4}));
    EXPECT_EQ(exec.values('S'), (Values{1000, 1, 2000, 1}));
}

TEST_F(InterpFixture, ErrorSHookMissing) {
    options.s_hook_program = 202;
    EXPECT_EQ(run_error("G0 X1 S1000\n"), "main.nc:1:7: S hook subprogram O202 not found");
}

TEST_F(InterpFixture, LibrarySubprogramCallableByG65) {
    run("G65 P\"helper\"\nM30\n", true);
    EXPECT_EQ(exec.values('X'), (Values{77}));
    EXPECT_EQ(files()[0], INTERP_FRONT_DATA_DIR "/public.dat");
}

TEST_F(InterpFixture, ProgramSubprogramWinsOverLibrary) {
    run("G65 P\"helper\"\nM30\nO\"helper\"\nG1 X5\nM17\n", true);
    EXPECT_EQ(exec.values('X'), (Values{5}));
}

// The dialect is chosen per program: the same interpreter reads V5.4 syntax after switching.
TEST_F(InterpFixture, DialectChosenPerProgram) {
    Interpreter& in = start("#1=2^3\n");
    EXPECT_THROW(in.run(), Error);  // ^ is not an operator of the 6th edition
    in.open(Source::from_string("v54.nc", "#1=2^3\nG0 X=#1 Y=#SSCURPOS0\n"),
            &ncstudio_v54_dialect());
    in.run();
    EXPECT_EQ(exec.values('X'), (Values{8}));
    EXPECT_EQ(in.dialect().name, "ncstudio-v54");
}

// S0 §3.5.1 G992 array, method 1 (EX-01), with the user's part reduced to one drilling move:
// O3455 runs #4=30 times and calls O3456 #3=30 times each, so the part runs 900 times, and
// every O3456 run ends with the X step G00 G90 X=#1 (X30).
TEST_F(InterpFixture, ManualG992ArrayCallStructure) {
    run("#1=30      'X offset\n"
        "#2=40      'Y offset\n"
        "#3=30      'items in X\n"
        "#4=30      'items in Y\n"
        "G65 P3455 L=#4\n"
        "G00 G90 X=-#1*#3 Y=-#2*#4\n"
        "G992 X0 Y0\n"
        "M30\n"
        "O3455\n"
        "G65 P3456 L=#3\n"
        "G00 G90 X=-#1*#3 Y=#2\n"
        "G906\n"
        "G992 X0 Y0\n"
        "M17\n"
        "O3456\n"
        "G81 X5 Y5 Z-1 R1 F100\n"
        "G00 G90 X=#1\n"
        "G906\n"
        "G992 X0\n"
        "M17\n");
    int part = 0, x_steps = 0, row_steps = 0;
    for (const Block& b : exec.blocks) {
        if (b.loc.line == 16) ++part;
        if (b.loc.line == 17 && b.get('X') == 30.0) ++x_steps;
        if (b.loc.line == 11 && b.get('X') == -900.0 && b.get('Y') == 40.0) ++row_steps;
    }
    EXPECT_EQ(part, 900);
    EXPECT_EQ(x_steps, 900);
    EXPECT_EQ(row_steps, 30);
    EXPECT_EQ(exec.blocks.back().loc.line, 8);                         // M30
    EXPECT_EQ(exec.blocks[exec.blocks.size() - 3].get('Y'), -1200.0);  // -#2*#4
}

// S0 §3.12 example 5 (EX-22): G65 P9001 L6 runs the loop six times; subprogram after M30.
TEST_F(InterpFixture, ManualExample5SubprogramAfterM30) {
    run("N01 G92 X0 Y0 Z0\nN02 G65 P9001 L6\nN03 G90 G00 Z12\nN04 M30\n"
        "O9001\nN10 G91 G01 Z-2 F100\nN20 X60\nN30 Y50\nN40 X-60\nN50 Y-50\nN60 M17\n");
    EXPECT_EQ(exec.values('Z'), (Values{0, -2, -2, -2, -2, -2, -2, 12}));
    EXPECT_EQ(exec.blocks.size(), 1u + 6 * 5 + 2);
}

// S0 §4.1.1 example 1 (EX-24): the G53 move to the fixed point runs only when ENABLE_CTP is set.
TEST_F(InterpFixture, ManualNamedParameterExample) {
    const std::string prog =
        "G65 P1000\nM30\n"
        "O1000      ' coolant, tool change\n"
        "M901 H=#COOLANT_START_PORT P1\n"
        "G04 P10\n"
        "IF(#ENABLE_CTP) G53 G00 G90 X=#CTP_POS. X Y=#CTP_POS. Y Z=#CTP_POS. Z\n"
        "' go to the tool-change position\n"
        "G00 G90 Z10 ' or just lift\n"
        "M05\n"
        "M17\n";
    machine.settings = {{"COOLANT_START_PORT", 24},
                        {"ENABLE_CTP", 1},
                        {"CTP_POS.X", 100},
                        {"CTP_POS.Y", 200},
                        {"CTP_POS.Z", -5}};
    run(prog);
    EXPECT_EQ(exec.values('H'), (Values{24}));
    EXPECT_EQ(exec.values('X'), (Values{100}));
    EXPECT_EQ(exec.values('Z'), (Values{-5, 10}));
    ASSERT_EQ(exec.blocks.size(), 6u);
    EXPECT_TRUE(exec.blocks[2].has_g(530));
    exec.blocks.clear();
    machine.settings["ENABLE_CTP"] = 0;
    run(prog);
    EXPECT_EQ(exec.values('X'), (Values{}));
    EXPECT_EQ(exec.blocks.size(), 5u);
}

// S1 §3.5 example 4 (EX-34): #2 #3 #4 set in the parameter window, then G00 X=#2 Y=#3 Z=#4.
TEST_F(InterpFixture, ManualV54ParameterWindowExample) {
    options.dialect = &ncstudio_v54_dialect();
    Interpreter& in =
        start("G=1+2 X1 Y1 R1\nG00 X=#2 Y=#3 Z=#4 \xE2\x80\x99#2 #3 #4 from the UI\n");
    in.variables().set_numbered(2, 5, {});
    in.variables().set_numbered(3, 8, {});
    in.variables().set_numbered(4, 2, {});
    in.run();
    ASSERT_EQ(exec.blocks.size(), 2u);
    EXPECT_EQ(exec.blocks[0].g[0], 30);  // G=1+2 is G3
    EXPECT_EQ(exec.blocks[1].get('X'), 5.0);
    EXPECT_EQ(exec.blocks[1].get('Y'), 8.0);
    EXPECT_EQ(exec.blocks[1].get('Z'), 2.0);
}

// No globals: two interpreters interleaved keep their own variables, stacks and positions.
TEST(InterpreterIsolation, TwoInterpretersSideBySide) {
    test::FakeMachine m1, m2;
    test::RecordingExecutor e1, e2;
    Interpreter a(e1, m1), b(e2, m2);
    a.open(Source::from_string("a.nc", "#1=1\nG65 P1 L2\nG0 X=#1\nM30\nO1\n#1=#1*10\nM17\n"));
    b.open(Source::from_string("b.nc", "#1=2\nG65 P1 L2\nG0 X=#1\nM30\nO1\n#1=#1+1\nM17\n"));
    bool more_a = true, more_b = true;
    while (more_a || more_b) {
        if (more_a) more_a = a.step();
        if (more_b) more_b = b.step();
    }
    EXPECT_EQ(e1.values('X'), (Values{100}));
    EXPECT_EQ(e2.values('X'), (Values{4}));
}

// Streaming: a 300k-line program runs with the source read through a fixed window.
TEST(InterpreterStreaming, LargeFileWithSubprogramAtTheEnd) {
    const std::string path =
        ::testing::TempDir() + "ifront_big_" + std::to_string(::getpid()) + ".nc";
    {
        std::ofstream f(path);
        f << "G65 P9 L2\n";
        for (int i = 0; i < 300000; ++i) f << "G1 X" << (i % 100) << " Y1.5 Z-0.5 F1000\n";
        f << "M30\nO9\nG0 Z5\nM17\n";
    }
    test::FakeMachine m;
    test::RecordingExecutor e;
    Interpreter in(e, m);
    in.open(path);
    in.run();
    EXPECT_EQ(e.blocks.size(), 300003u);
    EXPECT_EQ(e.blocks[0].get('Z'), 5.0);
    EXPECT_EQ(e.blocks[1].get('Z'), 5.0);
    EXPECT_EQ(e.blocks.back().loc.line, 300002);
    ::unlink(path.c_str());
}

// TSET-2: #FIXEDCALI_REC is the one named parameter a program writes. The write reaches the
// machine only after its block executed, in mm, and a rejected block writes nothing.
TEST_F(InterpFixture, WritableNamedParameterIsStoredAfterItsBlock) {
    machine.keeps_settings = true;
    machine.mm_per_unit = 25.4;
    run("#FIXEDCALI_REC=2 X=#FIXEDCALI_REC\nM30\n");
    ASSERT_EQ(machine.writes.size(), 1u);
    EXPECT_EQ(machine.writes[0].first, "FIXEDCALI_REC");
    EXPECT_DOUBLE_EQ(machine.writes[0].second, 50.8);
    // Read back in the same block before it was stored: program units.
    EXPECT_EQ(exec.values('X'), (Values{2.0}));
}

TEST_F(InterpFixture, WritableNamedParameterOfARejectedBlockIsDropped) {
    machine.keeps_settings = true;
    exec.reject_line = 1;
    EXPECT_EQ(run_error("#FIXEDCALI_REC=2 G01 X1\n"), "main.nc:1:1: rejected by test executor");
    EXPECT_TRUE(machine.writes.empty());
}

TEST_F(InterpFixture, WritableNamedParameterNeedsAMachineThatKeepsSettings) {
    EXPECT_EQ(run_error("#FIXEDCALI_REC=2\n"),
              "main.nc:1:1: named parameter #FIXEDCALI_REC cannot be stored on this machine (no "
              "settings file)");
}

TEST_F(InterpFixture, DuplicateSequenceNumberIsAWarningNotAnError) {
    WarningList w;
    options.warnings = &w;
    run("N5 G1 X1\nN5 G1 X2\nM30\n");
    EXPECT_EQ(exec.lines(), (Lines{1, 2, 3}));
    EXPECT_EQ(w.text, (std::vector<std::string>{
                          "main.nc:2:1: sequence number N5 is used twice in this program; M99 P "
                          "and searches find the first one"}));
}
