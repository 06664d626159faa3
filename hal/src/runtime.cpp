#include "runtime.hpp"

#include <dlfcn.h>
#include <fnmatch.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <set>

#include <fmt/format.h>

#include "ring.hpp"
#include "thread.hpp"

#ifndef CNC_COMPONENT_DIR
#define CNC_COMPONENT_DIR ""
#endif

namespace hal {

// ---------------------------------------------------------------------------------------
// Construction context: what the registration functions need while loadrt builds instances.

namespace detail {
thread_local InstanceContext* InstanceContext::current = nullptr;
InstanceContext* current_context() { return InstanceContext::current; }
}  // namespace detail

// Everything one loadrt line registered, so a failure can give it all back.
struct LoadTransaction {
    explicit LoadTransaction(Runtime& runtime) : rt(runtime) {}
    Runtime& rt;
    std::vector<std::string> pins, params, functs, streams;
    std::vector<std::pair<std::uint64_t, std::size_t>> blocks;  // segment allocations

    std::uint64_t allocate(std::size_t bytes) {
        auto off = rt.segment_->allocate(bytes);
        blocks.emplace_back(off, bytes);
        return off;
    }
    void rollback() {
        for (auto& n : pins) rt.pins_.erase(n);
        for (auto& n : params) rt.params_.erase(n);
        for (auto& n : functs) rt.functs_.erase(n);
        for (auto& n : streams) rt.streams_.erase(n);
        for (auto& [off, bytes] : blocks) rt.segment_->release(off, bytes);
    }
};

namespace {
detail::InstanceContext& context_of(Instance& owner, std::string_view what) {
    auto* ctx = detail::current_context();
    if (!ctx) throw Error(fmt::format("{} registered outside loadrt (only constructors may)", what));
    return *ctx;
}

void check_item_name(std::string_view name) {
    if (!name.empty() && name[0] == '=') name.remove_prefix(1);
    if (name.empty()) throw Error("empty pin or parameter name");
    for (char c : name)
        if (std::isspace(static_cast<unsigned char>(c)) || c == '#' || c == '"')
            throw Error(fmt::format("invalid character in name '{}'", name));
}

Value& own_value(Segment& seg, const Pin& p) { return seg.at<PinCell>(p.cell)->own; }
}  // namespace

// Instance -------------------------------------------------------------------------------

Instance::Instance() : ctx_(detail::current_context()) {
    if (!ctx_) throw Error("hal::Instance constructed outside loadrt");
}
Instance::~Instance() = default;
std::string_view Instance::name() const noexcept { return ctx_->name; }
int Instance::index() const noexcept { return ctx_->index; }

std::optional<std::string> Instance::arg(std::string_view key) const {
    auto it = ctx_->args.find(std::string(key));
    if (it == ctx_->args.end()) return std::nullopt;
    // A comma list gives one item per instance; a single item applies to every instance.
    std::vector<std::string> items;
    std::string item;
    for (char c : it->second) {
        if (c == ',') {
            items.push_back(item);
            item.clear();
        } else {
            item += c;
        }
    }
    items.push_back(item);
    if (items.size() == 1) return items[0];
    if (static_cast<std::size_t>(ctx_->index) < items.size() && !items[ctx_->index].empty())
        return items[ctx_->index];
    return std::nullopt;
}

long Instance::arg_int(std::string_view key, long fallback) const {
    auto v = arg(key);
    if (!v) return fallback;
    char* end = nullptr;
    errno = 0;
    long x = std::strtol(v->c_str(), &end, 0);
    if (v->empty() || *end || errno)
        throw Error(fmt::format("argument {}={}: not an integer", key, *v));
    return x;
}

namespace {
// Every instance allocation carries a 16-byte header saying where it came from, so delete
// needs no runtime: arena memory is released with the runtime, heap memory at once.
constexpr std::size_t kInstanceHeader = 16;
}  // namespace

void* Runtime::Arena::allocate(std::size_t bytes) {
    bytes = (bytes + 63) & ~std::size_t{63};  // whole cache lines: no two instances share one
    if (chunks.empty() || used + bytes > capacity) {
        capacity = std::max<std::size_t>(bytes, 256 * 1024);
        chunks.push_back(std::make_unique<std::byte[]>(capacity + 64));
        used = 0;
    }
    auto base = reinterpret_cast<std::uintptr_t>(chunks.back().get());
    auto aligned = (base + 63) & ~std::uintptr_t{63};
    void* p = reinterpret_cast<void*>(aligned + used);
    used += bytes;
    return p;
}

void* Instance::operator new(std::size_t size) {
    auto* ctx = detail::current_context();
    std::byte* block;
    if (ctx) {
        // The header sits just before the object; the object starts on a cache line.
        block = static_cast<std::byte*>(ctx->runtime->instance_arena_.allocate(size + 64)) + 64 - kInstanceHeader;
    } else {
        block = static_cast<std::byte*>(::operator new(size + kInstanceHeader));
    }
    *reinterpret_cast<bool*>(block) = ctx != nullptr;
    return block + kInstanceHeader;
}

void Instance::operator delete(void* p) noexcept {
    if (!p) return;
    auto* block = static_cast<std::byte*>(p) - kInstanceHeader;
    if (!*reinterpret_cast<bool*>(block)) ::operator delete(block);
}

void Instance::raise_fault() noexcept { fault_.store(true, std::memory_order_relaxed); }
void Instance::clear_fault() noexcept { fault_.store(false, std::memory_order_relaxed); }
bool Instance::faulted() const noexcept { return fault_.load(std::memory_order_relaxed); }

// Registration ---------------------------------------------------------------------------

namespace detail {

namespace {
// "in0" -> "and2.0.in0"; "=joint.0.motor-pos-cmd" -> "joint.0.motor-pos-cmd" for components
// that must publish LinuxCNC's fixed, unprefixed names (motion's joint.N.*, axis.L.*).
std::string qualified(const InstanceContext& ctx, std::string_view name) {
    if (!name.empty() && name[0] == '=') return std::string(name.substr(1));
    return fmt::format("{}.{}", ctx.name, name);
}
}  // namespace

void* register_pin(Instance& owner, std::string_view name, Type type, Dir dir, Value initial,
                   void* pointer_field) {
    auto& ctx = context_of(owner, "pin");
    check_item_name(name);
    Runtime& rt = *ctx.runtime;
    auto full = qualified(ctx, name);
    if (rt.pins_.count(full)) throw Error(fmt::format("duplicate pin '{}'", full));
    auto cell = ctx.building->allocate(sizeof(PinCell));
    auto* c = rt.segment_->at<PinCell>(cell);
    c->own = initial;
    c->data_offset.store(rt.segment_->offset_of(&c->own));
    rt.pins_[full] = std::make_unique<Pin>(
        Pin{full, type, dir, ctx.component, static_cast<void**>(pointer_field), cell, nullptr});
    ctx.building->pins.push_back(full);
    return &c->own;
}

void* register_param(Instance& owner, std::string_view name, Type type, ParamDir dir,
                     Value initial) {
    auto& ctx = context_of(owner, "parameter");
    check_item_name(name);
    Runtime& rt = *ctx.runtime;
    auto full = qualified(ctx, name);
    if (rt.params_.count(full)) throw Error(fmt::format("duplicate parameter '{}'", full));
    auto slot = ctx.building->allocate(sizeof(Value));
    *rt.segment_->at<Value>(slot) = initial;
    rt.params_[full] = std::make_unique<ParamRecord>(ParamRecord{full, type, dir, ctx.component, slot});
    ctx.building->params.push_back(full);
    return rt.segment_->at(slot);
}

void register_function(Instance& owner, std::string_view suffix, RealtimeFn fn, RealtimeBatchFn batch,
                       void* object, bool uses_fp) {
    auto& ctx = context_of(owner, "function");
    Runtime& rt = *ctx.runtime;
    auto full = suffix.empty() ? ctx.name : qualified(ctx, suffix);
    if (rt.functs_.count(full)) throw Error(fmt::format("duplicate function '{}'", full));
    // Its timing objects come once every instance is built (load_component).
    rt.functs_[full] = std::make_unique<Funct>(Funct{full, fn, batch, object, uses_fp, ctx.component, {}, 0});
    ctx.building->functs.push_back(full);
    ctx.has_functions = true;
}

void register_shared_function(Instance& owner, std::string_view name, RealtimeFn fn, void* object,
                              bool uses_fp) {
    auto& ctx = context_of(owner, "function");
    Runtime& rt = *ctx.runtime;
    Component& comp = *ctx.component;
    auto full = !name.empty() && name[0] == '=' ? std::string(name.substr(1))
                                                : fmt::format("{}.{}", comp.name, name);
    auto it = rt.functs_.find(full);
    if (it != rt.functs_.end()) {
        if (it->second->component != &comp || it->second->fn != &SharedFunct::call_all)
            throw Error(fmt::format("duplicate function '{}'", full));
        static_cast<SharedFunct*>(it->second->object)->objects.push_back(object);
    } else {
        comp.shared_functs.push_back(std::make_unique<SharedFunct>(SharedFunct{fn, {object}}));
        rt.functs_[full] = std::make_unique<Funct>(Funct{full, &SharedFunct::call_all, nullptr,
                                                         comp.shared_functs.back().get(), uses_fp, &comp, {},
                                                         0});
        ctx.building->functs.push_back(full);
    }
    ctx.has_functions = true;
}

void* register_stream(Instance& owner, std::string_view name, std::string_view layout,
                      std::uint32_t depth) {
    auto& ctx = context_of(owner, "stream");
    Runtime& rt = *ctx.runtime;
    std::string full(name);
    if (rt.streams_.count(full)) throw Error(fmt::format("duplicate stream '{}'", full));
    if (depth == 0 || depth > (1u << 24))
        throw Error(fmt::format("stream '{}': depth {} out of range 1..16777216", full, depth));
    Type types[kMaxStreamFields];
    auto fields = parse_layout(layout, types);
    auto off = ctx.building->allocate(Ring::bytes_for(depth, fields));
    auto* ring = rt.segment_->at<Ring>(off);
    ring->depth = depth;
    ring->fields = fields;
    std::copy(types, types + fields, ring->types);
    ring->magic = kRingMagic;
    rt.streams_[full] = off;
    ctx.building->streams.push_back(full);
    return ring;
}

void* attach_stream(Instance& owner, std::string_view name, std::string_view layout) {
    auto& ctx = context_of(owner, "stream attachment");
    Runtime& rt = *ctx.runtime;
    const std::string full(name);
    const auto it = rt.streams_.find(full);
    if (it == rt.streams_.end()) {
        std::vector<std::string> known;
        for (const auto& [k, v] : rt.streams_) known.push_back(k);
        const auto near = nearest_name(full, known);
        throw Error(fmt::format("no stream '{}' to attach to (load its owner first){}", full,
                                near.empty() ? "" : fmt::format(" (did you mean '{}'?)", near)));
    }
    Type types[kMaxStreamFields];
    const auto fields = parse_layout(layout, types);
    auto* ring = rt.segment_->at<Ring>(it->second);
    if (ring->fields != fields || !std::equal(types, types + fields, ring->types))
        throw Error(fmt::format("stream '{}' has {} fields of another layout than '{}'", full,
                                ring->fields, layout));
    return ring;
}

bool registered_functions(const Instance& inst) noexcept {
    auto* ctx = current_context();
    return ctx && ctx->has_functions;
}

}  // namespace detail

void SharedFunct::call_all(void* self, Period p) noexcept {
    auto* sf = static_cast<SharedFunct*>(self);
    for (void* o : sf->objects) sf->fn(o, p);
}

// Stream (component side) ----------------------------------------------------------------

Stream::Stream(Instance* owner, std::string_view name, std::string_view layout, std::uint32_t depth)
    : ring_(static_cast<Ring*>(detail::register_stream(*owner, name, layout, depth))) {}
Stream Stream::attach(Instance* owner, std::string_view name, std::string_view layout) {
    return Stream(static_cast<Ring*>(detail::attach_stream(*owner, name, layout)));
}
std::size_t Stream::fields() const noexcept { return ring_->fields; }
Type Stream::field_type(std::size_t i) const noexcept { return ring_->types[i]; }
bool Stream::push(const Value* record) noexcept { return ring_->push(record); }
bool Stream::pop(Value* record) noexcept { return ring_->pop(record); }
std::uint32_t Stream::depth() const noexcept { return ring_->depth; }
std::uint32_t Stream::used() const noexcept { return ring_->used(); }

// Signals ----------------------------------------------------------------------------------

Pin* Signal::writer() const {
    for (Pin* p : pins)
        if (p->dir == Dir::Out) return p;
    return nullptr;
}

// Names --------------------------------------------------------------------------------------

namespace {
std::size_t edit_distance(std::string_view a, std::string_view b) {
    std::vector<std::size_t> row(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
        std::size_t diag = row[0];
        row[0] = i;
        for (std::size_t j = 1; j <= b.size(); ++j) {
            std::size_t up = row[j];
            row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] != b[j - 1])});
            diag = up;
        }
    }
    return row[b.size()];
}
}  // namespace

