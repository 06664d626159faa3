#include <sys/wait.h>

#include <cmath>

#include "test_support.hpp"

namespace hal::test {
namespace {

using Rt = RuntimeFixture;

TEST_F(Rt, PinsOfEveryTypeStartAtTheirDeclaredValues) {
    make();
    run("loadrt tprobe");
    EXPECT_EQ(run("getp tprobe.0.in-float"), "1.5\n");
    EXPECT_EQ(run("getp tprobe.0.in-s32"), "-3\n");
    EXPECT_EQ(run("getp tprobe.0.in-bit"), "FALSE\n");
    EXPECT_EQ(run("getp tprobe.0.gain"), "2\n");
    EXPECT_EQ(run("ptype tprobe.0.in-u64"), "u64\n");
    EXPECT_EQ(run("getp tprobe.0.tap-01"), "0\n");
}

TEST_F(Rt, CountNamesAndPerInstanceArguments) {
    make();
    run("loadrt tprobe names=left,right taps=1,3");
    EXPECT_EQ(run("list pin left.tap"), "left.tap-00\n");
    EXPECT_EQ(run("list pin right.tap"), "right.tap-00 right.tap-01 right.tap-02\n");
    run("loadrt tprobe count=2");  // a second loadrt of the same component continues numbering
    EXPECT_EQ(run("list funct tprobe.2"), "tprobe.2\n");
    EXPECT_EQ(run("list funct tprobe.3"), "tprobe.3\n");
}

TEST_F(Rt, LoadrtErrorsNameTheProblem) {
    make();
    EXPECT_EQ(error_of("loadrt tprobe cont=2"), "loadrt tprobe: unknown argument 'cont' (did you mean 'count'?)");
    EXPECT_EQ(error_of("loadrt tprobe count=2 names=a"), "loadrt tprobe: give either count= or names=, not both");
    EXPECT_EQ(error_of("loadrt tprobe count=0"), "loadrt tprobe: count=0: expected a count from 1 to 100000");
    EXPECT_EQ(error_of("loadrt tprobe names=a,a"), "loadrt tprobe: instance name 'a' given twice");
    EXPECT_EQ(error_of("loadrt tprobe taps"), "loadrt tprobe: argument 'taps' is not of the form KEY=VALUE");
    EXPECT_NE(error_of("loadrt tprob").find("no component 'tprob' (did you mean 'tprobe'?)"), std::string::npos);
    EXPECT_NE(error_of("loadrt tbadabi").find("was built for HAL ABI 101, this runtime is ABI 1; rebuild it"),
              std::string::npos);
    EXPECT_NE(error_of("loadrt tnosym").find("is not a HAL component: it has no cnc_hal_component entry point"),
              std::string::npos);
    EXPECT_EQ(run("list comp"), "\n");
}

TEST_F(Rt, AComponentAttachesToAnotherInstancesStream) {
    make();
    run("loadrt tstream");
    run("loadrt tstreamreader from=tstream.0");
    run("newthread t 1000000");
    run("addf tstream.0 t");
    run("addf tstreamreader.0 t");
    run("setp tstream.0.value 2.5");
    run("start");
    run("advance 0.003");
    // Producer before consumer in the thread: each cycle's record is read in the same cycle.
    EXPECT_EQ(run("getp tstreamreader.0.popped"), "3\n");
    EXPECT_EQ(run("getp tstreamreader.0.value"), "2.5\n");
    EXPECT_EQ(run("getp tstreamreader.0.flag"), "TRUE\n");  // the third record: n = 2 is even
    EXPECT_NE(error_of("loadrt tstreamreader from=tstream.7").find("no stream 'tstream.7' to attach to"),
              std::string::npos);
    EXPECT_EQ(error_of("loadrt tstreamreader from=tstream.0 layout=ff"),
              "loadrt tstreamreader: stream 'tstream.0' has 2 fields of another layout than 'ff'");
    run("stop");
    run("unload tstreamreader");
    run("unload tstream");
    // The owner's stream name is free again after unload.
    run("loadrt tstream");
    run("loadrt tstreamreader from=tstream.0");
}

TEST_F(Rt, AFailedConstructorLeavesNothingBehind) {
    make();
    auto before = rt->segment().bytes_in_use();
    EXPECT_EQ(error_of("loadrt tfailing count=3 fail-at=2"), "loadrt tfailing: refusing to build this instance");
    EXPECT_EQ(run("list pin"), "\n");
    EXPECT_EQ(run("list funct"), "\n");
    EXPECT_EQ(run("list comp"), "\n");
    run("loadrt tfailing count=3");  // the storage the failed load took is reused
    // The function's `.time` pin too, as LinuxCNC gives every function one.
    EXPECT_EQ(run("list pin tfailing.2"), "tfailing.2.a tfailing.2.b tfailing.2.time\n");
    EXPECT_EQ(run("list pin fixed"), "fixed.0.b fixed.1.b fixed.2.b\n");  // '=' names are unprefixed
    EXPECT_LE(rt->segment().bytes_in_use(), before + 3 * 1024);
}

TEST_F(Rt, NetEnforcesOneWriterAndMatchingTypes) {
    make();
    run("loadrt tprobe count=2");
    run("net x tprobe.0.out-float => tprobe.1.in-float");
    EXPECT_EQ(error_of("net x tprobe.1.out-float"),
              "signal 'x' already has output pin 'tprobe.0.out-float'; 'tprobe.1.out-float' would be a second writer");
    EXPECT_EQ(error_of("net x tprobe.0.in-bit"), "signal 'x' is float but pin 'tprobe.0.in-bit' is bit");
    EXPECT_EQ(error_of("net x tprobe.0.io-float"),
              "signal 'x' already has output pin 'tprobe.0.out-float'; it cannot also have I/O pin 'tprobe.0.io-float'");
    EXPECT_EQ(error_of("net y tprobe.1.in-float"), "pin 'tprobe.1.in-float' is already linked to signal 'x'");
    EXPECT_EQ(error_of("net tprobe.0.in-bit tprobe.1.in-bit"),
              "'tprobe.0.in-bit' is a pin; the first argument of net is the signal name");
    EXPECT_EQ(run("net x tprobe.1.in-float"), "");  // relinking to the same signal is harmless
}

TEST_F(Rt, AFailingNetLinksNothing) {
    make();
    run("loadrt tprobe count=2");
    // The third pin is wrong: the first two must stay unlinked and no signal may appear.
    EXPECT_NE(error_of("net z tprobe.0.out-bit tprobe.1.in-bit tprobe.1.in-float"), "");
    EXPECT_EQ(run("list sig"), "\n");
    EXPECT_EQ(run("net z tprobe.1.in-bit"), "");
    EXPECT_EQ(error_of("net z2 tprobe.0.out-bit tprobe.1.out-bit"),
              "signal 'z2' already has output pin 'tprobe.0.out-bit'; 'tprobe.1.out-bit' would be a second writer");
    EXPECT_EQ(run("list sig"), "z\n");
}

TEST_F(Rt, ValuesFlowThroughSignalsAndUnlinkKeepsTheLastValue) {
    make();
    run("loadrt threads name1=t period1=1000000");
    run("loadrt tprobe count=2");
    run("addf tprobe.0 t");
    run("addf tprobe.1 t");
    run("net v tprobe.0.out-float tprobe.1.in-float");
    run("setp tprobe.0.in-float 4");
    run("start");
    run("advance 0.002");
    EXPECT_EQ(run("gets v"), "8\n");
    EXPECT_EQ(run("getp tprobe.1.out-float"), "16\n");
    run("unlinkp tprobe.1.in-float");
    EXPECT_EQ(run("getp tprobe.1.in-float"), "8\n");
    EXPECT_EQ(run("show sig v"), "Signals:\nType               Value  Name     (linked to)\nfloat                  8  v\n"
                                 "                         <== tprobe.0.out-float\n");
}

TEST_F(Rt, SetpAndSetsRefuseWhatWouldBeOverwritten) {
    make();
    run("loadrt tprobe count=2");
    run("net v tprobe.0.out-float tprobe.1.in-float");
    EXPECT_EQ(error_of("setp tprobe.0.out-float 1"),
              "pin 'tprobe.0.out-float' is an output; setp writes only inputs and parameters");
    EXPECT_EQ(error_of("setp tprobe.1.in-float 1"),
              "pin 'tprobe.1.in-float' is linked to signal 'v'; use sets on the signal");
    EXPECT_EQ(error_of("sets v 1"), "signal 'v' is driven by output pin 'tprobe.0.out-float'; sets would be overwritten");
    EXPECT_EQ(error_of("setp tprobe.0.ro 1"), "parameter 'tprobe.0.ro' is read-only");
    EXPECT_EQ(error_of("setp tprobe.0.in-s32 1.5"), "'1.5' is not a valid s32 value for tprobe.0.in-s32");
    EXPECT_EQ(error_of("setp tprobe.0.in-u32 -1"), "'-1' is not a valid u32 value for tprobe.0.in-u32");
    EXPECT_EQ(error_of("setp tprobe.0.in-bit 2"), "'2' is not a valid bit value for tprobe.0.in-bit");
    EXPECT_EQ(error_of("setp tprobe.0.gian 1"),
              "pin or parameter 'tprobe.0.gian' does not exist (did you mean 'tprobe.0.gain'?)");
    run("setp tprobe.0.in-u32 0x10");
    EXPECT_EQ(run("getp tprobe.0.in-u32"), "16\n");
    run("newsig free s64");
    run("sets free -9000000000");
    EXPECT_EQ(run("gets free"), "-9000000000\n");
}

TEST_F(Rt, AddfOrderPositionsAndRules) {
    make();
    run("loadrt threads name1=t period1=1000000");
    run("newthread slow 2000000 nofp");
    run("loadrt tprobe count=3");
    run("addf tprobe.0 t");
    run("addf tprobe.1 t 1");
    run("addf tprobe.2 t -2");
    EXPECT_NE(run("show thread t").find("1 tprobe.1\n                  2 tprobe.2\n                  3 tprobe.0"),
              std::string::npos);
    EXPECT_EQ(error_of("addf tprobe.0 t"), "function 'tprobe.0' is already in thread 't'; a function runs in one thread only");
    EXPECT_EQ(error_of("addf tprobe.tick-all slow"),
              "function 'tprobe.tick-all' uses floating point but thread 'slow' was created nofp");
    EXPECT_EQ(error_of("addf tprobe.0 fast"), "thread 'fast' does not exist");
    run("delf tprobe.1 t");
    EXPECT_EQ(error_of("delf tprobe.1"), "function 'tprobe.1' is not in any thread");
}

TEST_F(Rt, SimulatedClockRunsEachThreadAtItsPeriodDeterministically) {
    make();
    run("loadrt threads name1=fast period1=250000 name2=slow period2=1000000");
    run("loadrt tprobe names=f,s");
    run("addf f fast");
    run("addf s slow");
    run("start");
    run("advance 0.01");
    EXPECT_EQ(run("getp f.cycles"), "40\n");
    EXPECT_EQ(run("getp s.cycles"), "10\n");
    EXPECT_EQ(run("getp slow.cycles"), "10\n");
    run("stop");
    run("advance 1");
    EXPECT_EQ(run("getp s.cycles"), "10\n");
    EXPECT_EQ(error_of("advance -1"), "'-1' is not a duration in seconds (0 to 1e6)");
}

TEST_F(Rt, SharedFunctionCallsEveryInstance) {
    make();
    run("loadrt threads name1=t period1=1000000");
    run("loadrt tprobe count=3");
    run("addf tprobe.tick-all t");
    run("addf tprobe.2 t");
    run("start");
    run("advance 0.005");
    // tick-all counts once per cycle on each instance; tprobe.2 adds its own update.
    EXPECT_EQ(run("getp tprobe.2.cycles"), "10\n");
}

TEST_F(Rt, AThousandInstancesFitWithoutTuning) {
    make();
    run("loadrt tprobe count=1000");
    EXPECT_EQ(run("getp tprobe.999.gain"), "2\n");
    run("loadrt tfailing count=2000");
    EXPECT_EQ(run("ptype tfailing.1999.b"), "bit\n");
}

TEST_F(Rt, UnloadRemovesEverythingAndFreesStorage) {
    make();
    run("loadrt threads name1=t period1=1000000");
    run("loadrt tprobe count=2");
    run("net v tprobe.0.out-float tprobe.1.in-float");
    run("addf tprobe.0 t");
    auto used = rt->segment().bytes_in_use();
    run("unload tprobe");
    EXPECT_EQ(run("list pin"), "t.time\n");  // only the thread's own pin is left
    EXPECT_EQ(run("list funct"), "\n");
    EXPECT_EQ(run("show thread t").find("tprobe"), std::string::npos);
    EXPECT_EQ(run("list sig"), "v\n");  // signals outlive their pins, as in LinuxCNC
    EXPECT_LT(rt->segment().bytes_in_use(), used);
    run("loadrt tprobe count=2");
    EXPECT_EQ(rt->segment().bytes_in_use(), used);
}

TEST_F(Rt, AliasesAndLocks) {
    make();
    run("loadrt tprobe");
    run("alias pin tprobe.0.in-float feed");
    run("setp feed 3");
    EXPECT_EQ(run("getp tprobe.0.in-float"), "3\n");
    run("alias param tprobe.0.gain k");
    EXPECT_EQ(run("getp k"), "2\n");
    EXPECT_EQ(error_of("unalias pin k"), "no pin alias 'k'");
    run("unalias param k");
    EXPECT_EQ(error_of("getp k"), "pin or parameter 'k' does not exist");
    run("lock tune");
    EXPECT_EQ(error_of("loadrt tprobe"), "'loadrt' is not allowed: HAL is locked (use 'unlock')");
    EXPECT_EQ(error_of("net s feed"), "'net' is not allowed: HAL is locked (use 'unlock')");
    run("setp feed 5");
    run("lock all");
    EXPECT_EQ(error_of("setp feed 5"), "'setp' is not allowed: HAL is locked (use 'unlock')");
    run("unlock all");
    run("net s feed");
}

TEST_F(Rt, SaveReproducesTheConfiguration) {
    make();
    run("loadrt threads name1=t period1=1000000");
    run("loadrt tprobe names=a,b taps=3");
    run("net v a.out-float b.in-float");
    run("setp a.gain 0.5");
    run("addf a t");
    auto saved = run("save");
    EXPECT_NE(saved.find("newthread t 1000000 fp\n"), std::string::npos);
    EXPECT_NE(saved.find("loadrt tprobe names=a,b taps=3\n"), std::string::npos);
    EXPECT_NE(saved.find("net v a.out-float b.in-float\n"), std::string::npos);
    EXPECT_NE(saved.find("setp a.gain 0.5\n"), std::string::npos);
    EXPECT_NE(saved.find("addf a t\n"), std::string::npos);
    EXPECT_EQ(saved.find("tmax"), std::string::npos);
    // Replaying the saved file in a fresh instance gives the same save.
    Runtime again({unique_instance("again"), kDefaultSegmentBytes, true});
    std::string line, out;
    for (char c : saved) {
        if (c != '\n') {
            line += c;
            continue;
        }
        again.execute(words(line), out);
        line.clear();
    }
    std::string resaved;
    again.execute({"save"}, resaved);
    EXPECT_EQ(resaved, saved);
}

TEST_F(Rt, UnknownCommandsAndArgumentCountsAreExplained) {
    make();
    EXPECT_EQ(error_of("linkps"), "wrong number of arguments; usage: linkps PIN [=>|<=|<=>] SIGNAL");
    EXPECT_EQ(error_of("sohw pin"), "unknown command 'sohw' (did you mean 'show'?)");
    EXPECT_EQ(error_of("advance x"), "'x' is not a duration in seconds (0 to 1e6)");
}

TEST(Segment, AStaleInstanceIsDetectedAndReplaced) {
    auto name = unique_instance("stale");
    pid_t child = ::fork();
    if (child == 0) {
        // Dies without cleaning up, like a crashed owner.
        Runtime* leaked = new Runtime({name, kDefaultSegmentBytes, true});
        (void)leaked;
        ::_exit(0);
    }
    int status = 0;
    ::waitpid(child, &status, 0);
    ASSERT_TRUE(WIFEXITED(status));
    testing::internal::CaptureStderr();
    Runtime rt({name, kDefaultSegmentBytes, true});
    auto err = testing::internal::GetCapturedStderr();
    EXPECT_NE(err.find(fmt::format("removed stale HAL instance '{}' left by dead process {}", name, child)),
              std::string::npos);
}

TEST(Segment, ALiveInstanceIsNotTakenOver) {
    auto name = unique_instance("live");
    Runtime first({name, kDefaultSegmentBytes, true});
    try {
        Runtime second({name, kDefaultSegmentBytes, true});
        FAIL() << "second owner accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("is already running (pid"), std::string::npos);
    }
    Runtime other({unique_instance("other"), kDefaultSegmentBytes, true});  // another name coexists
}

TEST(Values, ParseAndFormatFollowLinuxCnc) {
    EXPECT_EQ(format_value(Type::Float, *parse_value(Type::Float, "0.1")), "0.1");
    EXPECT_EQ(format_value(Type::Float, *parse_value(Type::Float, "1e-9")), "1e-09");
    EXPECT_EQ(format_value(Type::U32, *parse_value(Type::U32, "255"), true), "0x000000FF");
    EXPECT_EQ(format_value(Type::Bit, *parse_value(Type::Bit, "TRUE")), "TRUE");
    EXPECT_FALSE(parse_value(Type::S32, "2147483648"));
    EXPECT_TRUE(parse_value(Type::S64, "2147483648"));
    EXPECT_TRUE(std::isnan(parse_value(Type::Float, "nan")->f));  // LinuxCNC accepts it
    EXPECT_FALSE(parse_value(Type::Float, ""));
    EXPECT_EQ(nearest_name("and2.0.in", {"and2.0.in0", "and2.0.out"}), "and2.0.in0");
    EXPECT_EQ(nearest_name("zzz", {"and2.0.in0"}), "");
}

}  // namespace
}  // namespace hal::test
