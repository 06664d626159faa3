// libFuzzer target: whole programs through the Interpreter (source, parser, control flow),
// stepping on after errors the way `cnc check` does. A step budget bounds endless loops
// (G65 … L99999999, M99 P…) that are legal programs.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "fuzz_support.hpp"
#include "interp/interpreter.hpp"

namespace {
constexpr char kLibrary[] =
    "O203\nM901 H2 P1\nG04 P5\nM03\nM17\n"
    "O686\n#FC50=#FIXEDCYCLE_BACK\nIF(!#FC13)G90 G65 P786\nIF(#FC13)G91 G65 P786 L=#FC11\nM17\n"
    "O786\nG00 X=#FC1 Y=#FC2\nG65 P886 L=INT(ABS(#FC4-#FC3) /ABS (#FC5)) -1\nM17\n"
    "O886\nG91 G00 Z=#FC50\nM17\n";
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace interp;
    interp::fuzz::FixedMachine machine;
    interp::fuzz::AcceptingExecutor exec;
    InterpreterOptions options;
    options.main_m99_loops = (size % 2) == 0;
    options.dialect = (size % 3) == 0 ? &ncstudio_v54_dialect() : &ncstudio_dialect();
    try {
        Interpreter in(exec, machine, options);
        in.set_library(Source::from_string("public.dat", kLibrary));
        fuzz::run_input(in, data, size);
    } catch (const Error&) {
        // A program the source indexer rejects (duplicate labels) never starts.
    }
    return 0;
}