std::string nearest_name(std::string_view name, const std::vector<std::string>& candidates) {
    // Two edits (one for short words) catch a typo or a swapped pair without proposing
    // an unrelated name that merely shares a long instance prefix.
    std::string best;
    std::size_t best_d = (name.size() < 4 ? 1 : 2) + 1;
    for (auto& c : candidates) {
        if (c.size() > name.size() + best_d || name.size() > c.size() + best_d) continue;
        auto d = edit_distance(name, c);
        if (d < best_d) {
            best_d = d;
            best = c;
        }
    }
    return best;
}

bool name_matches(const std::vector<std::string>& patterns, const std::string& name) {
    if (patterns.empty()) return true;
    for (auto& p : patterns) {
        if (name.compare(0, p.size(), p) == 0) return true;
        if (::fnmatch(p.c_str(), name.c_str(), 0) == 0) return true;
    }
    return false;
}

// Runtime --------------------------------------------------------------------------------------

Runtime::Runtime(const Options& options)
    : paths_(InstancePaths::for_instance(options.instance)), sim_clock_(options.sim_clock) {
    std::string notice;
    segment_ = Segment::create(paths_, options.segment_bytes, &notice);
    if (!notice.empty()) fmt::print(stderr, "halrun: {}\n", notice);
}

Runtime::~Runtime() {
    shutdown();
    segment_.reset();
    ::shm_unlink(paths_.shm_name.c_str());
}

void Runtime::shutdown() {
    std::lock_guard lock(mutex_);
    for (auto& [n, t] : threads_) t->stop();
    running_ = false;
    set_instance_states(InstanceState::Stopped);
    while (!components_.empty()) unload_component(*components_.back());
    instance_arena_ = Arena{};  // no instance is left in it
    threads_.clear();
    thread_order_.clear();
    signals_.clear();
    aliases_.clear();
}

std::string Runtime::resolve(const std::string& name) const {
    auto it = aliases_.find(name);
    return it == aliases_.end() ? name : it->second;
}

std::vector<std::string> Runtime::names(std::string_view kind) const {
    std::lock_guard lock(mutex_);
    std::vector<std::string> out;
    auto keys = [&](const auto& m) {
        for (auto& [k, v] : m) out.push_back(k);
    };
    if (kind == "pin") keys(pins_);
    else if (kind == "param") keys(params_);
    else if (kind == "sig" || kind == "signal") keys(signals_);
    else if (kind == "funct") keys(functs_);
    else if (kind == "thread") keys(threads_);
    else if (kind == "alias") keys(aliases_);
    else if (kind == "comp")
        for (auto& c : components_) out.push_back(c->name);
    return out;
}

void Runtime::not_found(std::string_view kind, const std::string& name,
                        std::string_view candidates_kind) const {
    auto near = nearest_name(name, names(candidates_kind));
    if (near.empty()) throw Error(fmt::format("{} '{}' does not exist", kind, name));
    throw Error(fmt::format("{} '{}' does not exist (did you mean '{}'?)", kind, name, near));
}

Pin& Runtime::find_pin(const std::string& name) const {
    auto it = pins_.find(resolve(name));
    if (it == pins_.end()) not_found("pin", name, "pin");
    return *it->second;
}
ParamRecord& Runtime::find_param(const std::string& name) const {
    auto it = params_.find(resolve(name));
    if (it == params_.end()) not_found("parameter", name, "param");
    return *it->second;
}
Signal& Runtime::find_signal(const std::string& name) const {
    auto it = signals_.find(name);
    if (it == signals_.end()) not_found("signal", name, "sig");
    return *it->second;
}
Funct& Runtime::find_funct(const std::string& name) const {
    auto it = functs_.find(name);
    if (it == functs_.end()) not_found("function", name, "funct");
    return *it->second;
}
Thread& Runtime::find_thread(const std::string& name) const {
    auto it = threads_.find(name);
    if (it == threads_.end()) not_found("thread", name, "thread");
    return *it->second;
}
Component& Runtime::find_component(const std::string& name) const {
    for (auto& c : components_)
        if (c->name == name) return *c;
    not_found("component", name, "comp");
}

