// conv_<from>_<to>: converts a pin value between HAL types, LinuxCNC-compatible
// (`loadrt conv_float_s32`, instances conv-float-s32.N, function conv-float-s32.N).
//
// Built once per pair: CMake defines CONV_FROM and CONV_TO as HAL type names (bit, float,
// s32, u32). When the target type cannot hold every source value the component also has
// an `out-of-range` pin and a `clamp` param:
//   clamp TRUE:  a value beyond the target range gives the nearest limit; out-of-range TRUE.
//   clamp FALSE: the value wraps modulo the target width (bit: any nonzero value is TRUE);
//                out-of-range still reports whether `in` was outside the target range.
// Floats convert to integers by truncation toward zero. NaN, and floats too large to wrap
// meaningfully (beyond +-2^63), give the nearest limit (NaN gives 0) and out-of-range TRUE.
#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <utility>

#include "hal/component.hpp"

#if !defined(CONV_FROM) || !defined(CONV_TO)
#error "conv.cpp is built by components/conv/CMakeLists.txt with CONV_FROM and CONV_TO"
#endif

#define CONV_TYPE_bit bool
#define CONV_TYPE_float double
#define CONV_TYPE_s32 std::int32_t
#define CONV_TYPE_u32 std::uint32_t
#define CONV_PASTE2(a, b) a##b
#define CONV_PASTE(a, b) CONV_PASTE2(a, b)
#define CONV_NAME4(a, b, c, d) a##b##c##d
#define CONV_NAME(a, b, c, d) CONV_NAME4(a, b, c, d)
#define CONV_STR2(x) #x
#define CONV_STR(x) CONV_STR2(x)
// HAL_COMPONENT stringizes its first argument; this extra level expands the name first.
#define CONV_REGISTER(name, type, doc) HAL_COMPONENT(name, type, doc)

namespace {

using From = CONV_PASTE(CONV_TYPE_, CONV_FROM);
using To = CONV_PASTE(CONV_TYPE_, CONV_TO);

// std::cmp_less refuses bool; a bit compares as the integer 0 or 1.
template <class X>
constexpr auto as_integer(X value) noexcept {
    if constexpr (std::is_same_v<X, bool>)
        return static_cast<int>(value);
    else
        return value;
}

template <class T>
constexpr T target_min() {
    return std::is_same_v<T, bool> ? T{false} : std::numeric_limits<T>::min();
}
template <class T>
constexpr T target_max() {
    return std::is_same_v<T, bool> ? T{true} : std::numeric_limits<T>::max();
}

// True when some source value has no exact place in the target type's range.
template <class F, class T>
constexpr bool needs_range_check() {
    if constexpr (std::is_same_v<F, bool> || std::is_floating_point_v<T>)
        return false;
    else if constexpr (std::is_floating_point_v<F>)
        return true;
    else
        return std::cmp_less(std::numeric_limits<F>::min(), as_integer(target_min<T>())) ||
               std::cmp_greater(std::numeric_limits<F>::max(), as_integer(target_max<T>()));
}

template <class F, class T>
bool below_range(F value) noexcept {
    if constexpr (std::is_floating_point_v<F>)
        return value < static_cast<double>(target_min<T>());
    else
        return std::cmp_less(value, as_integer(target_min<T>()));
}
template <class F, class T>
bool above_range(F value) noexcept {
    if constexpr (std::is_floating_point_v<F>)
        return value > static_cast<double>(target_max<T>());
    else
        return std::cmp_greater(value, as_integer(target_max<T>()));
}

constexpr bool kUsesFloat = std::is_floating_point_v<From> || std::is_floating_point_v<To>;

// The unclamped conversion: exact in range, modular (or nonzero-is-TRUE) outside it.
template <class F, class T>
T wrap(F value) noexcept {
    if constexpr (std::is_same_v<T, bool>) {
        return value != 0;
    } else if constexpr (std::is_floating_point_v<F>) {
        constexpr double kInt64Bound = 9223372036854775808.0;  // 2^63
        if (std::isnan(value)) return T{0};
        if (value >= kInt64Bound) return target_max<T>();
        if (value < -kInt64Bound) return target_min<T>();
        return static_cast<T>(static_cast<std::int64_t>(value));
    } else {
        return static_cast<T>(value);
    }
}

// Templates so that only the variant a pair uses is compiled.
template <class F, class T>
struct Plain : hal::Instance {
    hal::In<F> in{this, "in"};
    hal::Out<T> out{this, "out"};

    Plain() { this->template function<&Plain::update>("", kUsesFloat); }
    void update(hal::Period) noexcept { out = static_cast<T>(in.get()); }
};

template <class F, class T>
struct Checked : hal::Instance {
    hal::In<F> in{this, "in"};
    hal::Out<T> out{this, "out"};
    hal::Out<bool> out_of_range{this, "out-of-range"};
    hal::Param<bool> clamp{this, "clamp", false};

    Checked() { this->template function<&Checked::update>("", kUsesFloat); }
    void update(hal::Period) noexcept {
        const F value = in;
        const bool low = below_range<F, T>(value);
        const bool high = above_range<F, T>(value);
        bool invalid = false;
        if constexpr (std::is_floating_point_v<F>) invalid = std::isnan(value);
        out_of_range = low || high || invalid;
        if (!clamp || invalid)
            out = wrap<F, T>(value);
        else if (high)
            out = target_max<T>();
        else if (low)
            out = target_min<T>();
        else
            out = static_cast<T>(value);
    }
};

using Conv = std::conditional_t<needs_range_check<From, To>(), Checked<From, To>, Plain<From, To>>;

}  // namespace

CONV_REGISTER(CONV_NAME(conv_, CONV_FROM, _, CONV_TO), Conv,
              "Convert a value from " CONV_STR(CONV_FROM) " to " CONV_STR(CONV_TO))
