// show / list / save: the read-only views of the bus, in LinuxCNC's columns.
#include <algorithm>

#include <fmt/format.h>

#include "runtime.hpp"
#include "thread.hpp"

namespace hal {

namespace {
std::string_view arrow(Dir d) {
    switch (d) {
        case Dir::In: return "<==";
        case Dir::Out: return "==>";
        case Dir::IO: return "<=>";
    }
    return "";
}
std::string_view state_name(InstanceState s) {
    switch (s) {
        case InstanceState::Configured: return "configured";
        case InstanceState::Running: return "running";
        case InstanceState::Stopped: return "stopped";
    }
    return "";
}
}  // namespace

void Runtime::show_comps(const std::vector<std::string>& pats, std::string& out) const {
    out += "Loaded HAL Components:\n";
    out += fmt::format("{:>6}  {:<4}  {:<32} {:>7}  {}\n", "ID", "Type", "Name", "PID", "State");
    for (auto& c : components_) {
        if (!name_matches(pats, c->name)) continue;
        if (!c->realtime) {
            out += fmt::format("{:>6}  {:<4}  {:<32} {:>7}  {}\n", c->id, "User", c->name, c->pid,
                               c->ready ? "ready" : "initializing");
            continue;
        }
        out += fmt::format("{:>6}  {:<4}  {:<32} {:>7}  {}\n", c->id, "RT", c->name, "", "ready");
        for (auto& inst : c->instances)
            out += fmt::format("{:>6}  {:<4}    {:<30} {:>7}  {}\n", "", "", inst->name, "",
                               inst->object->faulted() ? "fault" : state_name(inst->state));
    }
}

void Runtime::show_pins(const std::vector<std::string>& pats, std::string& out) const {
    out += "Component Pins:\n";
    out += fmt::format("{:>6}  {:<5} {:<4} {:>18}  {}\n", "Owner", "Type", "Dir", "Value", "Name");
    for (auto& [name, p] : pins_) {
        if (!name_matches(pats, name)) continue;
        // A thread's `.time` pin has no owner component (LinuxCNC's is its threads module).
        out += fmt::format("{:>6}  {:<5} {:<4} {:>18}  {}", p->component ? p->component->id : 0, to_string(p->type),
                           to_string(p->dir), format_value(p->type, read_pin(*p), true), name);
        if (p->signal) out += fmt::format(" {} {}", arrow(p->dir), p->signal->name);
        out += "\n";
    }
}

void Runtime::show_params(const std::vector<std::string>& pats, std::string& out) const {
    out += "Parameters:\n";
    out += fmt::format("{:>6}  {:<5} {:<4} {:>18}  {}\n", "Owner", "Type", "Dir", "Value", "Name");
    for (auto& [name, p] : params_) {
        if (!name_matches(pats, name)) continue;
        out += fmt::format("{:>6}  {:<5} {:<4} {:>18}  {}\n", p->component ? p->component->id : 0,
                           to_string(p->type), to_string(p->dir),
                           format_value(p->type, *segment_->at<Value>(p->slot), true), name);
    }
}

void Runtime::show_signals(const std::vector<std::string>& pats, std::string& out) const {
    out += "Signals:\n";
    out += fmt::format("{:<5} {:>18}  {}\n", "Type", "Value", "Name     (linked to)");
    for (auto& [name, s] : signals_) {
        if (!name_matches(pats, name)) continue;
        out += fmt::format("{:<5} {:>18}  {}\n", to_string(s->type),
                           format_value(s->type, *segment_->at<Value>(s->slot), true), name);
        // The writer first, then readers and I/O pins, as LinuxCNC lists them.
        std::vector<Pin*> ordered = s->pins;
        std::stable_partition(ordered.begin(), ordered.end(), [](Pin* p) { return p->dir == Dir::Out; });
        for (Pin* p : ordered)
            out += fmt::format("{:>28} {}\n", p->dir == Dir::Out ? "<==" : p->dir == Dir::In ? "==>" : "<=>",
                               p->name);
    }
}

void Runtime::show_functs(const std::vector<std::string>& pats, std::string& out) const {
    out += "Exported Functions:\n";
    out += fmt::format("{:>6}  {:<3}  {:>5}  {}\n", "Owner", "FP", "Users", "Name");
    for (auto& [name, f] : functs_) {
        if (!name_matches(pats, name)) continue;
        out += fmt::format("{:>6}  {:<3}  {:>5}  {}\n", f->component->id, f->uses_fp ? "YES" : "NO",
                           f->users.size(), name);
    }
}

void Runtime::show_threads(const std::vector<std::string>& pats, std::string& out) const {
    out += fmt::format("Realtime Threads (clock: {}):\n", sim_clock_ ? "simulated" : "real-time");
    out += fmt::format("{:>11}  {:<3}  {:<20} ({:>9}, {:>9} ) {}\n", "Period", "FP", "Name", "Time", "Max-Time",
                       "wake-up error ns: p50 p99 p99.9 max, late cycles");
    for (Thread* t : thread_order_) {
        if (!name_matches(pats, t->name())) continue;
        auto& st = t->stats();
        // Percentiles from the histogram: each is the floor of its bucket (12.5 % resolution).
        std::uint64_t total = 0;
        for (auto c : st.histogram) total += c;
        auto percentile = [&](double q) -> std::int64_t {
            if (total == 0) return 0;
            auto want = static_cast<std::uint64_t>(q * static_cast<double>(total));
            std::uint64_t seen = 0;
            for (int b = 0; b < kHistogramBuckets; ++b) {
                seen += st.histogram[b];
                if (seen > want) return histogram_bucket_floor(b);
            }
            return histogram_bucket_floor(kHistogramBuckets - 1);
        };
        out += fmt::format("{:>11}  {:<3}  {:<20} ({:>9}, {:>9} ) {} {} {} {}, {}\n", t->period_ns(),
                           t->uses_fp() ? "YES" : "NO", t->name(), t->time_ns(), st.tmax.s32, percentile(0.5),
                           percentile(0.99), percentile(0.999), st.wakeup_max_ns, st.late_cycles);
        int n = 1;
        for (Funct* f : t->functs()) out += fmt::format("{:>19} {}\n", n++, f->name);
    }
}

void Runtime::show_aliases(const std::vector<std::string>& pats, std::string& out) const {
    out += "Aliases:\n";
    out += fmt::format("{:<32} {}\n", "Alias", "Original Name");
    for (auto& [alias, real] : aliases_)
        if (name_matches(pats, alias) || name_matches(pats, real)) out += fmt::format("{:<32} {}\n", alias, real);
}

void Runtime::cmd_show(const std::vector<std::string>& a, std::string& out) {
    static const std::vector<std::string> kinds = {"comp", "pin", "sig", "signal", "param", "parameter",
                                                   "funct", "function", "thread", "alias", "all"};
    std::string kind = "all";
    std::vector<std::string> pats;
    if (!a.empty()) {
        if (std::find(kinds.begin(), kinds.end(), a[0]) != kinds.end()) {
            kind = a[0];
            pats.assign(a.begin() + 1, a.end());
        } else {
            pats = a;
        }
    }
    bool all = kind == "all";
    if (all || kind == "comp") show_comps(pats, out);
    if (all || kind == "pin") show_pins(pats, out);
    if (all || kind == "param" || kind == "parameter") show_params(pats, out);
    if (all || kind == "sig" || kind == "signal") show_signals(pats, out);
    if (all || kind == "funct" || kind == "function") show_functs(pats, out);
    if (all || kind == "thread") show_threads(pats, out);
    if (kind == "alias") show_aliases(pats, out);
}

void Runtime::cmd_list(const std::vector<std::string>& a, std::string& out) {
    static const std::vector<std::string> kinds = {"comp", "pin", "sig", "param", "funct", "thread", "alias"};
    if (std::find(kinds.begin(), kinds.end(), a[0]) == kinds.end())
        throw Error(fmt::format("list takes one of comp, pin, sig, param, funct, thread, alias; not '{}'", a[0]));
    std::vector<std::string> pats(a.begin() + 1, a.end());
    std::vector<std::string> hits;
    for (auto& n : names(a[0]))
        if (name_matches(pats, n)) hits.push_back(n);
    out += fmt::format("{}\n", fmt::join(hits, " "));
}

void Runtime::save_to(const std::string& what, std::string& out) const {
    bool all = what == "all";
    if (all || what == "thread") {
        for (Thread* t : thread_order_)
            out += fmt::format("newthread {} {} {}{}\n", t->name(), t->period_ns(), t->uses_fp() ? "fp" : "nofp",
                               t->cpu() >= 0 ? fmt::format(" cpu={}", t->cpu()) : "");
    }
    if (all || what == "comp") {
        for (auto& c : components_) {
            if (!c->realtime) continue;
            for (auto& args : c->load_args)
                out += fmt::format("loadrt {}{}{}\n", c->name, args.empty() ? "" : " ", fmt::join(args, " "));
        }
    }
    if (all || what == "alias") {
        for (auto& [alias, real] : aliases_)
            out += fmt::format("alias {} {} {}\n", pins_.count(real) ? "pin" : "param", real, alias);
    }
    if (all || what == "sig") {
        for (auto& [name, s] : signals_)
            if (what == "sig" || s->pins.empty()) out += fmt::format("newsig {} {}\n", name, to_string(s->type));
    }
    if (what == "link" || what == "linka") {
        for (auto& [name, p] : pins_)
            if (p->signal)
                out += what == "linka" ? fmt::format("linkps {} {} {}\n", name, arrow(p->dir), p->signal->name)
                                       : fmt::format("linkps {} {}\n", name, p->signal->name);
    }
    if (all || what == "net" || what == "neta") {
        for (auto& [name, s] : signals_) {
            if (s->pins.empty()) continue;
            std::vector<Pin*> ordered = s->pins;
            std::stable_partition(ordered.begin(), ordered.end(), [](Pin* p) { return p->dir == Dir::Out; });
            out += fmt::format("net {}", name);
            for (Pin* p : ordered) out += fmt::format(" {}", p->name);
            out += "\n";
        }
    }
    if (all || what == "param") {
        for (auto& [name, p] : params_)
            if (p->dir == ParamDir::RW && p->component && !p->timing)
                out += fmt::format("setp {} {}\n", name, format_value(p->type, *segment_->at<Value>(p->slot)));
        // Unlinked input pins hold values a config set with setp; saving them keeps the machine.
        for (auto& [name, p] : pins_)
            if (p->dir != Dir::Out && !p->signal && p->component->realtime)
                out += fmt::format("setp {} {}\n", name, format_value(p->type, read_pin(*p)));
        for (auto& [name, s] : signals_)
            if (!s->writer()) out += fmt::format("sets {} {}\n", name, format_value(s->type, *segment_->at<Value>(s->slot)));
    }
    if (all || what == "thread") {
        for (Thread* t : thread_order_)
            for (Funct* f : t->functs()) out += fmt::format("addf {} {}\n", f->name, t->name());
    }
}

void Runtime::cmd_save(const std::vector<std::string>& a, std::string& out) {
    static const std::vector<std::string> kinds = {"all", "comp", "alias", "sig", "link", "linka",
                                                   "net", "neta", "param", "thread"};
    std::string what = a.empty() ? "all" : a[0];
    if (std::find(kinds.begin(), kinds.end(), what) == kinds.end())
        throw Error(fmt::format("save takes one of {}; not '{}'", fmt::join(kinds, ", "), what));
    save_to(what, out);
}

}  // namespace hal
