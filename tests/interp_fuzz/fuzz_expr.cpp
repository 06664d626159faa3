// libFuzzer target: the lexer, the expression evaluator and the block parser on one line of
// text, in both NcStudio dialects.
#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

#include "fuzz_support.hpp"
#include "interp/expr.hpp"
#include "interp/parser.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace interp;
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    const std::string_view line = text.substr(0, text.find('\n'));
    fuzz::FixedMachine machine;
    for (const Dialect* d : {&ncstudio_dialect(), &ncstudio_v54_dialect()}) {
        Variables vars;
        vars.set_numbered(1, 2.5, {});
        std::vector<Token> tokens;
        try {
            Lexer(*d).lex(line, SourceLoc{"fuzz", 1, 0}, tokens, true);
            TokenCursor cur{&tokens, 0};
            ExprEvaluator(*d, vars, machine, "fuzz", 1).evaluate(cur);
        } catch (const Error&) {
        }
        ParsedLine parsed;
        BlockParser parser(*d, vars, machine);
        vars.begin();
        try {
            parser.parse(line, SourceLoc{"fuzz", 1, 0}, parsed);
            vars.commit();
        } catch (const Error&) {
            vars.rollback();
        }
    }
    return 0;
}
