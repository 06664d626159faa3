// libFuzzer target: whole programs through the front end AND the back end (modal state,
// transforms, cycles, cutter compensation, canonical output and its text form), stepping on
// after errors like `cnc check`. Besides crashes and sanitizer reports it traps on a canonical
// command whose text shows a non-finite number, since bad input must never reach motion.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "fuzz_support.hpp"
#include "interp/canon.hpp"
#include "interp/executor.hpp"
#include "interp/interpreter.hpp"

namespace {


bool has_non_finite(std::string_view text) {
    for (std::string_view bad : {" nan", " -nan", " inf", " -inf", "=nan", "=inf", "=-inf"}) {
        const std::size_t at = text.find(bad);
        if (at == std::string_view::npos) continue;
        const std::size_t end = at + bad.size();
        if (end == text.size() || text[end] == ' ' || text[end] == ',' || text[end] == ')')
            return true;
    }
    return false;
}

class CheckingSink : public interp::CanonSink {
  public:
    void emit(const interp::Canon& c) override {
        const std::string text = interp::to_text(c);
        // Messages and warnings quote text, which may legitimately say "inf".
        if (text.find('"') == std::string::npos && has_non_finite(text)) std::abort();
    }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace interp;
    CheckingSink sink;
    BackendConfig cfg;
    cfg.default_feed_mm_s = 10.0;
    cfg.v54_compat = (size % 3) == 0;
    InterpreterOptions options;
    options.main_m99_loops = false;
    options.dialect = cfg.v54_compat ? &ncstudio_v54_dialect() : &ncstudio_dialect();
    try {
        Executor exec(sink, cfg);
        Interpreter in(exec, exec, options);
        fuzz::run_input(in, data, size);
    } catch (const Error&) {
    }
    return 0;
}
