// halsampler: drains a sampler stream to text, one record per line, as LinuxCNC's does.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cinttypes>
#include <csignal>
#include <cstdio>
#include <thread>

#include <fmt/format.h>

#include "hal/client.hpp"

namespace {
volatile std::sig_atomic_t g_stop = 0;
void on_signal(int) { g_stop = 1; }

void print_value(std::FILE* out, hal::Type t, hal::Value v) {
    switch (t) {
        case hal::Type::Bit: std::fprintf(out, "%d", v.b ? 1 : 0); break;
        case hal::Type::Float: std::fprintf(out, "%f", v.f); break;
        case hal::Type::S32: std::fprintf(out, "%" PRId32, v.s32); break;
        case hal::Type::U32: std::fprintf(out, "%" PRIu32, v.u32); break;
        case hal::Type::S64: std::fprintf(out, "%" PRId64, v.s64); break;
        case hal::Type::U64: std::fprintf(out, "%" PRIu64, v.u64); break;
    }
}
}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"halsampler: print the records of a sampler stream"};
    int channel = 0;
    long long count = -1;
    bool tag = false;
    double timeout_s = 0;
    std::string stream_name, file;
    app.add_option("-c,--channel", channel, "sampler instance number (stream sampler.N)");
    app.add_option("-s,--stream", stream_name, "stream name (instead of -c)");
    app.add_option("-n,--count", count, "stop after this many records");
    app.add_flag("-t,--tag", tag, "prefix each line with its record number");
    app.add_option("--timeout", timeout_s,
                   "give up (exit 1) when no record has come for this many seconds; 0 waits "
                   "for ever")
        ->check(CLI::NonNegativeNumber);
    app.add_option("file", file, "output file (default standard output)");
    CLI11_PARSE(app, argc, argv);
    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
    try {
        hal::Client client;
        if (stream_name.empty()) stream_name = fmt::format("sampler.{}", channel);
        auto stream = client.stream(stream_name);
        std::FILE* out = file.empty() ? stdout : std::fopen(file.c_str(), "w");
        if (!out) throw hal::Error(fmt::format("cannot write '{}'", file));
        std::vector<hal::Value> record(stream.fields());
        long long n = 0;
        // A test reading a fixed number of records fails at once, instead of at its runner's
        // timeout, when they stop coming.
        const auto wait_limit = std::chrono::duration<double>(timeout_s);
        auto last_record = std::chrono::steady_clock::now();
        while (!g_stop && (count < 0 || n < count)) {
            // Waiting for data is not an underrun: check before popping.
            if (stream.used() == 0 || !stream.pop(record.data())) {
                std::fflush(out);
                if (!hal::Connection::running(client.connection().instance()))
                    throw hal::Error("HAL instance ended");
                if (timeout_s > 0 && std::chrono::steady_clock::now() - last_record > wait_limit)
                    throw hal::Error(fmt::format("no record on '{}' for {} s ({} read{})",
                                                 stream_name, timeout_s, n,
                                                 count < 0 ? "" : fmt::format(" of {}", count)));
                std::this_thread::sleep_for(std::chrono::milliseconds(1));
                continue;
            }
            last_record = std::chrono::steady_clock::now();
            if (tag) std::fprintf(out, "%lld ", n);
            for (std::size_t i = 0; i < record.size(); ++i) {
                print_value(out, stream.field_type(i), record[i]);
                std::fputc(i + 1 < record.size() ? ' ' : '\n', out);
            }
            ++n;
        }
        std::fflush(out);
        if (out != stdout) std::fclose(out);
        return 0;
    } catch (const hal::Error& e) {
        fmt::print(stderr, "halsampler: {}\n", e.what());
        return 1;
    }
}
