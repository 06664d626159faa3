// Fuzz target: HAL-file text through the language front end (comments, quotes, `\`
// continuation, $ENV substitution, tokenizing) into the bus commands of a simulated-clock
// instance. Commands that would run programs, read files or load arbitrary paths are skipped;
// `advance` and instance counts are capped so a slow input cannot stall the run. Any input must end in either
// success or hal::Error — never a crash, a hang, or another exception type.
#include <cstdint>
#include <cstdlib>
#include <string>

#include <fmt/format.h>
#include <sys/mman.h>
#include <unistd.h>

#include "backends.hpp"
#include "runtime.hpp"

namespace {

struct Harness {
    hal::Runtime runtime{{fmt::format("fuzz-{}", ::getpid()), 64u << 20, true}};
    hal::LocalBackend backend{runtime};
    hal::Script script{backend};
    // Nothing attaches to this instance by name, and libFuzzer may leave with _Exit (no
    // destructors): drop the name now so no segment outlives the process.
    Harness() { ::shm_unlink(runtime.paths().shm_name.c_str()); }
};

bool allowed(const std::vector<std::string>& words) {
    const auto& cmd = words[0];
    if (cmd == "loadusr" || cmd == "waitusr" || cmd == "source") return false;
    if (cmd == "loadrt" && words.size() > 1 && words[1].find('/') != std::string::npos) return false;
    // Huge instance counts are legal but only slow (they are tested elsewhere).
    for (const auto& w : words)
        if ((w.rfind("count=", 0) == 0 || w.rfind("num_chan=", 0) == 0) && w.size() > 10) return false;
    if (cmd == "advance" && words.size() > 1) {
        char* end = nullptr;
        double s = std::strtod(words[1].c_str(), &end);
        if (!(s <= 0.002)) return false;
    }
    return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    // One instance for the whole run, reset per input; a static so exit removes its segment.
    static Harness harness;
    Harness* h = &harness;
    std::string text(reinterpret_cast<const char*>(data), size);
    std::string line, out;
    auto run = [&](const std::string& logical) {
        try {
            auto words = h->script.tokenize(logical);
            if (words.empty() || !allowed(words)) return;
            h->script.execute(logical, out);
        } catch (const hal::Error&) {
        }
    };
    for (char c : text) {
        if (c != '\n') {
            line += c;
            continue;
        }
        if (!line.empty() && line.back() == '\\') {
            line.back() = ' ';
            continue;
        }
        run(line);
        line.clear();
    }
    run(line);
    out.clear();
    // Start every input from an empty bus so inputs stay independent.
    try {
        h->runtime.execute({"unlock", "all"}, out);
    } catch (const hal::Error&) {
    }
    h->runtime.shutdown();
    return 0;
}