bool Runtime::component_exists(const std::string& name) const {
    std::lock_guard lock(mutex_);
    return std::any_of(components_.begin(), components_.end(),
                       [&](auto& c) { return c->name == name; });
}
bool Runtime::component_ready(const std::string& name) const {
    std::lock_guard lock(mutex_);
    return std::any_of(components_.begin(), components_.end(),
                       [&](auto& c) { return c->name == name && c->ready; });
}

// Command table --------------------------------------------------------------------------------

namespace {
constexpr LockLevel kLoad = LockLevel::Load;
constexpr LockLevel kConfig = LockLevel::Config;
constexpr LockLevel kTune = LockLevel::Tune;
constexpr LockLevel kNone = LockLevel::None;
constexpr LockLevel kRun = static_cast<LockLevel>(8);
}  // namespace

const std::vector<Runtime::CommandSpec>& Runtime::commands() {
    static const std::vector<CommandSpec> table = {
        {"loadrt", &Runtime::cmd_loadrt, 1, -1, kLoad, "loadrt COMPONENT [count=N|names=a,b] [ARG=VALUE ...]"},
        {"unload", &Runtime::cmd_unload, 1, 1, kLoad, "unload COMPONENT|all"},
        {"unloadrt", &Runtime::cmd_unload, 1, 1, kLoad, "unloadrt COMPONENT|all"},
        {"net", &Runtime::cmd_net, 1, -1, kConfig, "net SIGNAL [=>|<=|<=>] PIN ..."},
        {"newsig", &Runtime::cmd_newsig, 2, 2, kConfig, "newsig SIGNAL TYPE"},
        {"delsig", &Runtime::cmd_delsig, 1, 1, kConfig, "delsig SIGNAL|all"},
        {"linkps", &Runtime::cmd_linkps, 2, 3, kConfig, "linkps PIN [=>|<=|<=>] SIGNAL"},
        {"linksp", &Runtime::cmd_linksp, 2, 3, kConfig, "linksp SIGNAL [=>|<=|<=>] PIN"},
        {"linkpp", &Runtime::cmd_linkpp, 2, 3, kConfig, "linkpp PIN1 [=>|<=|<=>] PIN2"},
        {"unlinkp", &Runtime::cmd_unlinkp, 1, 1, kConfig, "unlinkp PIN"},
        {"setp", &Runtime::cmd_setp, 2, 2, kTune, "setp PIN|PARAM VALUE"},
        {"getp", &Runtime::cmd_getp, 1, 1, kNone, "getp PIN|PARAM"},
        {"sets", &Runtime::cmd_sets, 2, 2, kTune, "sets SIGNAL VALUE"},
        {"gets", &Runtime::cmd_gets, 1, 1, kNone, "gets SIGNAL"},
        {"ptype", &Runtime::cmd_ptype, 1, 1, kNone, "ptype PIN|PARAM"},
        {"stype", &Runtime::cmd_stype, 1, 1, kNone, "stype SIGNAL"},
        {"addf", &Runtime::cmd_addf, 2, 3, kConfig, "addf FUNCTION THREAD [POSITION]"},
        {"delf", &Runtime::cmd_delf, 1, 2, kConfig, "delf FUNCTION [THREAD]"},
        {"newthread", &Runtime::cmd_newthread, 2, 4, kConfig, "newthread NAME PERIOD_NS [fp|nofp] [cpu=N]"},
        {"delthread", &Runtime::cmd_delthread, 1, 1, kConfig, "delthread NAME"},
        {"start", &Runtime::cmd_start, 0, 0, kRun, "start"},
        {"stop", &Runtime::cmd_stop, 0, 0, kRun, "stop"},
        {"show", &Runtime::cmd_show, 0, -1, kNone, "show [comp|pin|sig|param|funct|thread|alias|all] [PATTERN ...]"},
        {"list", &Runtime::cmd_list, 1, -1, kNone, "list comp|pin|sig|param|funct|thread|alias [PATTERN ...]"},
        {"save", &Runtime::cmd_save, 0, 1, kNone, "save [all|comp|alias|sig|link|net|param|thread]"},
        {"alias", &Runtime::cmd_alias, 3, 3, kConfig, "alias pin|param NAME ALIAS"},
        {"unalias", &Runtime::cmd_unalias, 2, 2, kConfig, "unalias pin|param ALIAS"},
        {"lock", &Runtime::cmd_lock, 0, 1, kNone, "lock [none|load|config|tune|all]"},
        {"unlock", &Runtime::cmd_unlock, 0, 1, kNone, "unlock [none|load|config|tune|all]"},
        {"advance", &Runtime::cmd_advance, 1, 1, kRun, "advance SECONDS   (simulated clock only)"},
        {"status", &Runtime::cmd_status, 0, 0, kNone, "status"},
        {"help", &Runtime::cmd_help, 0, 1, kNone, "help [COMMAND]"},
    };
    return table;
}

bool Runtime::is_bus_command(std::string_view word) const {
    for (auto& c : commands())
        if (word == c.name) return true;
    return false;
}

std::vector<std::string> Runtime::command_names() const {
    std::vector<std::string> out;
    for (auto& c : commands()) out.emplace_back(c.name);
    return out;
}

void Runtime::execute(const std::vector<std::string>& words, std::string& out) {
    if (words.empty()) return;
    std::lock_guard lock(mutex_);
    for (auto& c : commands()) {
        if (words[0] != c.name) continue;
        int n = static_cast<int>(words.size()) - 1;
        if (n < c.min_args || (c.max_args >= 0 && n > c.max_args))
            throw Error(fmt::format("wrong number of arguments; usage: {}", c.usage));
        if (lock_ & static_cast<int>(c.blocked_by))
            throw Error(fmt::format("'{}' is not allowed: HAL is locked (use 'unlock')", c.name));
        std::vector<std::string> args(words.begin() + 1, words.end());
        (this->*c.handler)(args, out);
        return;
    }
    auto near = nearest_name(words[0], command_names());
    throw Error(near.empty() ? fmt::format("unknown command '{}'", words[0])
                             : fmt::format("unknown command '{}' (did you mean '{}'?)", words[0], near));
}

// loadrt / unload ------------------------------------------------------------------------------

namespace {
std::pair<std::string, std::string> split_arg(const std::string& a) {
    auto eq = a.find('=');
    if (eq == std::string::npos || eq == 0)
        throw Error(fmt::format("argument '{}' is not of the form KEY=VALUE", a));
    auto value = a.substr(eq + 1);
    if (value.size() >= 2 && value.front() == '"' && value.back() == '"')
        value = value.substr(1, value.size() - 2);
    return {a.substr(0, eq), value};
}

std::vector<std::string> component_dirs() {
    std::vector<std::string> dirs;
    if (const char* env = std::getenv("HAL_COMPONENT_PATH")) {
        std::string s = env, item;
        for (char c : s + ":") {
            if (c == ':') {
                if (!item.empty()) dirs.push_back(item);
                item.clear();
            } else {
                item += c;
            }
        }
    }
    std::error_code ec;
    auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
    if (!ec) dirs.push_back((exe.parent_path().parent_path() / "lib/cnc/components").string());
    if (*CNC_COMPONENT_DIR) dirs.emplace_back(CNC_COMPONENT_DIR);
    return dirs;
}

std::vector<std::string> available_components(const std::vector<std::string>& dirs) {
    std::vector<std::string> names{"threads"};
    for (auto& d : dirs) {
        std::error_code ec;
        for (auto& e : std::filesystem::directory_iterator(d, ec))
            if (e.path().extension() == ".so" || e.path().extension() == ".alias")
                names.push_back(e.path().stem().string());
    }
    return names;
}

// A LinuxCNC module name that one of our components answers to: `<name>.alias` beside the
// components says which component to load and with what, so `loadrt trivkins coordinates=XYZ`
// loads kins_trivial with `names=trivkins` added. Its lines ('#' starts a comment):
//
//   COMPONENT [KEY=VALUE ...]     the component; KEY=VALUEs are defaults for keys the loadrt
//                                 line does not give
//   thread NAME KEY [DEFAULT_NS]  after loading, create thread NAME (floating point allowed)
//                                 with the period the loadrt line gives in KEY, else
//                                 DEFAULT_NS; none if neither, or 0 (LinuxCNC's motmod makes
//                                 servo-thread and base-thread from its period arguments)
//
// The file lives with the component it names (its CMakeLists copies it here), so the runtime
// knows no component by name. The first folder holding `<name>.so` or `<name>.alias` decides,
// a .so first: a real component of that name always wins.
struct AliasThread {
    std::string name, key, fallback_ns;
};

struct Alias {
    std::string path;
    std::string target;
    std::vector<std::string> args;
    std::vector<AliasThread> threads;
};

Alias read_alias(const std::string& path, std::istream& in) {
    Alias alias{path, {}, {}, {}};
    std::string line;
    for (int number = 1; std::getline(in, line); ++number) {
        std::istringstream words(line.substr(0, line.find('#')));
        std::vector<std::string> w;
        for (std::string word; words >> word;) w.push_back(word);
        if (w.empty()) continue;
        if (w[0] == "thread") {
            if (w.size() < 3 || w.size() > 4)
                throw Error(fmt::format("{}:{}: expected 'thread NAME KEY [DEFAULT_NS]'", path, number));
            alias.threads.push_back({w[1], w[2], w.size() == 4 ? w[3] : ""});
        } else if (alias.target.empty() && w[0].find('/') == std::string::npos) {
            alias.target = w[0];
            alias.args.assign(w.begin() + 1, w.end());
        } else {
            throw Error(fmt::format("{}:{}: expected one line 'COMPONENT [KEY=VALUE ...]'", path, number));
        }
    }
    if (alias.target.empty()) throw Error(fmt::format("{}: names no component", path));
    return alias;
}

std::optional<Alias> find_alias(const std::string& name, const std::vector<std::string>& dirs) {
    if (name.find('/') != std::string::npos) return std::nullopt;
    for (auto& d : dirs) {
        if (std::filesystem::exists(fmt::format("{}/{}.so", d, name))) return std::nullopt;
        const auto path = fmt::format("{}/{}.alias", d, name);
        std::ifstream in(path);
        if (in) return read_alias(path, in);
    }
    return std::nullopt;
}

// The threads an alias makes, with their periods from the merged loadrt arguments.
std::vector<std::pair<std::string, std::int64_t>> alias_threads(const Alias& alias,
                                                                 const std::vector<std::string>& merged) {
    std::vector<std::pair<std::string, std::int64_t>> out;
    for (auto& t : alias.threads) {
        std::string value = t.fallback_ns;
        for (auto& m : merged)
            if (auto [k, v] = split_arg(m); k == t.key) value = v;
        if (value.empty()) continue;
        auto period = parse_value(Type::S64, value);
        if (!period || period->s64 < 0)
            throw Error(fmt::format("{}={}: not a number of nanoseconds", t.key, value));
        if (period->s64 > 0) out.emplace_back(t.name, period->s64);
    }
    return out;
}

// The alias's defaults for the keys the line leaves out, then the line's own arguments.
std::vector<std::string> merge_alias_args(const Alias& alias, const std::vector<std::string>& given) {
    std::vector<std::string> out;
    for (auto& d : alias.args) {
        const auto key = split_arg(d).first;
        const bool overridden = std::any_of(given.begin(), given.end(), [&](const std::string& g) {
            return g.compare(0, key.size() + 1, key + "=") == 0;
        });
        if (!overridden) out.push_back(d);
    }
    out.insert(out.end(), given.begin(), given.end());
    return out;
}
}  // namespace

