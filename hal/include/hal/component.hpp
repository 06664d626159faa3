// The component API: everything a component .so includes.
//
// A component is one file: a struct deriving from hal::Instance whose pins and params are
// typed members that register themselves, one small realtime function, and one
// HAL_COMPONENT(...) line. Example:
//
//     struct And2 : hal::Instance {
//         hal::In<bool> in0{this, "in0"}, in1{this, "in1"};
//         hal::Out<bool> out{this, "out"};
//         void update(hal::Period) noexcept { out = in0 && in1; }
//     };
//     HAL_COMPONENT(and2, And2, "Two-input AND gate")
//
// Two worlds: constructors run in the configuration world (may allocate, throw hal::Error,
// read args); functions registered with function<>() run on a HAL thread and must be
// noexcept, allocation-, lock- and syscall-free and bounded in time.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "hal/types.hpp"

namespace hal {

inline constexpr std::uint32_t kAbiVersion = 1;

class Instance;
class Runtime;
using RealtimeFn = void (*)(void* object, Period period) noexcept;
// The same function over consecutive instances of one component in a thread: the runtime
// calls it once for a run of them, so the per-instance cost is an inlined call, not an
// indirect one (a chain of 1000 and2 is one call, not 1000).
using RealtimeBatchFn = void (*)(void* const* objects, std::size_t count, Period period) noexcept;

namespace detail {
struct InstanceContext;  // runtime-owned; opaque to components

// Implemented by the runtime (libcnchal). Only callable while an instance is being
// constructed by loadrt; they throw hal::Error on a duplicate or malformed name.
void* register_pin(Instance& owner, std::string_view name, Type type, Dir dir, Value initial,
                   void* pointer_field);
void* register_param(Instance& owner, std::string_view name, Type type, ParamDir dir,
                     Value initial);
void register_function(Instance& owner, std::string_view suffix, RealtimeFn fn,
                       RealtimeBatchFn batch, void* object, bool uses_fp);
void register_shared_function(Instance& owner, std::string_view name, RealtimeFn fn,
                              void* object, bool uses_fp);
void* register_stream(Instance& owner, std::string_view name, std::string_view layout,
                      std::uint32_t depth);
void* attach_stream(Instance& owner, std::string_view name, std::string_view layout);
InstanceContext* current_context();

template <class C, auto Method>
void call_one(void* object, Period p) noexcept {
    (static_cast<C*>(object)->*Method)(p);
}
template <class C, auto Method>
void call_batch(void* const* objects, std::size_t count, Period p) noexcept {
    for (std::size_t i = 0; i < count; ++i) (static_cast<C*>(objects[i])->*Method)(p);
}

template <class M>
struct MemberOf;
template <class C, class R, class... A>
struct MemberOf<R (C::*)(A...) noexcept> {
    using type = C;
};

template <class T>
Value to_value(T v) noexcept {
    Value out{};
    if constexpr (std::is_same_v<T, bool>) out.b = v;
    else if constexpr (std::is_same_v<T, double>) out.f = v;
    else if constexpr (std::is_same_v<T, std::int32_t>) out.s32 = v;
    else if constexpr (std::is_same_v<T, std::uint32_t>) out.u32 = v;
    else if constexpr (std::is_same_v<T, std::int64_t>) out.s64 = v;
    else out.u64 = v;
    return out;
}

// Realtime access to one slot of bus storage: a relaxed atomic is a plain load/store on
// every target we build for, and keeps cross-process readers free of torn values.
template <class T>
inline T load(T* p) noexcept {
    return std::atomic_ref<T>(*p).load(std::memory_order_relaxed);
}
template <class T>
inline void store(T* p, T v) noexcept {
    std::atomic_ref<T>(*p).store(v, std::memory_order_relaxed);
}
}  // namespace detail

// Pin, param and function names are prefixed with the instance name ("in0" -> "and2.0.in0");
// a name starting with '=' is taken as it is ("=joint.0.motor-pos-cmd"), for components that
// must publish LinuxCNC's fixed names.
//
// Per-instance view of the loadrt line, e.g. `loadrt sampler depth=1000,200 cfg=ffb,bb`.
// A comma list gives one value per instance; arg() returns this instance's item.
class Instance {
public:
    Instance();
    Instance(const Instance&) = delete;
    Instance& operator=(const Instance&) = delete;
    virtual ~Instance();

