#pragma once
// Control-flow words of a block and the call stack they act on. take_flow_words() is a pure
// function of one parsed line, so the rules of G65/M98/M17/M99 can be tested without sources.
#include <cstdint>
#include <optional>
#include <string>

#include "interp/block.hpp"
#include "interp/dialect.hpp"
#include "interp/parser.hpp"
#include "interp/source.hpp"

namespace interp {

// A subprogram call: by number or (when `name` is set) by name, `count` times.
struct CallRequest {
    std::int64_t program = -1;
    std::optional<std::string> name;
    std::int64_t count = 1;
    SourceLoc loc;  // the call word
};

// M17, or M99 with an optional target sequence number.
struct ReturnRequest {
    int m = 17;
    std::optional<std::int64_t> sequence;
    SourceLoc loc;
};

struct FlowWords {
    std::optional<CallRequest> call;
    std::optional<ReturnRequest> ret;
};

// Removes G65 / M98 (with their P and L) and M17 / M99 (with M99's P) from line.block and
// returns them. Throws Error for malformed or conflicting control words.
FlowWords take_flow_words(ParsedLine& line, const Dialect& dialect);

// "O9001" or "O\"name\"" for messages.
std::string program_label(std::int64_t number, const std::optional<std::string>& name);

// One active (or queued) subprogram run.
struct CallFrame {
    Source* source = nullptr;  // where the subprogram is defined
    SourcePos body;            // its first line after the label
    Source* return_source = nullptr;
    SourcePos return_pos;        // the line after the calling block
    std::int64_t remaining = 1;  // runs left, including the current one
    std::string label;           // "O9001", for messages
    int custom_code = -1;        // public.dat code it implements (see kCustomGFlag)
    bool started = false;        // queued frames (several custom codes in one block) wait
};

// CallFrame::custom_code of public.dat custom code G n is kCustomGFlag + n; of M n it is n; the
// S-word hook (InterpreterOptions::s_hook_program) is kSHookCode.
constexpr int kCustomGFlag = 1000;
constexpr int kSHookCode = 2000;

// A public.dat call produced by a custom M or G code of a block, queued behind the block.
struct CustomCall {
    int code = 0;  // M n -> n, G n -> kCustomGFlag + n, S hook -> kSHookCode
    std::int64_t program = 0;
    LabelSite site;
    Source* source = nullptr;  // where the subprogram is defined
};

}  // namespace interp