void Runtime::cmd_loadrt(const std::vector<std::string>& a, std::string& out) {
    std::vector<std::string> args(a.begin() + 1, a.end());
    try {
        if (a[0] == "threads") {
            load_threads_component(args);
        } else if (auto alias = find_alias(a[0], component_dirs())) {
            if (find_alias(alias->target, component_dirs()))
                throw Error(fmt::format("{}: names another alias, '{}'; name a component", alias->path,
                                        alias->target));
            const auto merged = merge_alias_args(*alias, args);
            load_alias(alias->target, merged, alias_threads(*alias, merged));
        } else {
            load_component(a[0], args);
        }
    } catch (const Error& e) {
        throw Error(fmt::format("loadrt {}: {}", a[0], e.what()));
    }
}

void Runtime::load_alias(const std::string& target, const std::vector<std::string>& args,
                         const std::vector<std::pair<std::string, std::int64_t>>& threads) {
    // Threads are checked before and made after the component: a failure leaves nothing behind.
    for (auto& [name, period_ns] : threads)
        if (threads_.count(name)) throw Error(fmt::format("thread '{}' already exists", name));
    load_component(target, args);
    for (auto& [name, period_ns] : threads) create_thread(name, period_ns, true, -1);
}

void Runtime::load_threads_component(const std::vector<std::string>& args) {
    std::map<std::string, std::string> kv;
    for (auto& a : args) {
        auto [k, v] = split_arg(a);
        static const std::set<std::string> known = {"name1", "name2", "name3", "period1", "period2",
                                                    "period3", "fp1", "fp2", "fp3", "cpu1", "cpu2", "cpu3"};
        if (!known.count(k)) {
            auto near = nearest_name(k, std::vector<std::string>(known.begin(), known.end()));
            throw Error(fmt::format("unknown argument '{}'{}", k,
                                    near.empty() ? "" : fmt::format(" (did you mean '{}'?)", near)));
        }
        kv[k] = v;
    }
    struct Spec {
        std::string name;
        std::int64_t period;
        bool fp;
        int cpu;
    };
    std::vector<Spec> specs;
    for (int i = 1; i <= 3; ++i) {
        auto n = kv.find(fmt::format("name{}", i));
        if (n == kv.end()) continue;
        auto p = kv.find(fmt::format("period{}", i));
        if (p == kv.end()) throw Error(fmt::format("thread '{}' needs period{}=NANOSECONDS", n->second, i));
        auto period = parse_value(Type::S64, p->second);
        if (!period || period->s64 <= 0)
            throw Error(fmt::format("period{}={}: not a positive number of nanoseconds", i, p->second));
        bool fp = true;
        if (auto f = kv.find(fmt::format("fp{}", i)); f != kv.end()) fp = f->second != "0";
        int cpu = -1;
        if (auto c = kv.find(fmt::format("cpu{}", i)); c != kv.end()) cpu = std::stoi(c->second);
        specs.push_back({n->second, period->s64, fp, cpu});
    }
    if (specs.empty()) throw Error("no thread given (name1=NAME period1=NANOSECONDS)");
    for (auto& s : specs)
        if (threads_.count(s.name)) throw Error(fmt::format("thread '{}' already exists", s.name));
    for (auto& s : specs) create_thread(s.name, s.period, s.fp, s.cpu);
}

