// Value types shared by the bus runtime, components and clients.
#pragma once

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

namespace hal {

// Numeric values match LinuxCNC's hal_type_t / hal_pin_dir_t so saved files and habits carry over.
enum class Type : std::uint8_t { Bit = 1, Float = 2, S32 = 3, U32 = 4, S64 = 5, U64 = 6 };
enum class Dir : std::uint8_t { In = 16, Out = 32, IO = 48 };
enum class ParamDir : std::uint8_t { RO = 64, RW = 192 };

// The period handed to every realtime function: the thread's nominal period, exact in
// simulated-clock mode, so outputs are reproducible.
struct Period {
    std::int64_t ns;
    double s;
    static constexpr Period from_ns(std::int64_t period_ns) noexcept {
        return Period{period_ns, static_cast<double>(period_ns) * 1e-9};
    }
};

// One 8-byte slot of bus storage. Every pin, param and signal value occupies one, 8-byte
// aligned, so any process can read or write it with a single plain (relaxed atomic) access.
union Value {
    bool b;
    double f;
    std::int32_t s32;
    std::uint32_t u32;
    std::int64_t s64;
    std::uint64_t u64;
};
static_assert(sizeof(Value) == 8);

template <class T>
struct TypeOf;
template <>
struct TypeOf<bool> {
    static constexpr Type value = Type::Bit;
};
template <>
struct TypeOf<double> {
    static constexpr Type value = Type::Float;
};
template <>
struct TypeOf<std::int32_t> {
    static constexpr Type value = Type::S32;
};
template <>
struct TypeOf<std::uint32_t> {
    static constexpr Type value = Type::U32;
};
template <>
struct TypeOf<std::int64_t> {
    static constexpr Type value = Type::S64;
};
template <>
struct TypeOf<std::uint64_t> {
    static constexpr Type value = Type::U64;
};

std::string_view to_string(Type t) noexcept;
std::string_view to_string(Dir d) noexcept;
std::string_view to_string(ParamDir d) noexcept;
std::optional<Type> parse_type(std::string_view s) noexcept;

// Parses a value written by a user (setp/sets, INI) for a given type: bit accepts
// 0/1/TRUE/FALSE, integers accept decimal, 0x hex and 0 octal, float anything strtod does.
std::optional<Value> parse_value(Type t, std::string_view text) noexcept;
// LinuxCNC's spelling: TRUE/FALSE, %.7g style floats, 0x%08X for u32 in `show`.
std::string format_value(Type t, Value v, bool for_show = false);

// Configuration-world error: loaders, parsers and commands throw it; the caller adds the
// file and line. Never thrown on a realtime path.
class Error : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

}  // namespace hal
