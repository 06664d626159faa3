#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string>

#include <fmt/format.h>

#include "hal/component.hpp"
#include "hal/types.hpp"
#include "ring.hpp"

namespace hal {

std::string_view to_string(Type t) noexcept {
    switch (t) {
        case Type::Bit: return "bit";
        case Type::Float: return "float";
        case Type::S32: return "s32";
        case Type::U32: return "u32";
        case Type::S64: return "s64";
        case Type::U64: return "u64";
    }
    return "?";
}

std::string_view to_string(Dir d) noexcept {
    switch (d) {
        case Dir::In: return "IN";
        case Dir::Out: return "OUT";
        case Dir::IO: return "I/O";
    }
    return "?";
}

std::string_view to_string(ParamDir d) noexcept { return d == ParamDir::RO ? "RO" : "RW"; }

std::optional<Type> parse_type(std::string_view s) noexcept {
    for (Type t : {Type::Bit, Type::Float, Type::S32, Type::U32, Type::S64, Type::U64})
        if (s == to_string(t)) return t;
    return std::nullopt;
}

namespace {
template <class T>
std::optional<T> parse_integer(std::string_view text) {
    std::string s(text);
    if (s.empty()) return std::nullopt;
    char* end = nullptr;
    errno = 0;
    if constexpr (std::is_signed_v<T>) {
        long long v = std::strtoll(s.c_str(), &end, 0);
        if (errno || *end || v < std::numeric_limits<T>::min() || v > std::numeric_limits<T>::max())
            return std::nullopt;
        return static_cast<T>(v);
    } else {
        if (s[0] == '-') return std::nullopt;
        unsigned long long v = std::strtoull(s.c_str(), &end, 0);
        if (errno || *end || v > std::numeric_limits<T>::max()) return std::nullopt;
        return static_cast<T>(v);
    }
}
}  // namespace

std::optional<Value> parse_value(Type t, std::string_view text) noexcept {
    Value v{};
    switch (t) {
        case Type::Bit:
            if (text == "1" || text == "TRUE" || text == "true") v.b = true;
            else if (text == "0" || text == "FALSE" || text == "false") v.b = false;
            else return std::nullopt;
            return v;
        case Type::Float: {
            std::string s(text);
            if (s.empty()) return std::nullopt;
            char* end = nullptr;
            // nan and inf are accepted as LinuxCNC does: a user may need to inject one to
            // test a component's guard; strtod takes both spellings.
            v.f = std::strtod(s.c_str(), &end);
            if (*end) return std::nullopt;
            return v;
        }
        case Type::S32:
            if (auto x = parse_integer<std::int32_t>(text)) v.s32 = *x; else return std::nullopt;
            return v;
        case Type::U32:
            if (auto x = parse_integer<std::uint32_t>(text)) v.u32 = *x; else return std::nullopt;
            return v;
        case Type::S64:
            if (auto x = parse_integer<std::int64_t>(text)) v.s64 = *x; else return std::nullopt;
            return v;
        case Type::U64:
            if (auto x = parse_integer<std::uint64_t>(text)) v.u64 = *x; else return std::nullopt;
            return v;
    }
    return std::nullopt;
}

std::string format_value(Type t, Value v, bool for_show) {
    switch (t) {
        case Type::Bit: return v.b ? "TRUE" : "FALSE";
        case Type::Float: {
            char buf[32];
            std::snprintf(buf, sizeof buf, "%.7g", v.f);
            return buf;
        }
        case Type::S32: return std::to_string(v.s32);
        case Type::U32: return for_show ? fmt::format("0x{:08X}", v.u32) : std::to_string(v.u32);
        case Type::S64: return std::to_string(v.s64);
        case Type::U64: return for_show ? fmt::format("0x{:016X}", v.u64) : std::to_string(v.u64);
    }
    return "?";
}

std::string format_indexed_name(std::string_view pattern, std::size_t index) {
    return fmt::format(fmt::runtime(pattern), index);
}

std::uint32_t parse_layout(std::string_view layout, Type* types) {
    if (layout.empty()) throw Error("stream layout is empty (expected letters b f s u l k)");
    if (layout.size() > kMaxStreamFields)
        throw Error(fmt::format("stream layout '{}' has {} fields; at most {}", layout,
                                layout.size(), kMaxStreamFields));
    for (std::size_t i = 0; i < layout.size(); ++i) {
        switch (layout[i]) {
            case 'b': case 'B': types[i] = Type::Bit; break;
            case 'f': case 'F': types[i] = Type::Float; break;
            case 's': case 'S': types[i] = Type::S32; break;
            case 'u': case 'U': types[i] = Type::U32; break;
            case 'l': case 'L': types[i] = Type::S64; break;
            case 'k': case 'K': types[i] = Type::U64; break;
            default:
                throw Error(fmt::format(
                    "stream layout '{}': '{}' is not a field type (b=bit f=float s=s32 u=u32 "
                    "l=s64 k=u64)",
                    layout, layout[i]));
        }
    }
    return static_cast<std::uint32_t>(layout.size());
}

}  // namespace hal