void Runtime::load_component(const std::string& name, const std::vector<std::string>& args) {
    auto dirs = component_dirs();
    Component* existing = nullptr;
    for (auto& c : components_)
        if (c->name == name) existing = c.get();
    if (existing && !existing->realtime)
        throw Error(fmt::format("'{}' is already a userspace component", name));

    std::unique_ptr<Component> fresh;
    Component* comp = existing;
    if (!comp) {
        std::string path;
        if (name.find('/') != std::string::npos) {
            path = name;
        } else {
            for (auto& d : dirs) {
                auto candidate = fmt::format("{}/{}.so", d, name);
                if (std::filesystem::exists(candidate)) {
                    path = candidate;
                    break;
                }
            }
        }
        if (path.empty()) {
            auto near = nearest_name(name, available_components(dirs));
            throw Error(fmt::format("no component '{}'{} (searched {}; HAL_COMPONENT_PATH adds folders)",
                                    name, near.empty() ? "" : fmt::format(" (did you mean '{}'?)", near),
                                    fmt::join(dirs, ", ")));
        }
        void* lib = ::dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
        if (!lib) throw Error(fmt::format("cannot load {}: {}", path, ::dlerror()));
        using Entry = const ComponentDescriptor* (*)();
        auto entry = reinterpret_cast<Entry>(::dlsym(lib, "cnc_hal_component"));
        if (!entry) {
            ::dlclose(lib);
            throw Error(fmt::format("{} is not a HAL component: it has no cnc_hal_component entry point", path));
        }
        // Only the first field is read before the version matches: it is the one field
        // every ABI version keeps in place.
        const ComponentDescriptor* d = entry();
        const std::uint32_t abi = d ? d->abi_version : 0;
        if (abi != kAbiVersion) {
            ::dlclose(lib);
            throw Error(fmt::format("{} was built for HAL ABI {}, this runtime is ABI {}; rebuild it", path,
                                    abi, kAbiVersion));
        }
        fresh = std::make_unique<Component>();
        fresh->name = name.find('/') != std::string::npos ? d->name : name;
        fresh->id = next_component_id_;
        fresh->realtime = true;
        fresh->library = lib;
        fresh->descriptor = d;
        fresh->path = path;
        fresh->ready = true;
        comp = fresh.get();
    }
    auto close_fresh = [&] {
        if (fresh) ::dlclose(fresh->library);
    };

    std::map<std::string, std::string> kv;
    std::vector<std::string> names;
    long count = -1;
    try {
        for (auto& a : args) {
            auto [k, v] = split_arg(a);
            if (kv.count(k)) throw Error(fmt::format("argument '{}' given twice", k));
            if (k == "count" || k == "num_chan") {
                auto n = parse_value(Type::S32, v);
                if (!n || n->s32 < 1 || n->s32 > 100000)
                    throw Error(fmt::format("{}={}: expected a count from 1 to 100000", k, v));
                if (count >= 0) throw Error("give only one of count= and num_chan=");
                count = n->s32;
            } else if (k == "names") {
                std::string item;
                for (char c : v + ",") {
                    if (c == ',') {
                        if (item.empty()) throw Error(fmt::format("names={}: empty name", v));
                        names.push_back(item);
                        item.clear();
                    } else {
                        item += c;
                    }
                }
            } else {
                std::vector<std::string> accepted;
                for (auto p = comp->descriptor->args; p && *p; ++p) accepted.emplace_back(*p);
                if (std::find(accepted.begin(), accepted.end(), k) == accepted.end()) {
                    accepted.insert(accepted.end(), {"count", "names", "num_chan"});
                    auto near = nearest_name(k, accepted);
                    throw Error(fmt::format("unknown argument '{}'{}", k,
                                            near.empty() ? "" : fmt::format(" (did you mean '{}'?)", near)));
                }
            }
            kv[k] = v;
        }
        if (count >= 0 && !names.empty()) throw Error("give either count= or names=, not both");
    } catch (...) {
        close_fresh();
        throw;
    }
    int first_index = existing ? static_cast<int>(existing->instances.size()) : 0;
    if (names.empty()) {
        const auto& opts = comp->descriptor->options;
        long n = count < 0 ? opts.default_count : count;
        if (count < 0 && opts.count_from)
            if (auto it = kv.find(opts.count_from); it != kv.end())
                n = static_cast<long>(std::count(it->second.begin(), it->second.end(), ',')) + 1;
        std::string prefix = opts.prefix ? opts.prefix : comp->name;
        if (!opts.prefix) std::replace(prefix.begin(), prefix.end(), '_', '-');
        for (long i = 0; i < n; ++i) names.push_back(fmt::format("{}.{}", prefix, first_index + i));
    }
    std::set<std::string> seen;
    for (auto& n : names) {
        check_item_name(n);
        if (!seen.insert(n).second) {
            close_fresh();
            throw Error(fmt::format("instance name '{}' given twice", n));
        }
        for (auto& c : components_)
            for (auto& inst : c->instances)
                if (inst->name == n) {
                    close_fresh();
                    throw Error(fmt::format("an instance named '{}' already exists", n));
                }
    }

    LoadTransaction building{*this};
    std::vector<std::unique_ptr<InstanceRecord>> made;
    auto shared_before = comp->shared_functs.size();
    std::vector<std::size_t> shared_sizes;
    for (auto& sf : comp->shared_functs) shared_sizes.push_back(sf->objects.size());
    std::optional<std::string> failure;
    try {
        for (std::size_t i = 0; i < names.size(); ++i) {
            // The record owns the context before construction starts: the instance keeps a
            // pointer to it for name() and arg(), and a failure frees both together.
            auto rec = std::make_unique<InstanceRecord>();
            rec->name = names[i];
            rec->context.reset(new detail::InstanceContext{this, &building, comp, names[i], static_cast<int>(i), kv});
            made.push_back(std::move(rec));
            auto& made_rec = *made.back();
            detail::InstanceContext::current = made_rec.context.get();
            try {
                made_rec.object.reset(comp->descriptor->create());
            } catch (...) {
                detail::InstanceContext::current = nullptr;
                throw;
            }
            detail::InstanceContext::current = nullptr;
            made_rec.context->building = nullptr;
        }
        // After every instance's own pins: a function's timing is touched only on its sampled
        // cycles, so it stays out from between the cells its instance uses every cycle
        // (interleaved, they slowed a chain of 1000 and2 by 3 % on the simulated clock).
        for (const std::string& name : building.functs) add_funct_timing(*functs_[name], building);
    } catch (const std::exception& e) {
        // The exception may have been made by the component, its vtable in the library:
        // keep only its text, and unload the library after the handler has destroyed it.
        failure = e.what();
        made.clear();
        building.rollback();
        comp->shared_functs.resize(shared_before);
        for (std::size_t i = 0; i < shared_sizes.size(); ++i) comp->shared_functs[i]->objects.resize(shared_sizes[i]);
    }
    if (failure) {
        close_fresh();
        throw Error(*failure);
    }
    if (fresh) {
        ++next_component_id_;
        components_.push_back(std::move(fresh));
    }
    for (auto& m : made) comp->instances.push_back(std::move(m));
    comp->load_args.push_back(args);
    comp->streams.insert(comp->streams.end(), building.streams.begin(), building.streams.end());
}

void Runtime::unload_component(Component& c) {
    // Take its functions off every thread first, so nothing calls into it any more.
    for (auto& [n, f] : functs_) {
        if (f->component != &c) continue;
        for (Thread* t : f->users) {
            auto list = t->functs();
            list.erase(std::remove(list.begin(), list.end(), f.get()), list.end());
            t->set_functs(list, *segment_);
            t->quiesce();
        }
        f->users.clear();
    }
    for (auto it = pins_.begin(); it != pins_.end();) {
        if (it->second->component == &c) {
            if (it->second->signal) unlink(*it->second);
            segment_->release(it->second->cell, sizeof(PinCell));
            it = pins_.erase(it);
        } else {
            ++it;
        }
    }
    for (auto it = params_.begin(); it != params_.end();) {
        if (it->second->component != &c) {
            ++it;
            continue;
        }
        if (!it->second->timing) segment_->release(it->second->slot, sizeof(Value));
        it = params_.erase(it);
    }
    for (auto it = functs_.begin(); it != functs_.end();) {
        if (it->second->component == &c) {
            segment_->release(it->second->timing, sizeof(FunctTiming));
            it = functs_.erase(it);
        } else {
            ++it;
        }
    }
    for (auto it = aliases_.begin(); it != aliases_.end();) {
        if (!pins_.count(it->second) && !params_.count(it->second)) it = aliases_.erase(it);
        else ++it;
    }
    // Stream rings stay allocated until the instance ends: halsampler may still be draining
    // one, and a ring reused under it would hand it another stream's records.
    for (const std::string& name : c.streams) streams_.erase(name);
    c.instances.clear();
    if (c.library) ::dlclose(c.library);
    auto pos = std::find_if(components_.begin(), components_.end(), [&](auto& p) { return p.get() == &c; });
    if (pos != components_.end()) components_.erase(pos);
}

void Runtime::cmd_unload(const std::vector<std::string>& a, std::string& out) {
    if (a[0] == "all") {
        for (auto& [n, t] : threads_) t->stop();
        running_ = false;
        while (!components_.empty()) {
            auto& c = *components_.back();
            if (!c.realtime && c.pid > 0) ::kill(c.pid, SIGTERM);
            unload_component(c);
        }
        return;
    }
    Component& c = find_component(a[0]);
    if (!c.realtime && c.pid > 0) ::kill(c.pid, SIGTERM);
    unload_component(c);
}

// Signals and links ------------------------------------------------------------------------------

Signal& Runtime::new_signal(const std::string& name, Type type) {
    check_item_name(name);
    if (signals_.count(name)) throw Error(fmt::format("signal '{}' already exists", name));
    auto slot = segment_->allocate(sizeof(Value));
    auto& s = signals_[name];
    s = std::make_unique<Signal>(Signal{name, type, slot, {}});
    return *s;
}

void Runtime::check_link(const Pin& pin, const Signal& sig) const {
    if (pin.signal == &sig) return;
    if (pin.signal)
        throw Error(fmt::format("pin '{}' is already linked to signal '{}'", pin.name, pin.signal->name));
    if (pin.type != sig.type)
        throw Error(fmt::format("signal '{}' is {} but pin '{}' is {}", sig.name, to_string(sig.type),
                                pin.name, to_string(pin.type)));
    if (pin.dir == Dir::Out) {
        if (Pin* w = sig.writer())
            throw Error(fmt::format("signal '{}' already has output pin '{}'; '{}' would be a second writer",
                                    sig.name, w->name, pin.name));
        for (Pin* p : sig.pins)
            if (p->dir == Dir::IO)
                throw Error(fmt::format("signal '{}' has I/O pin '{}'; it cannot also have output pin '{}'",
                                        sig.name, p->name, pin.name));
    }
    if (pin.dir == Dir::IO)
        if (Pin* w = sig.writer())
            throw Error(fmt::format("signal '{}' already has output pin '{}'; it cannot also have I/O pin '{}'",
                                    sig.name, w->name, pin.name));
}

void Runtime::retarget(Pin& pin, std::uint64_t data_offset) {
    segment_->at<PinCell>(pin.cell)->data_offset.store(data_offset, std::memory_order_release);
    if (pin.pointer_field)
        std::atomic_ref<void*>(*pin.pointer_field).store(segment_->at(data_offset), std::memory_order_release);
}

