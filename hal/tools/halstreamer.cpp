// halstreamer: feeds a streamer stream from text, one record per line, as LinuxCNC's does.
#include <CLI/CLI.hpp>
#include <chrono>
#include <csignal>
#include <fstream>
#include <iostream>
#include <sstream>
#include <thread>

#include <fmt/format.h>

#include "hal/client.hpp"

namespace {
volatile std::sig_atomic_t g_stop = 0;
void on_signal(int) { g_stop = 1; }
}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"halstreamer: write text records into a streamer stream"};
    int channel = 0;
    std::string stream_name, file;
    app.add_option("-c,--channel", channel, "streamer instance number (stream streamer.N)");
    app.add_option("-s,--stream", stream_name, "stream name (instead of -c)");
    app.add_option("file", file, "input file (default standard input)");
    CLI11_PARSE(app, argc, argv);
    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
    std::string source = file.empty() ? "<stdin>" : file;
    try {
        hal::Client client;
        if (stream_name.empty()) stream_name = fmt::format("streamer.{}", channel);
        auto stream = client.stream(stream_name);
        std::ifstream in_file;
        if (!file.empty()) {
            in_file.open(file);
            if (!in_file) throw hal::Error(fmt::format("cannot read '{}'", file));
        }
        std::istream& in = file.empty() ? std::cin : in_file;
        std::vector<hal::Value> record(stream.fields());
        std::string line;
        int line_no = 0;
        while (!g_stop && std::getline(in, line)) {
            ++line_no;
            if (line.find_first_not_of(" \t\r") == std::string::npos || line[0] == '#') continue;
            std::istringstream words(line);
            std::string word;
            std::size_t i = 0;
            for (; i < record.size() && words >> word; ++i) {
                auto v = hal::parse_value(stream.field_type(i), word);
                if (!v)
                    throw hal::Error(fmt::format("{}:{}: field {} '{}' is not a valid {}", source, line_no, i + 1,
                                                 word, hal::to_string(stream.field_type(i))));
                record[i] = *v;
            }
            if (i < record.size() || words >> word)
                throw hal::Error(fmt::format("{}:{}: expected {} fields", source, line_no, record.size()));
            // Waiting for room is not an overrun: check before pushing.
            while (!g_stop && stream.used() >= stream.depth()) {
                if (!hal::Connection::running(client.connection().instance())) throw hal::Error("HAL instance ended");
                std::this_thread::sleep_for(std::chrono::milliseconds(1));
            }
            if (!g_stop) stream.push(record.data());
        }
        return 0;
    } catch (const hal::Error& e) {
        fmt::print(stderr, "halstreamer: {}\n", e.what());
        return 1;
    }
}