    std::string_view name() const noexcept;  // "and2.0", or the name from names=
    int index() const noexcept;              // 0-based position in the loadrt line
    // This instance's item of a loadrt argument (`personality=3,4` -> "4" for index 1).
    std::optional<std::string> arg(std::string_view key) const;
    // arg() parsed as an integer, with a clear error for junk; fallback when absent.
    long arg_int(std::string_view key, long fallback) const;

    // Lifecycle hooks, configuration world. start() runs when a thread carrying one of this
    // instance's functions starts, stop() when it stops.
    virtual void start() {}
    virtual void stop() {}

    // Instances are packed into one arena per runtime, in load order, so a thread running a
    // component's instances one after another walks contiguous memory.
    static void* operator new(std::size_t size);
    static void operator delete(void* p) noexcept;

    // Realtime-safe: moves the instance to the fault state (`show comp` shows it).
    void raise_fault() noexcept;
    void clear_fault() noexcept;
    bool faulted() const noexcept;

protected:
    // Exports a realtime function named after the instance ("and2.0") when suffix is
    // empty, else "<instance>.<suffix>" ("pid.x.do-pid-calcs").
    template <auto Method>
    void function(std::string_view suffix = "", bool uses_fp = true) {
        using C = typename detail::MemberOf<decltype(Method)>::type;
        detail::register_function(*this, suffix, &detail::call_one<C, Method>,
                                  &detail::call_batch<C, Method>, static_cast<C*>(this), uses_fp);
    }
    // One function for all instances of the component ("encoder.update-counters"), as
    // LinuxCNC's hand-written drivers export: it calls Method on every instance in order.
    // A name starting with '=' is used as it is ("=process_wsums"), without the prefix.
    template <auto Method>
    void shared_function(std::string_view name, bool uses_fp = true) {
        using C = typename detail::MemberOf<decltype(Method)>::type;
        detail::register_shared_function(
            *this, name, [](void* o, Period p) noexcept { (static_cast<C*>(o)->*Method)(p); },
            static_cast<C*>(this), uses_fp);
    }

private:
    friend struct detail::InstanceContext;
    friend class Runtime;
    detail::InstanceContext* ctx_;
    std::atomic<bool> fault_{false};
};

template <class T>
class In {
public:
    In(Instance* owner, std::string_view name, T initial = T{}) {
        ptr_ = static_cast<T*>(detail::register_pin(*owner, name, TypeOf<T>::value, Dir::In,
                                                    detail::to_value(initial), &ptr_));
    }
    In(const In&) = delete;
    In& operator=(const In&) = delete;
    T get() const noexcept { return detail::load(std::atomic_ref<T*>(ptr_).load(std::memory_order_relaxed)); }
    operator T() const noexcept { return get(); }

private:
    mutable T* ptr_;  // retargeted by the runtime when the pin is linked or unlinked
};

// An input pin whose own storage the component may also write (LinuxCNC's pid computes its
// command-deriv when nothing drives it, and writes back tuned gains). Reads follow the linked
// signal when there is one; set_own() always writes the pin's own storage, which is what an
// unlinked pin reads, so a signal's value is never overwritten by a reader.
template <class T>
class SelfWritableIn {
public:
    SelfWritableIn(Instance* owner, std::string_view name, T initial = T{}) {
        own_ = static_cast<T*>(detail::register_pin(*owner, name, TypeOf<T>::value, Dir::In,
                                                    detail::to_value(initial), &ptr_));
        ptr_ = own_;
    }
    SelfWritableIn(const SelfWritableIn&) = delete;
    SelfWritableIn& operator=(const SelfWritableIn&) = delete;
    T get() const noexcept { return detail::load(std::atomic_ref<T*>(ptr_).load(std::memory_order_relaxed)); }
    operator T() const noexcept { return get(); }
    void set_own(T v) noexcept { detail::store(own_, v); }

private:
    mutable T* ptr_;  // retargeted by the runtime when the pin is linked or unlinked
    T* own_;
};

template <class T>
class Out {
public:
    Out(Instance* owner, std::string_view name, T initial = T{}) {
        ptr_ = static_cast<T*>(detail::register_pin(*owner, name, TypeOf<T>::value, Dir::Out,
                                                    detail::to_value(initial), &ptr_));
    }
    Out(const Out&) = delete;
    Out& operator=(const Out&) = delete;
    void set(T v) noexcept { detail::store(std::atomic_ref<T*>(ptr_).load(std::memory_order_relaxed), v); }
    Out& operator=(T v) noexcept {
        set(v);
        return *this;
    }

private:
    T* ptr_;
};

template <class T>
class IO {
public:
    IO(Instance* owner, std::string_view name, T initial = T{}) {
        ptr_ = static_cast<T*>(detail::register_pin(*owner, name, TypeOf<T>::value, Dir::IO,
                                                    detail::to_value(initial), &ptr_));
    }
    IO(const IO&) = delete;
    IO& operator=(const IO&) = delete;
    T get() const noexcept { return detail::load(std::atomic_ref<T*>(ptr_).load(std::memory_order_relaxed)); }
    operator T() const noexcept { return get(); }
    void set(T v) noexcept { detail::store(std::atomic_ref<T*>(ptr_).load(std::memory_order_relaxed), v); }
    IO& operator=(T v) noexcept {
        set(v);
        return *this;
    }

private:
    mutable T* ptr_;
};

// A pin whose type is chosen at load time (sampler's and streamer's cfg=ffb): reads and
// writes whole 8-byte Values; the field of the Value that matters is the one of type().
class AnyPin {
public:
    AnyPin(Instance* owner, std::string_view name, Type type, Dir dir, Value initial = Value{})
        : type_(type) {
        initial.u64 = type == Type::Bit ? std::uint64_t{initial.b} : initial.u64;
        ptr_ = detail::register_pin(*owner, name, type, dir, initial, &ptr_);
    }
    AnyPin(const AnyPin&) = delete;
    AnyPin& operator=(const AnyPin&) = delete;
    Type type() const noexcept { return type_; }
    Value get() const noexcept {
        Value v;
        v.u64 = detail::load(static_cast<std::uint64_t*>(std::atomic_ref<void*>(ptr_).load(std::memory_order_relaxed)));
        return v;
    }
    void set(Value v) noexcept {
        if (type_ == Type::Bit) v.u64 = v.b ? 1 : 0;  // keep the slot's unused bytes zero
        detail::store(static_cast<std::uint64_t*>(std::atomic_ref<void*>(ptr_).load(std::memory_order_relaxed)), v.u64);
    }

private:
    Type type_;
    mutable void* ptr_;
};

// A parameter: like a pin that can never be linked. RO params are written only by the
// component (timing figures, counters); RW ones by setp as well.
template <class T>
class Param {
public:
    Param(Instance* owner, std::string_view name, T initial = T{}, ParamDir dir = ParamDir::RW)
        : ptr_(static_cast<T*>(detail::register_param(*owner, name, TypeOf<T>::value, dir,
                                                      detail::to_value(initial)))) {}
    Param(const Param&) = delete;
    Param& operator=(const Param&) = delete;
    T get() const noexcept { return detail::load(ptr_); }
    operator T() const noexcept { return get(); }
    void set(T v) noexcept { detail::store(ptr_, v); }
    Param& operator=(T v) noexcept {
        set(v);
        return *this;
    }

private:
    T* ptr_;
};

// N pins or params named from a pattern with one {} for the index ("in{}" -> in0, in1;
// "out-{:02}" -> out-00). Storage is allocated once; elements never move, which the
// runtime relies on to retarget linked pins.
template <class P>
class Array {
public:
    template <class... Extra>
    Array(Instance* owner, std::string_view pattern, std::size_t count, Extra&&... extra)
        : count_(count), storage_(new std::byte[sizeof(P) * (count ? count : 1)]) {
        for (; built_ < count_; ++built_)
            new (slot(built_)) P(owner, format_name(pattern, built_), extra...);
    }
    Array(const Array&) = delete;
    Array& operator=(const Array&) = delete;
    ~Array() {
        while (built_ > 0) slot(--built_)->~P();
    }
    P& operator[](std::size_t i) noexcept { return *slot(i); }
    const P& operator[](std::size_t i) const noexcept { return *slot(i); }
    std::size_t size() const noexcept { return count_; }

private:
    P* slot(std::size_t i) const noexcept { return std::launder(reinterpret_cast<P*>(storage_.get()) + i); }
    static std::string format_name(std::string_view pattern, std::size_t index);
    std::size_t count_;
    std::size_t built_ = 0;
    std::unique_ptr<std::byte[]> storage_;
};

std::string format_indexed_name(std::string_view pattern, std::size_t index);
template <class P>
std::string Array<P>::format_name(std::string_view pattern, std::size_t index) {
    return format_indexed_name(pattern, index);
}

// A stream endpoint owned by a component: a lock-free single-producer/single-consumer ring
// of fixed-size records in the shared segment. `layout` has one letter per field, LinuxCNC's
// sampler/streamer cfg letters: b=bit f=float s=s32 u=u32 l=s64 k=u64.
class Stream {
public:
    Stream(Instance* owner, std::string_view name, std::string_view layout, std::uint32_t depth);
    // The other end of a stream that an instance loaded earlier registered, for a component
    // that consumes (or produces) another's stream in-process: motion reading the interp
    // component's canonical commands. Only from a constructor during loadrt; throws
    // hal::Error when there is no such stream or its layout differs from `layout`. The ring
    // stays valid after its owner is unloaded (rings live as long as the HAL instance); it
    // just receives nothing more. Either end must still be used by one thread only.
    static Stream attach(Instance* owner, std::string_view name, std::string_view layout);
    std::size_t fields() const noexcept;
    Type field_type(std::size_t i) const noexcept;
    // Realtime-safe. push() fails (and counts an overrun) when the ring is full; pop() fails
    // when it is empty. Records are `fields()` Values long.
    bool push(const Value* record) noexcept;
    bool pop(Value* record) noexcept;
    std::uint32_t depth() const noexcept;
    std::uint32_t used() const noexcept;

private:
    explicit Stream(struct Ring* ring) noexcept : ring_(ring) {}
    struct Ring* ring_;
};

namespace detail {
// Builds an instance; if the type declares `update(Period) noexcept` and registered no
// function itself, that becomes the instance function, the way LinuxCNC's comp exports `_`.
template <class T>
Instance* create_instance();
bool registered_functions(const Instance& inst) noexcept;
}  // namespace detail

template <class T>
Instance* detail::create_instance() {
    auto inst = std::make_unique<T>();
    if constexpr (requires(T& t, Period p) {
                      { t.update(p) } noexcept;
                  }) {
        if (!registered_functions(*inst)) {
            register_function(*inst, "", &call_one<T, &T::update>, &call_batch<T, &T::update>,
                              inst.get(), true);
        }
    }
    return inst.release();
}

// Naming rules a few LinuxCNC components need; the defaults suit almost all.
struct ComponentOptions {
    // Prefix of default instance names ("wsum" -> wsum.0); null: the component name with
    // '_' turned into '-' (conv_float_s32 -> conv-float-s32.0), as LinuxCNC's comp does.
    const char* prefix = nullptr;
    // A loadrt argument whose comma-list length is the default instance count
    // (weighted_sum's wsum_sizes=8,4 makes two summers).
    const char* count_from = nullptr;
    // Instances made when neither count=, names= nor count_from says (pid and encoder: 3).
    int default_count = 1;
};

struct ComponentDescriptor {
    std::uint32_t abi_version;  // first, and kept first by every future version
    const char* name;
    const char* doc;
    // loadrt arguments accepted besides count=, names= and num_chan=; null-terminated.
    const char* const* args;
    Instance* (*create)();
    ComponentOptions options;
};

}  // namespace hal

// The one entry point of a component .so. Extra arguments name the loadrt keys it accepts.
#define HAL_COMPONENT(NAME, TYPE, DOC, ...) \
    HAL_COMPONENT_WITH_OPTIONS(NAME, TYPE, DOC, (::hal::ComponentOptions{}) __VA_OPT__(, ) __VA_ARGS__)

// The same with naming options: HAL_COMPONENT_WITH_OPTIONS(weighted_sum, WeightedSum, "doc",
// (hal::ComponentOptions{.prefix = "wsum", .count_from = "wsum_sizes"}), "wsum_sizes")
#define HAL_COMPONENT_WITH_OPTIONS(NAME, TYPE, DOC, OPTIONS, ...)                              \
    extern "C" __attribute__((visibility("default"))) const ::hal::ComponentDescriptor*     \
    cnc_hal_component() {                                                                    \
        static const char* const args[] = {__VA_ARGS__ __VA_OPT__(, ) nullptr};              \
        static const ::hal::ComponentDescriptor descriptor{                                 \
            ::hal::kAbiVersion, #NAME, DOC, args, &::hal::detail::create_instance<TYPE>,     \
            OPTIONS};                                                                        \
        return &descriptor;                                                                  \
    }