void Runtime::link(Pin& pin, Signal& sig) {
    if (pin.signal == &sig) return;
    // The first pin's value seeds the signal, as in LinuxCNC, so wiring does not glitch it.
    if (sig.pins.empty()) *segment_->at<Value>(sig.slot) = own_value(*segment_, pin);
    sig.pins.push_back(&pin);
    pin.signal = &sig;
    retarget(pin, sig.slot);
}

void Runtime::unlink(Pin& pin) {
    if (!pin.signal) return;
    Signal& sig = *pin.signal;
    // An input keeps the signal's last value instead of jumping back to a stale one.
    own_value(*segment_, pin) = *segment_->at<Value>(sig.slot);
    retarget(pin, segment_->offset_of(&segment_->at<PinCell>(pin.cell)->own));
    sig.pins.erase(std::remove(sig.pins.begin(), sig.pins.end(), &pin), sig.pins.end());
    pin.signal = nullptr;
}

namespace {
bool is_arrow(const std::string& s) { return s == "=>" || s == "<=" || s == "<=>"; }
}  // namespace

void Runtime::cmd_net(const std::vector<std::string>& a, std::string& out) {
    const std::string& sig_name = a[0];
    if (pins_.count(resolve(sig_name)))
        throw Error(fmt::format("'{}' is a pin; the first argument of net is the signal name", sig_name));
    std::vector<Pin*> pins;
    for (std::size_t i = 1; i < a.size(); ++i) {
        if (is_arrow(a[i])) continue;
        Pin& p = find_pin(a[i]);
        if (std::find(pins.begin(), pins.end(), &p) != pins.end())
            throw Error(fmt::format("pin '{}' is listed twice", p.name));
        pins.push_back(&p);
    }
    if (pins.empty()) throw Error("net needs at least one pin; usage: net SIGNAL [=>|<=|<=>] PIN ...");
    net_pins(sig_name, pins);
}

void Runtime::net_pins(const std::string& sig_name, std::vector<Pin*> pins) {
    auto it = signals_.find(sig_name);
    // Validate every pin against the signal as it would be after the whole line, so a
    // failure leaves nothing half-linked.
    Signal probe{sig_name, it != signals_.end() ? it->second->type : pins[0]->type, 0,
                 it != signals_.end() ? it->second->pins : std::vector<Pin*>{}};
    for (Pin* p : pins) {
        Signal* real = it != signals_.end() ? it->second.get() : nullptr;
        if (p->signal && p->signal == real) continue;
        check_link(*p, probe);
        probe.pins.push_back(p);
    }
    Signal& sig = it != signals_.end() ? *it->second : new_signal(sig_name, pins[0]->type);
    // A writer is linked first so the signal starts from the driving pin's value.
    std::stable_partition(pins.begin(), pins.end(), [](Pin* p) { return p->dir == Dir::Out; });
    for (Pin* p : pins) link(*p, sig);
}

void Runtime::cmd_newsig(const std::vector<std::string>& a, std::string& out) {
    auto t = parse_type(a[1]);
    if (!t) throw Error(fmt::format("'{}' is not a type (bit, float, s32, u32, s64, u64)", a[1]));
    new_signal(a[0], *t);
}

void Runtime::cmd_delsig(const std::vector<std::string>& a, std::string& out) {
    std::vector<Signal*> victims;
    if (a[0] == "all") {
        for (auto& [n, s] : signals_) victims.push_back(s.get());
    } else {
        victims.push_back(&find_signal(a[0]));
    }
    for (Signal* s : victims) {
        auto pins = s->pins;
        for (Pin* p : pins) unlink(*p);
        segment_->release(s->slot, sizeof(Value));
        signals_.erase(s->name);
    }
}

namespace {
// The link commands take an optional arrow between their two names, as decoration.
void check_optional_arrow(const std::vector<std::string>& a) {
    if (a.size() == 3 && !is_arrow(a[1])) throw Error(fmt::format("'{}' is not an arrow (=>, <= or <=>)", a[1]));
}
}  // namespace

void Runtime::link_checked(const std::string& pin_name, const std::string& signal_name) {
    Pin& p = find_pin(pin_name);
    Signal& s = find_signal(signal_name);
    check_link(p, s);
    link(p, s);
}

void Runtime::cmd_linkps(const std::vector<std::string>& a, std::string& out) {
    check_optional_arrow(a);
    link_checked(a[0], a.back());
}

void Runtime::cmd_linksp(const std::vector<std::string>& a, std::string& out) {
    check_optional_arrow(a);
    link_checked(a.back(), a[0]);
}

void Runtime::cmd_linkpp(const std::vector<std::string>& a, std::string& out) {
    check_optional_arrow(a);
    // LinuxCNC's linkpp names the new signal after the first pin.
    Pin& p1 = find_pin(a[0]);
    Pin& p2 = find_pin(a.back());
    if (&p1 == &p2) throw Error(fmt::format("pin '{}' cannot be linked to itself", p1.name));
    net_pins(p1.name, {&p1, &p2});
}

void Runtime::cmd_unlinkp(const std::vector<std::string>& a, std::string& out) {
    unlink(find_pin(a[0]));
}

// Values ---------------------------------------------------------------------------------------------

Value Runtime::read_pin(const Pin& p) const {
    auto off = segment_->at<PinCell>(p.cell)->data_offset.load(std::memory_order_acquire);
    return *segment_->at<Value>(off);
}

namespace {
Value parse_or_throw(Type t, const std::string& text, const std::string& what) {
    auto v = parse_value(t, text);
    if (!v) throw Error(fmt::format("'{}' is not a valid {} value for {}", text, to_string(t), what));
    return *v;
}
}  // namespace

void Runtime::no_pin_or_param(const std::string& name) const {
    auto candidates = names("pin");
    auto params = names("param");
    candidates.insert(candidates.end(), params.begin(), params.end());
    auto near = nearest_name(name, candidates);
    throw Error(fmt::format("pin or parameter '{}' does not exist{}", name,
                            near.empty() ? "" : fmt::format(" (did you mean '{}'?)", near)));
}

void Runtime::cmd_setp(const std::vector<std::string>& a, std::string& out) {
    auto name = resolve(a[0]);
    if (auto it = params_.find(name); it != params_.end()) {
        ParamRecord& p = *it->second;
        if (p.dir == ParamDir::RO) throw Error(fmt::format("parameter '{}' is read-only", p.name));
        *segment_->at<Value>(p.slot) = parse_or_throw(p.type, a[1], p.name);
        return;
    }
    if (auto it = pins_.find(name); it != pins_.end()) {
        Pin& p = *it->second;
        if (p.dir == Dir::Out) throw Error(fmt::format("pin '{}' is an output; setp writes only inputs and parameters", p.name));
        if (p.signal)
            throw Error(fmt::format("pin '{}' is linked to signal '{}'; use sets on the signal", p.name, p.signal->name));
        own_value(*segment_, p) = parse_or_throw(p.type, a[1], p.name);
        return;
    }
    no_pin_or_param(a[0]);
}

void Runtime::cmd_getp(const std::vector<std::string>& a, std::string& out) {
    auto name = resolve(a[0]);
    if (auto it = params_.find(name); it != params_.end()) {
        out += format_value(it->second->type, *segment_->at<Value>(it->second->slot)) + "\n";
        return;
    }
    if (auto it = pins_.find(name); it != pins_.end()) {
        out += format_value(it->second->type, read_pin(*it->second)) + "\n";
        return;
    }
    no_pin_or_param(a[0]);
}

void Runtime::cmd_sets(const std::vector<std::string>& a, std::string& out) {
    Signal& s = find_signal(a[0]);
    if (Pin* w = s.writer())
        throw Error(fmt::format("signal '{}' is driven by output pin '{}'; sets would be overwritten", s.name, w->name));
    *segment_->at<Value>(s.slot) = parse_or_throw(s.type, a[1], s.name);
}

void Runtime::cmd_gets(const std::vector<std::string>& a, std::string& out) {
    Signal& s = find_signal(a[0]);
    out += format_value(s.type, *segment_->at<Value>(s.slot)) + "\n";
}

void Runtime::cmd_ptype(const std::vector<std::string>& a, std::string& out) {
    auto name = resolve(a[0]);
    if (auto it = params_.find(name); it != params_.end()) {
        out += fmt::format("{}\n", to_string(it->second->type));
        return;
    }
    out += fmt::format("{}\n", to_string(find_pin(a[0]).type));
}

void Runtime::cmd_stype(const std::vector<std::string>& a, std::string& out) {
    out += fmt::format("{}\n", to_string(find_signal(a[0]).type));
}

// Threads and functions ----------------------------------------------------------------------------

