#include <thread>

#include "backends.hpp"
#include "hal/client.hpp"
#include "server.hpp"
#include "test_support.hpp"

namespace hal::test {
namespace {

struct ClientTest : RuntimeFixture {
    void SetUp() override {
        RuntimeFixture::SetUp();
        make(true, "client");
        server = std::make_unique<Server>(*rt, nullptr);
    }
    void TearDown() override { server.reset(); }
    std::unique_ptr<Server> server;
};

TEST_F(ClientTest, UserspaceComponentPinsJoinTheBus) {
    {
        Client user("ui", rt->paths().instance);
        auto jog = user.new_pin("ui.jog", Type::Float, Dir::Out);
        auto seen = user.new_pin("ui.seen", Type::Float, Dir::In);
        user.ready();
        EXPECT_TRUE(rt->component_ready("ui"));
        run("loadrt tprobe");
        run("loadrt threads name1=t period1=1000000");
        run("addf tprobe.0 t");
        run("net jog ui.jog tprobe.0.in-float");
        run("net back tprobe.0.out-float ui.seen");
        Value v;
        v.f = 2.5;
        jog.set(v);
        run("start");
        run("advance 0.001");
        EXPECT_EQ(seen.get().f, 5.0);  // gain 2: written by the RT function, read lock-free here
        EXPECT_NE(run("show comp ui").find(fmt::format("User  ui {:>37}  ready", ::getpid())), std::string::npos);
        auto found = user.find("tprobe.0.gain");
        EXPECT_EQ(found.get().f, 2.0);
    }
    // Closing the client removes its component and pins; signals stay.
    for (int i = 0; i < 200 && rt->component_exists("ui"); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    EXPECT_FALSE(rt->component_exists("ui"));
    EXPECT_EQ(run("list pin ui"), "\n");
}

TEST_F(ClientTest, RemoteCommandsReturnOutputAndErrors) {
    Connection c(rt->paths().instance);
    RemoteBackend remote(c);
    std::string out;
    remote.exec({"loadrt", "tprobe"}, out);
    remote.exec({"getp", "tprobe.0.in-float"}, out);
    EXPECT_EQ(out, "1.5\n");
    try {
        remote.exec({"getp", "tprobe.0.nope"}, out);
        FAIL();
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()), "pin or parameter 'tprobe.0.nope' does not exist");
    }
    auto pins = remote.names("pin");
    // 6 inputs, 2 outputs, io, cycles, 2 taps, and the `.time` of tprobe.0 and tprobe.tick-all
    EXPECT_EQ(pins.size(), 14u);
}

TEST_F(ClientTest, StreamRecordsCrossProcessesInOrder) {
    run("loadrt threads name1=t period1=1000000");
    run("loadrt tstream");
    run("addf tstream.0 t");
    run("setp tstream.0.value 1.25");
    run("start");
    run("advance 0.010");  // 10 cycles into a ring of 8: two pushes refused
    Client reader("", rt->paths().instance);
    auto s = reader.stream("tstream.0");
    EXPECT_EQ(s.fields(), 2u);
    EXPECT_EQ(s.field_type(1), Type::Bit);
    EXPECT_EQ(s.used(), 8u);
    EXPECT_EQ(s.overruns(), 2u);
    Value rec[2];
    for (int i = 0; i < 8; ++i) {
        ASSERT_TRUE(s.pop(rec));
        EXPECT_EQ(rec[0].f, 1.25);
        EXPECT_EQ(rec[1].b, i % 2 == 0);
    }
    EXPECT_FALSE(s.pop(rec));
    EXPECT_THROW(reader.stream("tstream.1"), Error);
}

TEST(Connection, NoInstanceIsAClearError) {
    try {
        Connection c("surely-not-running-instance");
        FAIL();
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()), "no HAL instance 'surely-not-running-instance' is running (start one with halrun)");
    }
}

TEST(Wire, RequestEncodingRoundTrips) {
    std::vector<std::string> w{"echo", "a\tb", "c\\d", "e\nf", ""};
    auto line = encode_request(w);
    EXPECT_EQ(line.find('\n'), line.size() - 1);
    EXPECT_EQ(decode_request(line.substr(0, line.size() - 1)), w);
}

}  // namespace
}  // namespace hal::test
