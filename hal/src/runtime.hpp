// The HAL instance as its owning process sees it: the registry of components, pins,
// params, signals, functions and threads, and one method per bus command. Configuration
// world only: every public method takes the config mutex; realtime code never calls here.
#pragma once

#include <sys/types.h>

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include "hal/component.hpp"
#include "segment.hpp"

namespace hal {

class Thread;
struct Component;
struct Signal;

// The shared-memory side of a pin: where its value currently lives (its own slot while
// unlinked, the signal's once linked), so processes other than the owner can follow it.
struct PinCell {
    std::atomic<std::uint64_t> data_offset;
    Value own;
};

struct Pin {
    std::string name;
    Type type;
    Dir dir;
    Component* component;
    void** pointer_field;  // the In/Out/IO member's pointer (in-process components), or null
    std::uint64_t cell;    // PinCell offset
    Signal* signal = nullptr;
};

struct ParamRecord {
    std::string name;
    Type type;
    ParamDir dir;
    Component* component;
    std::uint64_t slot;
    bool timing = false;  // written by the thread runner, not part of a saved configuration
};

struct Signal {
    std::string name;
    Type type;
    std::uint64_t slot;
    std::vector<Pin*> pins;  // in link order; at most one Out (or IO writers only)
    Pin* writer() const;
};

// Per-function timing params, written by the thread that samples the function (the RT side
// only stores). Each field is one param slot: `<funct>.tmax` (s32, ns, saturated at
// INT32_MAX; setp 0 resets it) and `<funct>.tmax-increased` (bit: the last timed call raised
// tmax). `<funct>.time` is a pin, so it lives in its own cell or a signal (Funct::time_pin).
struct FunctTiming {
    Value tmax;
    Value tmax_increased;
};

struct Funct {
    std::string name;
    RealtimeFn fn;
    RealtimeBatchFn batch;  // null: never grouped (shared functions already loop)
    void* object;
    bool uses_fp;
    Component* component;
    std::vector<Thread*> users;
    std::uint64_t timing;  // FunctTiming offset in the segment
    // Where the `<funct>.time` pin's value lives now (an s32 slot: its own, or its signal's);
    // retargeted by link/unlink, read by the thread that times the function.
    void* time_pin = nullptr;
};

// State of one instance of a loaded component (DESIGN: loaded -> configured -> running <->
// stopped, plus fault).
enum class InstanceState { Configured, Running, Stopped };

}  // namespace hal

namespace hal {
struct LoadTransaction;
}

namespace hal::detail {
// What an instance knows of itself (name, index, loadrt arguments); during loadrt also
// where its registrations go.
struct InstanceContext {
    Runtime* runtime;
    LoadTransaction* building;
    Component* component;
    std::string name;
    int index;
    std::map<std::string, std::string> args;
    bool has_functions = false;
    static thread_local InstanceContext* current;
};
}  // namespace hal::detail

namespace hal {

struct InstanceRecord {
    std::string name;
    std::unique_ptr<detail::InstanceContext> context;  // declared first: outlives the object
    std::unique_ptr<Instance> object;
    InstanceState state = InstanceState::Configured;
};

struct SharedFunct;

struct Component {
    std::string name;
    int id;
    bool realtime;  // loaded with loadrt (else a userspace component attached by a client)
    void* library = nullptr;
    const ComponentDescriptor* descriptor = nullptr;
    std::string path;
    std::vector<std::unique_ptr<InstanceRecord>> instances;
    std::vector<std::unique_ptr<SharedFunct>> shared_functs;
    std::vector<std::vector<std::string>> load_args;  // each loadrt line's arguments, for save
    std::vector<std::string> streams;  // names its instances registered (any name, not only prefixed)
    pid_t pid = 0;  // userspace: the process that owns it
    bool ready = false;
};

// One component-wide function: calls the same member on every instance, in load order.
struct SharedFunct {
    RealtimeFn fn;
    std::vector<void*> objects;
    static void call_all(void* self, Period p) noexcept;
};

struct Location {
    std::string file;
    int line = 0;
};

enum class LockLevel { None = 0, Load = 1, Config = 2, Tune = 4, All = 7 };

class Runtime {
public:
    struct Options {
        std::string instance = "default";
        std::size_t segment_bytes = kDefaultSegmentBytes;
        bool sim_clock = false;
    };
    explicit Runtime(const Options& options);
    ~Runtime();
    Runtime(const Runtime&) = delete;
    Runtime& operator=(const Runtime&) = delete;

