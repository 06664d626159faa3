#include "interp/interpreter.hpp"

#include <algorithm>
#include <array>
#include <string>

#include "interp/text.hpp"

namespace interp {

namespace {

// G codes that may stand in a block that re-runs an active custom cycle (×10, as in Block::g):
// planes, units, distance mode, feed mode, return level.
bool cycle_neutral_g(int g) {
    constexpr std::array<int, 12> kNeutral = {170, 180, 190, 200, 210, 700,
                                              710, 900, 910, 940, 980, 990};
    return std::find(kNeutral.begin(), kNeutral.end(), g) != kNeutral.end();
}

bool starts_with_slash(std::string_view line) {
    for (char c : line) {
        if (is_space(c)) continue;
        return c == '/';
    }
    return false;
}

// Sequence number at the start of a line ("  N0120 G1 …" -> 120), if any.
std::optional<std::int64_t> leading_sequence(std::string_view line) {
    std::size_t i = 0;
    while (i < line.size() && (is_space(line[i]) || line[i] == '/')) ++i;
    if (i >= line.size() || to_upper(line[i]) != 'N') return std::nullopt;
    ++i;
    while (i < line.size() && is_space(line[i])) ++i;
    if (i >= line.size() || !is_digit(line[i])) return std::nullopt;
    std::int64_t n = 0;
    while (i < line.size() && is_digit(line[i]) && n < (std::int64_t{1} << 50)) {
        n = n * 10 + (line[i] - '0');
        ++i;
    }
    return n;
}

bool is_label_line(std::string_view line) {
    std::size_t i = 0;
    while (i < line.size() && is_space(line[i])) ++i;
    if (i + 1 >= line.size() || to_upper(line[i]) != 'O') return false;
    return is_digit(line[i + 1]) || quote_length(line.substr(i + 1)) != 0;
}

// Searches `src` from `from` for a line starting with N `seq`, stopping at the next subprogram
// label (the end of the current program) or at `stop` when given.
std::optional<SourcePos> find_sequence(Source& src, SourcePos from, std::int64_t seq,
                                       std::optional<std::uint64_t> stop) {
    src.seek(from);
    std::string_view line;
    bool first = true;
    while (src.next_line(line)) {
        const SourcePos at = src.line_start();
        if (stop && at.offset >= *stop) return std::nullopt;
        if (is_label_line(line) && !first) return std::nullopt;
        first = false;
        if (leading_sequence(line) == seq) return at;
    }
    return std::nullopt;
}

}  // namespace

Interpreter::Interpreter(BlockExecutor& executor, MachineQuery& machine, InterpreterOptions options)
    : executor_(executor),
      machine_(machine),
      options_(options),
      parser_(*options.dialect, vars_, machine) {}

Interpreter::~Interpreter() = default;

void Interpreter::load_library(const std::string& path) {
    set_library(Source::open_file(path));
}

void Interpreter::set_library(std::unique_ptr<Source> library) {
    library_ = std::move(library);
    report_scan_warnings(*library_);
}

// LEX-07 allows a sequence number twice, but an M99 P search then stops at the first one.
void Interpreter::report_scan_warnings(const Source& src) {
    if (options_.warnings == nullptr) return;
    for (const DuplicateSequence& d : src.duplicate_sequences())
        options_.warnings->warning(
            SourceLoc{src.name(), d.line, d.col},
            "sequence number N" + std::to_string(d.n) +
                " is used twice in this program; M99 P and searches find the first one");
}

void Interpreter::open(const std::string& path, const Dialect* dialect) {
    open(Source::open_file(path), dialect);
}

void Interpreter::open(std::unique_ptr<Source> program, const Dialect* dialect) {
    if (dialect != nullptr) {
        options_.dialect = dialect;
        parser_.set_dialect(*dialect);
    }
    main_ = std::move(program);
    report_scan_warnings(*main_);
    current_ = main_.get();
    stack_.clear();
    vars_.clear();
    finished_ = false;
    main_started_ = false;
}

void Interpreter::run() {
    while (step()) {
    }
}

bool Interpreter::step() {
    if (finished_) return false;
    std::string_view line;
    if (!current_->next_line(line)) {
        const SourceLoc eof{current_->name(), current_->line_number() + 1, 1};
        if (!stack_.empty()) {
            const std::string label = stack_.back().label;
            finished_ = true;
            stack_.clear();
            throw Error(eof, "subprogram " + label + " ends without M17");
        }
        end_program(eof);
        return false;
    }
    const SourceLoc loc{current_->name(), current_->line_number(), 1};
    if (options_.block_delete && starts_with_slash(line)) return true;
    vars_.begin();
    try {
        parser_.parse(line, loc, parsed_);
        execute_line(parsed_.block.loc);
        for (const Variables::NamedWrite& w : vars_.pending_named_writes())
            machine_.write_setting(w.name, w.value);
        vars_.commit();
    } catch (...) {
        vars_.rollback();
        throw;
    }
    return !finished_;
}

void Interpreter::end_program(const SourceLoc& loc) {
    finished_ = true;
    stack_.clear();
    executor_.end_of_input(loc);
}

void Interpreter::execute_line(const SourceLoc& loc) {
    ParsedLine& line = parsed_;
    if (line.is_label) {
        handle_label(loc);
        return;
    }
    if (stack_.empty()) main_started_ = true;

    FlowWords flow = take_flow_words(line, *options_.dialect);
    Block& b = line.block;

    // Resolve everything that can fail before the block runs: a rejected block changes nothing.
    std::optional<CallFrame> call_frame;
    if (flow.call) call_frame = resolve_call(*flow.call);
    customs_.clear();
    if (options_.s_hook_program && b.has('S') && !custom_code_active(kSHookCode)) queue_s_hook(b);
    if (library_) collect_custom_codes(b, flow.call.has_value());
    // Most blocks neither call nor continue a public.dat cycle: they skip its planning and the
    // copy of its modal data.
    const bool cycle_planned = custom_cycle_involved();
    if (cycle_planned) {
        cycle_plan_.next = custom_cycles_;
        cycle_plan_.run = plan_custom_cycle(b, cycle_plan_.next);
    }
    const Dialect& d = *options_.dialect;
    const std::size_t new_frames = (call_frame ? 1 : 0) + customs_.size();
    if (stack_.size() + new_frames > static_cast<std::size_t>(d.max_call_depth)) {
        throw Error(
            flow.call ? flow.call->loc : loc,
            "subprogram calls nested deeper than " + std::to_string(d.max_call_depth) + " levels");
    }

    if (!b.empty()) executor_.execute(b);
    if (b.has_m(2) || b.has_m(30)) {
        finished_ = true;
        stack_.clear();
        return;
    }
    if (cycle_planned) {
        custom_cycles_ = cycle_plan_.next;
        if (cycle_plan_.run) set_fixed_cycle_vars(*cycle_plan_.run, loc);
    }

    const SourcePos after_call = current_->tell();
    if (flow.ret) {
        handle_return(*flow.ret, after_call);
        return;
    }
    if (call_frame || !customs_.empty()) push_calls(call_frame, after_call);
}

void Interpreter::handle_label(const SourceLoc& loc) {
    if (stack_.empty()) {
        // A label before any block names the main program; after blocks it is the first
        // subprogram, which the main program must not run into (S0 §3.12 ex. 5).
        if (main_started_) end_program(loc);
        return;
    }
    const std::string label = stack_.back().label;
    finished_ = true;
    stack_.clear();
    throw Error(loc, "subprogram " + label + " runs into the next label without M17");
}

std::optional<CallFrame> Interpreter::resolve_call(const CallRequest& c) {
    const std::string label = program_label(c.program, c.name);
    for (Source* s : {current_, main_.get(), library_.get()}) {
        if (s == nullptr) continue;
        const std::optional<LabelSite> site =
            c.name ? s->find_label(*c.name) : s->find_label(c.program);
        if (!site) continue;
        if (c.count == 0) return std::nullopt;
        CallFrame f;
        f.source = s;
        f.body = site->pos;
        f.remaining = c.count;
        f.label = label;
        return f;
    }
    throw Error(c.loc, "subprogram " + label + " not found");
}

bool Interpreter::custom_code_active(int code) const {
    // Only runs that have started: a code queued behind the running one is not "inside" it.
    for (const CallFrame& f : stack_)
        if (f.started && f.custom_code == code) return true;
    return false;
}

void Interpreter::collect_custom_codes(Block& b, bool has_call) {
    const Dialect& d = *options_.dialect;
    for (std::size_t i = 0; i < b.m.size();) {
        const int m = b.m[i];
        std::optional<LabelSite> site;
        if (m <= d.custom_code_max && !custom_code_active(m))
            site = library_->find_label(d.custom_m_base + m);
        if (!site) {
            ++i;
            continue;
        }
        customs_.push_back(CustomCall{m, d.custom_m_base + m, *site, library_.get()});
        b.m.erase_at(i);
        b.m_col.erase_at(i);
    }
    for (std::size_t i = 0; i < b.g.size();) {
        const int g = b.g[i];
        const int n = g / 10;
        std::optional<LabelSite> site;
        if (g % 10 == 0 && n <= d.custom_code_max && !custom_code_active(kCustomGFlag + n))
            site = library_->find_label(d.custom_g_base + n);
        if (!site) {
            ++i;
            continue;
        }
        if (has_call) {
            throw Error(SourceLoc{b.loc.file, b.loc.line, b.g_col[i]},
                        "custom G" + std::to_string(n) + " and a subprogram call in one block");
        }
        customs_.push_back(
            CustomCall{kCustomGFlag + n, d.custom_g_base + n, *site, library_.get()});
        b.g.erase_at(i);
        b.g_col.erase_at(i);
    }
}

void Interpreter::queue_s_hook(const Block& b) {
    // CUS-4 REC: a configured subprogram runs after every block that sets S (gear changes …),
    // before the block's custom M codes; an S inside the hook does not trigger it again.
    const std::int64_t program = *options_.s_hook_program;
    for (Source* s : {library_.get(), main_.get()}) {
        if (s == nullptr) continue;
        if (const auto site = s->find_label(program)) {
            customs_.push_back(CustomCall{kSHookCode, program, *site, s});
            return;
        }
    }
    throw Error(b.loc_of('S'), "S hook subprogram O" + std::to_string(program) + " not found");
}

// A custom cycle is active, or the block calls a custom G code (which may start one).
bool Interpreter::custom_cycle_involved() const {
    if (custom_cycles_.active()) return true;
    for (const CustomCall& c : customs_)
        if (c.code >= kCustomGFlag && c.code < kSHookCode) return true;
    return false;
}

// Custom canned cycles (CC-19, FC-1/FC-2): the cycles core keeps their modal data; here the
// block's cycle words become #FC values and the block's O(600+n) call is added (a bare position
// re-runs the active cycle) or dropped (K0, no position). Blocks inside a running library cycle
// are ordinary blocks.
std::optional<cycles::CustomCycles::Run> Interpreter::plan_custom_cycle(
    Block& b, cycles::CustomCycles& next) {
    for (const CallFrame& f : stack_)
        if (f.started && f.custom_code >= kCustomGFlag && f.custom_code < kSHookCode)
            return std::nullopt;
    cycles::CustomCycles::BlockInfo info;
    std::size_t call = customs_.size();
    for (std::size_t i = 0; i < customs_.size(); ++i)
        if (customs_[i].code >= kCustomGFlag && customs_[i].code < kSHookCode) {
            call = i;
            info.custom_g = customs_[i].code - kCustomGFlag;
        }
    // Most blocks: no custom cycle called or active; decided before looking at the G codes.
    if (!info.custom_g && !next.active()) return std::nullopt;
    for (const int g : {0, 10, 20, 30, 800}) info.cancels = info.cancels || b.has_g(g);
    for (int n = 73; n <= 89; ++n) info.cancels = info.cancels || b.has_g(n * 10);
    if (!info.custom_g && !info.cancels) {
        // While a custom cycle is active, only a block of positions and modal switches re-runs
        // it; G04 P, G28 X, G92 X … keep their words, as with the built-in cycles.
        for (const int g : b.g)
            if (!cycle_neutral_g(g)) return std::nullopt;
    }

    const auto word = [&](char c) { return b.opt(c); };
    info.words.axis_mm = {word('X'), word('Y'), word('Z')};
    info.words.r_mm = word('R');
    info.words.q_mm = word('Q');
    info.words.p_ms = word('P');
    info.words.k = b.has('K') ? word('K') : word('L');
    info.f = word('F');
    info.ctx.incremental = b.has_g(910) || (!b.has_g(900) && machine_.incremental_mode());
    info.ctx.return_to_r = b.has_g(990) || (!b.has_g(980) && machine_.cycle_return_to_r());
    const double unit = machine_.mm_per_program_unit();
    for (int a = 0; a < 3; ++a) info.ctx.position_mm[a] = machine_.work_pos_mm(Axis(a)) / unit;
    std::optional<cycles::CustomCycles::Run> run;
    try {
        run = next.block(info);
    } catch (const cycles::CycleError& e) {
        throw Error(b.loc, e.what());
    }
    if (!info.custom_g && !next.active()) return std::nullopt;  // cancelled by this block
    // The cycle words belong to the library cycle, not to a move of this block.
    for (const char c : {'X', 'Y', 'Z', 'R', 'Q', 'P', 'F', 'K', 'L'}) b.words[letter_index(c)].reset();
    if (run && call == customs_.size()) {
        const Dialect& d = *options_.dialect;
        const std::int64_t program = d.custom_g_base + run->g;
        if (const auto site = library_->find_label(program))
            customs_.push_back(CustomCall{kCustomGFlag + run->g, program, *site, library_.get()});
    } else if (!run && call < customs_.size()) {
        customs_.erase(customs_.begin() + static_cast<std::ptrdiff_t>(call));
    }
    return run;
}

void Interpreter::set_fixed_cycle_vars(const cycles::CustomCycles::Run& run, const SourceLoc& loc) {
    for (int fc = 1; fc <= 14; ++fc) vars_.set_fixed_cycle(fc, run.fc[fc], loc);
}

void Interpreter::handle_return(const ReturnRequest& r, const SourcePos& after_call) {
    if (stack_.empty()) {
        return_in_main(r, after_call);
        return;
    }
    CallFrame& top = stack_.back();
    if (r.sequence) {
        return_to_sequence(r, after_call);
        return;
    }
    if (--top.remaining > 0) {
        enter(top);
        return;
    }
    const CallFrame done = top;
    stack_.pop_back();
    resume_after(done);
}

void Interpreter::return_in_main(const ReturnRequest& r, const SourcePos& after_call) {
    if (r.m != 99) {
        // M17-1 REC: M17 in a main program ends it as M30 does, with a warning.
        if (options_.warnings != nullptr)
            options_.warnings->warning(r.loc, "M" + std::to_string(r.m) +
                                                  " in the main program ends it as M30 does");
        Block end;
        end.loc = r.loc;
        end.m.push_back(30);
        end.m_col.push_back(r.loc.col);
        finished_ = true;
        stack_.clear();
        executor_.execute(end);
        return;
    }
    if (!options_.main_m99_loops) {
        end_program(r.loc);
        return;
    }
    // S0 §3.4: M99 in the main program returns to its start (or to N n, SUB-8).
    SourcePos target{};
    if (r.sequence) {
        const auto at = find_sequence(*main_, SourcePos{}, *r.sequence, std::nullopt);
        if (!at) {
            main_->seek(after_call);
            throw Error(r.loc, "M99 P" + std::to_string(*r.sequence) + ": no block N" +
                                   std::to_string(*r.sequence) + " in the main program");
        }
        target = *at;
    }
    main_->seek(target);
    main_started_ = false;
}

void Interpreter::return_to_sequence(const ReturnRequest& r, const SourcePos& after_call) {
    // SUB-7: return to the caller at N n, searching forward from the call, then from the start
    // of the calling program.
    const CallFrame done = stack_.back();
    stack_.pop_back();
    Source& caller = *done.return_source;
    const SourcePos caller_start = stack_.empty() ? SourcePos{} : stack_.back().body;
    std::optional<SourcePos> at = find_sequence(caller, done.return_pos, *r.sequence, std::nullopt);
    if (!at) at = find_sequence(caller, caller_start, *r.sequence, done.return_pos.offset);
    if (!at) {
        stack_.push_back(done);
        current_->seek(after_call);
        throw Error(r.loc, "M99 P" + std::to_string(*r.sequence) + ": no block N" +
                               std::to_string(*r.sequence) + " in the calling program");
    }
    // Queued calls of the same block are dropped: control left that block for good.
    while (!stack_.empty() && !stack_.back().started) stack_.pop_back();
    current_ = &caller;
    current_->seek(*at);
}

void Interpreter::push_calls(std::optional<CallFrame>& call_frame, const SourcePos& after_call) {
    // Queue so that the written call runs first, then the custom codes in written order.
    for (std::size_t i = customs_.size(); i-- > 0;) {
        const CustomCall& cc = customs_[i];
        CallFrame f;
        f.source = cc.source;
        f.body = cc.site.pos;
        f.return_source = current_;
        f.return_pos = after_call;
        f.label = program_label(cc.program, std::nullopt);
        f.custom_code = cc.code;
        stack_.push_back(f);
    }
    if (call_frame) {
        call_frame->return_source = current_;
        call_frame->return_pos = after_call;
        stack_.push_back(*call_frame);
    }
    enter(stack_.back());
}

void Interpreter::enter(CallFrame& frame) {
    frame.started = true;
    current_ = frame.source;
    current_->seek(frame.body);
    std::string_view label_line;
    current_->next_line(label_line);  // the O label itself
}

void Interpreter::resume_after(const CallFrame& done) {
    if (!stack_.empty() && !stack_.back().started) {
        enter(stack_.back());
        return;
    }
    current_ = done.return_source;
    current_->seek(done.return_pos);
}

}  // namespace interp