void Runtime::add_time_pin(const std::string& name, Component* owner, void** field, std::uint64_t cell) {
    if (pins_.count(name)) throw Error(fmt::format("duplicate pin '{}'", name));
    auto* c = segment_->at<PinCell>(cell);
    c->own.u64 = 0;
    c->data_offset.store(segment_->offset_of(&c->own));
    *field = &c->own;
    pins_[name] = std::make_unique<Pin>(Pin{name, Type::S32, Dir::Out, owner, field, cell, nullptr});
}

namespace {
// A function's or thread's timing param: its name after the owner's, where it lies in the
// owner's timing block, its type and direction.
struct TimingParam {
    const char* suffix;
    std::size_t offset;
    Type type;
    ParamDir dir;
};
}  // namespace

void Runtime::add_funct_timing(Funct& f, LoadTransaction& building) {
    const auto pin = f.name + ".time";
    add_time_pin(pin, f.component, &f.time_pin, building.allocate(sizeof(PinCell)));
    building.pins.push_back(pin);
    f.timing = building.allocate(sizeof(FunctTiming));
    *segment_->at<FunctTiming>(f.timing) = FunctTiming{};
    for (auto p : {TimingParam{"tmax", offsetof(FunctTiming, tmax), Type::S32, ParamDir::RW},
                   TimingParam{"tmax-increased", offsetof(FunctTiming, tmax_increased), Type::Bit, ParamDir::RO}}) {
        auto name = fmt::format("{}.{}", f.name, p.suffix);
        if (params_.count(name)) throw Error(fmt::format("duplicate parameter '{}'", name));
        params_[name] = std::make_unique<ParamRecord>(ParamRecord{name, p.type, p.dir, f.component, f.timing + p.offset, true});
        building.params.push_back(name);
    }
}

Thread& Runtime::create_thread(const std::string& name, std::int64_t period_ns, bool fp, int cpu) {
    check_item_name(name);
    if (threads_.count(name)) throw Error(fmt::format("thread '{}' already exists", name));
    if (period_ns < 1000) throw Error(fmt::format("thread '{}': period {} ns is below 1 us", name, period_ns));
    if (cpu >= 0 && cpu >= static_cast<int>(std::thread::hardware_concurrency()))
        throw Error(fmt::format("thread '{}': cpu={} but this machine has {} cpus", name, cpu,
                                std::thread::hardware_concurrency()));
    const auto time_pin = name + ".time";
    if (pins_.count(time_pin)) throw Error(fmt::format("thread '{}': pin '{}' already exists", name, time_pin));
    auto stats_off = segment_->allocate(sizeof(ThreadStats));
    auto* stats = segment_->at<ThreadStats>(stats_off);
    // Simulated time reads no clock, so nothing is sampled unless asked for.
    stats->funct_sample = sim_clock_ ? 0 : 1000;
    auto t = std::make_unique<Thread>(name, period_ns, fp, cpu, stats);
    t->next_deadline_ns = sim_now_ns_ + period_ns;
    for (auto p : {TimingParam{"tmax", offsetof(ThreadStats, tmax), Type::S32, ParamDir::RW},
                   TimingParam{"wakeup-err", offsetof(ThreadStats, wakeup_err_ns), Type::S64, ParamDir::RO},
                   TimingParam{"wakeup-err-max", offsetof(ThreadStats, wakeup_max_ns), Type::S64, ParamDir::RW},
                   TimingParam{"late-cycles", offsetof(ThreadStats, late_cycles), Type::U64, ParamDir::RO},
                   TimingParam{"cycles", offsetof(ThreadStats, cycles), Type::U64, ParamDir::RO},
                   TimingParam{"funct-sample", offsetof(ThreadStats, funct_sample), Type::U32, ParamDir::RW}}) {
        auto pname = fmt::format("{}.{}", name, p.suffix);
        params_[pname] = std::make_unique<ParamRecord>(ParamRecord{pname, p.type, p.dir, nullptr, stats_off + p.offset, true});
    }
    add_time_pin(time_pin, nullptr, t->time_pin_field(), segment_->allocate(sizeof(PinCell)));
    auto& ref = *t;
    thread_order_.push_back(t.get());
    threads_[name] = std::move(t);
    if (running_ && sim_clock_) ref.next_deadline_ns = sim_now_ns_ + period_ns;
    return ref;
}

void Runtime::cmd_newthread(const std::vector<std::string>& a, std::string& out) {
    auto period = parse_value(Type::S64, a[1]);
    if (!period || period->s64 <= 0)
        throw Error(fmt::format("period '{}' is not a positive number of nanoseconds", a[1]));
    bool fp = true;
    int cpu = -1;
    for (std::size_t i = 2; i < a.size(); ++i) {
        if (a[i] == "fp") fp = true;
        else if (a[i] == "nofp") fp = false;
        else if (a[i].rfind("cpu=", 0) == 0) {
            auto c = parse_value(Type::S32, a[i].substr(4));
            if (!c || c->s32 < 0) throw Error(fmt::format("'{}': expected cpu=N with N >= 0", a[i]));
            cpu = c->s32;
        } else {
            throw Error(fmt::format("unknown option '{}' (expected fp, nofp or cpu=N)", a[i]));
        }
    }
    auto& t = create_thread(a[0], period->s64, fp, cpu);
    if (running_ && !sim_clock_)
        if (auto w = t.start(90); !w.empty()) out += w + "\n";
}

void Runtime::cmd_delthread(const std::vector<std::string>& a, std::string& out) {
    Thread& t = find_thread(a[0]);
    t.stop();
    for (Funct* f : t.functs()) f->users.erase(std::remove(f->users.begin(), f->users.end(), &t), f->users.end());
    for (const char* suffix : {"tmax", "wakeup-err", "wakeup-err-max", "late-cycles", "cycles", "funct-sample"})
        params_.erase(fmt::format("{}.{}", t.name(), suffix));
    if (auto it = pins_.find(t.name() + ".time"); it != pins_.end()) {
        if (it->second->signal) unlink(*it->second);
        segment_->release(it->second->cell, sizeof(PinCell));
        pins_.erase(it);
    }
    thread_order_.erase(std::remove(thread_order_.begin(), thread_order_.end(), &t), thread_order_.end());
    threads_.erase(a[0]);
}

void Runtime::cmd_addf(const std::vector<std::string>& a, std::string& out) {
    Funct& f = find_funct(a[0]);
    Thread& t = find_thread(a[1]);
    if (!f.users.empty())
        throw Error(fmt::format("function '{}' is already in thread '{}'; a function runs in one thread only",
                                f.name, f.users.front()->name()));
    if (f.uses_fp && !t.uses_fp())
        throw Error(fmt::format("function '{}' uses floating point but thread '{}' was created nofp", f.name, t.name()));
    auto list = t.functs();
    long pos = -1;
    if (a.size() == 3) {
        auto p = parse_value(Type::S32, a[2]);
        if (!p || p->s32 == 0) throw Error(fmt::format("position '{}' must be a non-zero integer", a[2]));
        pos = p->s32;
    }
    long n = static_cast<long>(list.size());
    long index = pos > 0 ? std::min(pos - 1, n) : std::max(0L, n + 1 + pos);
    list.insert(list.begin() + index, &f);
    t.set_functs(list, *segment_);
    f.users.push_back(&t);
}

void Runtime::cmd_delf(const std::vector<std::string>& a, std::string& out) {
    Funct& f = find_funct(a[0]);
    if (a.size() == 2) {
        Thread& t = find_thread(a[1]);
        if (std::find(f.users.begin(), f.users.end(), &t) == f.users.end())
            throw Error(fmt::format("function '{}' is not in thread '{}'", f.name, t.name()));
    }
    if (f.users.empty()) throw Error(fmt::format("function '{}' is not in any thread", f.name));
    for (Thread* t : f.users) {
        auto list = t->functs();
        list.erase(std::remove(list.begin(), list.end(), &f), list.end());
        t->set_functs(list, *segment_);
    }
    f.users.clear();
}

void Runtime::set_instance_states(InstanceState state) {
    for (auto& c : components_) {
        for (auto& inst : c->instances) {
            if (inst->state == state) continue;
            if (state == InstanceState::Running) inst->object->start();
            else if (inst->state == InstanceState::Running) inst->object->stop();
            inst->state = state;
        }
    }
}