    // Executes one bus command (already tokenized, substitutions done). Output goes to `out`.
    // Throws hal::Error; a failed command changes nothing.
    void execute(const std::vector<std::string>& words, std::string& out);
    bool is_bus_command(std::string_view word) const;
    std::vector<std::string> command_names() const;
    // Names for completion and "did you mean" suggestions.
    std::vector<std::string> names(std::string_view kind) const;

    // Userspace components (driven by the socket server on behalf of client processes).
    int user_component(const std::string& name, pid_t pid);
    std::uint64_t user_pin(int comp_id, const std::string& name, Type type, Dir dir);
    std::uint64_t user_param(int comp_id, const std::string& name, Type type, ParamDir dir);
    void user_ready(int comp_id);
    void user_exit(int comp_id);
    bool component_exists(const std::string& name) const;
    bool component_ready(const std::string& name) const;
    // Lookups for clients: offset of a pin cell / param slot / signal slot / stream ring.
    struct Lookup {
        std::string kind;
        Type type;
        int dir;
        std::uint64_t offset;
    };
    Lookup lookup(const std::string& name) const;
    std::uint64_t stream_offset(const std::string& name) const;

    const InstancePaths& paths() const noexcept { return paths_; }
    Segment& segment() noexcept { return *segment_; }
    bool sim_clock() const noexcept { return sim_clock_; }
    // Stops threads and unloads everything (in reverse load order).
    void shutdown();

    // Used by the registration functions while loadrt constructs instances.
    friend struct LoadTransaction;
    friend void* detail::register_pin(Instance&, std::string_view, Type, Dir, Value, void*);
    friend void* detail::register_param(Instance&, std::string_view, Type, ParamDir, Value);
    friend void detail::register_function(Instance&, std::string_view, RealtimeFn, RealtimeBatchFn, void*, bool);
    friend void detail::register_shared_function(Instance&, std::string_view, RealtimeFn, void*, bool);
    friend void* detail::register_stream(Instance&, std::string_view, std::string_view, std::uint32_t);
    friend void* detail::attach_stream(Instance&, std::string_view, std::string_view);

private:
    using Handler = void (Runtime::*)(const std::vector<std::string>&, std::string&);
    struct CommandSpec {
        const char* name;
        Handler handler;
        int min_args;
        int max_args;  // -1: unbounded
        LockLevel blocked_by;
        const char* usage;
    };
    static const std::vector<CommandSpec>& commands();

    void cmd_loadrt(const std::vector<std::string>& a, std::string& out);
    void cmd_unload(const std::vector<std::string>& a, std::string& out);
    void cmd_net(const std::vector<std::string>& a, std::string& out);
    void cmd_newsig(const std::vector<std::string>& a, std::string& out);
    void cmd_delsig(const std::vector<std::string>& a, std::string& out);
    void cmd_linkps(const std::vector<std::string>& a, std::string& out);
    void cmd_linksp(const std::vector<std::string>& a, std::string& out);
    void cmd_linkpp(const std::vector<std::string>& a, std::string& out);
    void cmd_unlinkp(const std::vector<std::string>& a, std::string& out);
    void cmd_setp(const std::vector<std::string>& a, std::string& out);
    void cmd_getp(const std::vector<std::string>& a, std::string& out);
    void cmd_sets(const std::vector<std::string>& a, std::string& out);
    void cmd_gets(const std::vector<std::string>& a, std::string& out);
    void cmd_ptype(const std::vector<std::string>& a, std::string& out);
    void cmd_stype(const std::vector<std::string>& a, std::string& out);
    void cmd_addf(const std::vector<std::string>& a, std::string& out);
    void cmd_delf(const std::vector<std::string>& a, std::string& out);
    void cmd_newthread(const std::vector<std::string>& a, std::string& out);
    void cmd_delthread(const std::vector<std::string>& a, std::string& out);
    void cmd_start(const std::vector<std::string>& a, std::string& out);
    void cmd_stop(const std::vector<std::string>& a, std::string& out);
    void cmd_show(const std::vector<std::string>& a, std::string& out);
    void cmd_list(const std::vector<std::string>& a, std::string& out);
    void cmd_save(const std::vector<std::string>& a, std::string& out);
    void cmd_alias(const std::vector<std::string>& a, std::string& out);
    void cmd_unalias(const std::vector<std::string>& a, std::string& out);
    void cmd_lock(const std::vector<std::string>& a, std::string& out);
    void cmd_unlock(const std::vector<std::string>& a, std::string& out);
    void cmd_advance(const std::vector<std::string>& a, std::string& out);
    void cmd_status(const std::vector<std::string>& a, std::string& out);
    void cmd_help(const std::vector<std::string>& a, std::string& out);

