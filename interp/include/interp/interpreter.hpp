#pragma once
// The interpreter's front end: source -> lexer -> block parser (with expressions and variables)
// -> control flow -> BlockExecutor::execute. One instance owns everything it uses; two
// instances can run side by side in one process.
//
// Control flow (S0 §2.3, §3.4, §3.10, §4.2; FEATURES §1.2, §5.1, §5.6):
//   O1234 / O"name" … M17      subprograms; M99 in a subprogram ends it as M17 does
//   G65 P<n|"name"> L<k>       call k times (default 1; L0 calls nothing)
//   M98 P<n> L<k>              the same; a 5–8 digit P without L is count(4)+program(4)
//   M99 P<n>                   in a subprogram: return to the caller at block N n
//   M99 [P<n>] in the main     restart the main program (at N n)
//   M n / G n (n ≤ 99)         run O(200+n) / O(600+n) when public.dat defines it
//   M02 / M30                  passed on to the executor, then the program ends
// Subprograms are looked up in the calling file, then the main file, then public.dat.
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "interp/block.hpp"
#include "interp/cycles.hpp"
#include "interp/dialect.hpp"
#include "interp/flow.hpp"
#include "interp/parser.hpp"
#include "interp/source.hpp"
#include "interp/variables.hpp"

namespace interp {

struct InterpreterOptions {
    const Dialect* dialect = &ncstudio_dialect();
    // Skip blocks that start with '/' (optional block skip, LEX-44 EXT).
    bool block_delete = false;
    // M99 in the main program restarts it (S0 §3.4). A checker turns this off so that a
    // looping program ends after one pass instead of running forever.
    bool main_m99_loops = true;
    // cfg:s_hook_prog (CUS-4 REC): a subprogram (in public.dat, else in the program) run after
    // every block with an S word, e.g. for gear changes. None by default.
    std::optional<std::int64_t> s_hook_program;
    // Where the front end's warnings go (duplicate sequence numbers); none = not reported.
    WarningSink* warnings = nullptr;
};

class Interpreter {
  public:
    Interpreter(BlockExecutor& executor, MachineQuery& machine, InterpreterOptions options = {});
    ~Interpreter();
    Interpreter(const Interpreter&) = delete;
    Interpreter& operator=(const Interpreter&) = delete;

    // The public.dat library (S0 §3.8, §4.2): subprograms every program can call, and the
    // custom M/G codes. Optional; load before or between programs.
    void load_library(const std::string& path);
    void set_library(std::unique_ptr<Source> library);

    // Starts a program (resets the call stack and the variables). The dialect is chosen per
    // program: `dialect` overrides the one in the options for this and later programs.
    void open(const std::string& path, const Dialect* dialect = nullptr);
    void open(std::unique_ptr<Source> program, const Dialect* dialect = nullptr);

    // Interprets one source line. Returns false once the program has ended. Throws Error for a
    // bad line; that line changes nothing, and calling step() again continues with the next
    // line (a checker collects every error this way).
    bool step();
    // Steps to the end; the first error propagates.
    void run();

    bool finished() const { return finished_; }
    int call_depth() const { return static_cast<int>(stack_.size()); }
    Variables& variables() { return vars_; }
    const Dialect& dialect() const { return *options_.dialect; }

  private:
    void execute_line(const SourceLoc& loc);
    void handle_label(const SourceLoc& loc);
    std::optional<CallFrame> resolve_call(const CallRequest& call);
    bool custom_code_active(int code) const;
    void collect_custom_codes(Block& b, bool has_call);
    void queue_s_hook(const Block& b);
    // What a block does to the custom cycles, committed only once the block has run.
    struct CustomCyclePlan {
        cycles::CustomCycles next;                     // their modal data after the block
        std::optional<cycles::CustomCycles::Run> run;  // the O(600+n) run the block asks for
    };
    bool custom_cycle_involved() const;
    std::optional<cycles::CustomCycles::Run> plan_custom_cycle(Block& b,
                                                               cycles::CustomCycles& next);
    void set_fixed_cycle_vars(const cycles::CustomCycles::Run& run, const SourceLoc& loc);
    void handle_return(const ReturnRequest& r, const SourcePos& after_call);
    void return_in_main(const ReturnRequest& r, const SourcePos& after_call);
    void return_to_sequence(const ReturnRequest& r, const SourcePos& after_call);
    void push_calls(std::optional<CallFrame>& call_frame, const SourcePos& after_call);
    void end_program(const SourceLoc& loc);
    void report_scan_warnings(const Source& src);
    // Starts (or repeats) a subprogram run: positions at the line after its label.
    void enter(CallFrame& frame);
    // Continues after a finished run: a queued run of the same block, or the caller.
    void resume_after(const CallFrame& done);

    BlockExecutor& executor_;
    MachineQuery& machine_;
    InterpreterOptions options_;
    Variables vars_;
    BlockParser parser_;
    ParsedLine parsed_;
    std::unique_ptr<Source> main_;
    std::unique_ptr<Source> library_;
    std::vector<CallFrame> stack_;
    std::vector<CustomCall> customs_;                  // custom codes of the current block
    cycles::CustomCycles custom_cycles_;  // public.dat canned cycles and their modal data
    CustomCyclePlan cycle_plan_;          // the current block's, when it involves one
    Source* current_ = nullptr;
    bool finished_ = true;
    bool main_started_ =
        false;  // a block of the main program has run (a leading O label is a name)
};

}  // namespace interp