void Runtime::cmd_start(const std::vector<std::string>& a, std::string& out) {
    if (running_) return;
    set_instance_states(InstanceState::Running);
    running_ = true;
    if (sim_clock_) {
        for (Thread* t : thread_order_) t->next_deadline_ns = sim_now_ns_ + t->period_ns();
        return;
    }
    // Page faults on a realtime thread cost milliseconds; lock memory once, when permitted.
    // MCL_ONFAULT locks pages as they are touched, so the sparse segment reservation is not
    // committed in full.
    if (!memory_locked_ && ::mlockall(MCL_CURRENT | MCL_FUTURE | MCL_ONFAULT) == 0) memory_locked_ = true;
    // Faster threads get higher priority, as in LinuxCNC.
    std::vector<Thread*> by_period = thread_order_;
    std::stable_sort(by_period.begin(), by_period.end(),
                     [](Thread* x, Thread* y) { return x->period_ns() < y->period_ns(); });
    int priority = 90;
    std::string warning;
    for (Thread* t : by_period) {
        auto w = t->start(priority > 1 ? priority-- : 1);
        if (!w.empty() && warning.empty()) warning = w;
    }
    if (!warning.empty()) out += "warning: " + warning + "\n";
}

void Runtime::cmd_stop(const std::vector<std::string>& a, std::string& out) {
    for (Thread* t : thread_order_) t->stop();
    if (running_) set_instance_states(InstanceState::Stopped);
    running_ = false;
}

void Runtime::cmd_advance(const std::vector<std::string>& a, std::string& out) {
    if (!sim_clock_) throw Error("advance works only with a simulated clock (halrun --sim-clock)");
    auto secs = parse_value(Type::Float, a[0]);
    if (!secs || secs->f < 0 || secs->f > 1e6)
        throw Error(fmt::format("'{}' is not a duration in seconds (0 to 1e6)", a[0]));
    const std::int64_t end = sim_now_ns_ + std::llround(secs->f * 1e9);
    if (running_) {
        while (true) {
            Thread* next = nullptr;
            for (Thread* t : thread_order_)
                if (!next || t->next_deadline_ns < next->next_deadline_ns ||
                    (t->next_deadline_ns == next->next_deadline_ns && t->period_ns() < next->period_ns()))
                    next = t;
            if (!next || next->next_deadline_ns > end) break;
            sim_now_ns_ = next->next_deadline_ns;
            next->run_sim_cycle();
        }
    }
    sim_now_ns_ = end;
}

// Aliases, locks, status ----------------------------------------------------------------------------

void Runtime::cmd_alias(const std::vector<std::string>& a, std::string& out) {
    if (a[0] != "pin" && a[0] != "param") throw Error(fmt::format("alias takes pin or param, not '{}'", a[0]));
    std::string real = a[0] == "pin" ? find_pin(a[1]).name : find_param(a[1]).name;
    check_item_name(a[2]);
    if (pins_.count(a[2]) || params_.count(a[2]) || aliases_.count(a[2]))
        throw Error(fmt::format("'{}' is already a pin, parameter or alias name", a[2]));
    for (auto it = aliases_.begin(); it != aliases_.end();)
        it = it->second == real ? aliases_.erase(it) : std::next(it);
    aliases_[a[2]] = real;
}

void Runtime::cmd_unalias(const std::vector<std::string>& a, std::string& out) {
    if (a[0] != "pin" && a[0] != "param") throw Error(fmt::format("unalias takes pin or param, not '{}'", a[0]));
    auto it = aliases_.find(a[1]);
    bool right_kind = it != aliases_.end() && (a[0] == "pin" ? pins_.count(it->second) : params_.count(it->second));
    if (!right_kind) throw Error(fmt::format("no {} alias '{}'", a[0], a[1]));
    aliases_.erase(it);
}

namespace {
int lock_bits(const std::vector<std::string>& a) {
    std::string level = a.empty() ? "all" : a[0];
    if (level == "none") return 0;
    if (level == "load") return 1;
    if (level == "config") return 3;
    if (level == "tune") return 3;
    if (level == "params") return 7;
    if (level == "all") return 15;
    throw Error(fmt::format("unknown lock level '{}' (none, load, config, tune, params, all)", level));
}
}  // namespace

void Runtime::cmd_lock(const std::vector<std::string>& a, std::string& out) { lock_ |= lock_bits(a); }
void Runtime::cmd_unlock(const std::vector<std::string>& a, std::string& out) { lock_ &= ~lock_bits(a); }

void Runtime::cmd_help(const std::vector<std::string>& a, std::string& out) {
    for (auto& c : commands())
        if (a.empty() || a[0] == c.name) out += fmt::format("  {}\n", c.usage);
    if (a.empty()) {
        out += "  source FILE\n  echo WORDS...\n  loadusr [-W|-w|-i|-Wn NAME] PROGRAM [ARGS...]\n"
               "  waitusr COMPONENT\n  PIN = VALUE   (same as setp)\n  quit | exit\n";
    } else if (out.empty()) {
        auto near = nearest_name(a[0], command_names());
        throw Error(fmt::format("no command '{}'{}", a[0], near.empty() ? "" : fmt::format(" (did you mean '{}'?)", near)));
    }
}

void Runtime::cmd_status(const std::vector<std::string>& a, std::string& out) {
    out += fmt::format("instance {}  clock {}  threads {}\n", paths_.instance,
                       sim_clock_ ? fmt::format("simulated ({:.9f} s)", sim_now_ns_ * 1e-9) : "real-time",
                       running_ ? "running" : "stopped");
    out += fmt::format("shared memory {} bytes used of {} reserved\n", segment_->bytes_in_use(), segment_->size());
    out += fmt::format("lock: {}\n", lock_ == 0 ? "none" : fmt::format("0x{:x}", lock_));
}

// Userspace components ----------------------------------------------------------------------------

int Runtime::user_component(const std::string& name, pid_t pid) {
    std::lock_guard lock(mutex_);
    check_item_name(name);
    for (auto& c : components_)
        if (c->name == name) throw Error(fmt::format("component '{}' already exists", name));
    auto c = std::make_unique<Component>();
    c->name = name;
    c->id = next_component_id_++;
    c->realtime = false;
    c->pid = pid;
    components_.push_back(std::move(c));
    return components_.back()->id;
}

namespace {
Component* by_id(std::vector<std::unique_ptr<Component>>& cs, int id) {
    for (auto& c : cs)
        if (c->id == id) return c.get();
    throw Error(fmt::format("no component with id {}", id));
}
}  // namespace

std::uint64_t Runtime::user_pin(int comp_id, const std::string& name, Type type, Dir dir) {
    std::lock_guard lock(mutex_);
    Component* c = by_id(components_, comp_id);
    check_item_name(name);
    if (pins_.count(name)) throw Error(fmt::format("duplicate pin '{}'", name));
    auto cell = segment_->allocate(sizeof(PinCell));
    auto* pc = segment_->at<PinCell>(cell);
    pc->data_offset.store(segment_->offset_of(&pc->own));
    pins_[name] = std::make_unique<Pin>(Pin{name, type, dir, c, nullptr, cell, nullptr});
    return cell;
}

std::uint64_t Runtime::user_param(int comp_id, const std::string& name, Type type, ParamDir dir) {
    std::lock_guard lock(mutex_);
    Component* c = by_id(components_, comp_id);
    check_item_name(name);
    if (params_.count(name)) throw Error(fmt::format("duplicate parameter '{}'", name));
    auto slot = segment_->allocate(sizeof(Value));
    params_[name] = std::make_unique<ParamRecord>(ParamRecord{name, type, dir, c, slot});
    return slot;
}

void Runtime::user_ready(int comp_id) {
    std::lock_guard lock(mutex_);
    by_id(components_, comp_id)->ready = true;
}

void Runtime::user_exit(int comp_id) {
    std::lock_guard lock(mutex_);
    for (auto& c : components_)
        if (c->id == comp_id) {
            unload_component(*c);
            return;
        }
}

Runtime::Lookup Runtime::lookup(const std::string& raw) const {
    std::lock_guard lock(mutex_);
    auto name = resolve(raw);
    if (auto it = pins_.find(name); it != pins_.end())
        return {"pin", it->second->type, static_cast<int>(it->second->dir), it->second->cell};
    if (auto it = params_.find(name); it != params_.end())
        return {"param", it->second->type, static_cast<int>(it->second->dir), it->second->slot};
    if (auto it = signals_.find(name); it != signals_.end())
        return {"sig", it->second->type, 0, it->second->slot};
    throw Error(fmt::format("no pin, parameter or signal '{}'", raw));
}

std::uint64_t Runtime::stream_offset(const std::string& name) const {
    std::lock_guard lock(mutex_);
    auto it = streams_.find(name);
    if (it == streams_.end()) {
        std::vector<std::string> known;
        for (auto& [k, v] : streams_) known.push_back(k);
        auto near = nearest_name(name, known);
        throw Error(fmt::format("no stream '{}'{}", name, near.empty() ? "" : fmt::format(" (did you mean '{}'?)", near)));
    }
    return it->second;
}

}  // namespace hal