    void load_threads_component(const std::vector<std::string>& a);
    void load_component(const std::string& name, const std::vector<std::string>& args);
    // A LinuxCNC module name's alias file resolved (runtime.cpp, find_alias): the component,
    // its arguments, and the threads to make once it has loaded.
    void load_alias(const std::string& target, const std::vector<std::string>& args,
                    const std::vector<std::pair<std::string, std::int64_t>>& threads);
    void unload_component(Component& c);
    Thread& create_thread(const std::string& name, std::int64_t period_ns, bool fp, int cpu);
    // LinuxCNC's timing objects (docs/hal.md, Threads): `<name>.time`, an s32 output pin in
    // `cell` (allocated by the caller, so a loadrt transaction can take it back) whose current
    // storage the thread runner follows through `field`; a thread's has no owner component.
    void add_time_pin(const std::string& name, Component* owner, void** field, std::uint64_t cell);
    // A function's `.time` pin, `.tmax` and `.tmax-increased` params, undone with `building`.
    void add_funct_timing(Funct& f, LoadTransaction& building);

    std::string resolve(const std::string& name) const;  // alias -> real name
    Pin& find_pin(const std::string& name) const;
    ParamRecord& find_param(const std::string& name) const;
    Signal& find_signal(const std::string& name) const;
    Funct& find_funct(const std::string& name) const;
    Thread& find_thread(const std::string& name) const;
    Component& find_component(const std::string& name) const;
    [[noreturn]] void no_pin_or_param(const std::string& name) const;
    [[noreturn]] void not_found(std::string_view kind, const std::string& name,
                                std::string_view candidates_kind) const;

    Signal& new_signal(const std::string& name, Type type);
    void check_link(const Pin& pin, const Signal& sig) const;
    void link(Pin& pin, Signal& sig);
    void link_checked(const std::string& pin_name, const std::string& signal_name);
    // Links every pin to the signal (made if absent) after checking them all: all or none.
    void net_pins(const std::string& sig_name, std::vector<Pin*> pins);
    void unlink(Pin& pin);
    void retarget(Pin& pin, std::uint64_t data_offset);
    void remove_pin(Pin& pin);
    void check_name_free(const std::string& name) const;

    void show_comps(const std::vector<std::string>& pats, std::string& out) const;
    void show_pins(const std::vector<std::string>& pats, std::string& out) const;
    void show_params(const std::vector<std::string>& pats, std::string& out) const;
    void show_signals(const std::vector<std::string>& pats, std::string& out) const;
    void show_functs(const std::vector<std::string>& pats, std::string& out) const;
    void show_threads(const std::vector<std::string>& pats, std::string& out) const;
    void show_aliases(const std::vector<std::string>& pats, std::string& out) const;
    void save_to(const std::string& what, std::string& out) const;
    Value read_pin(const Pin& p) const;
    void set_instance_states(InstanceState state);

    // Storage for instance objects (Instance::operator new), freed with the runtime.
    struct Arena {
        std::vector<std::unique_ptr<std::byte[]>> chunks;
        std::size_t used = 0;      // bytes used in the last chunk
        std::size_t capacity = 0;  // size of the last chunk
        void* allocate(std::size_t bytes);
    };
    Arena instance_arena_;
    friend class Instance;

    mutable std::recursive_mutex mutex_;
    InstancePaths paths_;
    std::unique_ptr<Segment> segment_;
    bool sim_clock_;
    std::int64_t sim_now_ns_ = 0;
    bool running_ = false;
    bool memory_locked_ = false;
    int lock_ = 0;
    int next_component_id_ = 1;

    std::vector<std::unique_ptr<Component>> components_;  // load order
    std::map<std::string, std::unique_ptr<Pin>> pins_;
    std::map<std::string, std::unique_ptr<ParamRecord>> params_;
    std::map<std::string, std::unique_ptr<Signal>> signals_;
    std::map<std::string, std::unique_ptr<Funct>> functs_;
    std::map<std::string, std::unique_ptr<Thread>> threads_;
    std::vector<Thread*> thread_order_;  // creation order
    std::map<std::string, std::string> aliases_;  // alias -> real name
    std::map<std::string, std::uint64_t> streams_;  // name -> ring offset
};

// Closest candidate within a small edit distance, for "did you mean" hints.
std::string nearest_name(std::string_view name, const std::vector<std::string>& candidates);
bool name_matches(const std::vector<std::string>& patterns, const std::string& name);

}  // namespace hal
