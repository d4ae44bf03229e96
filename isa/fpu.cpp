// Rounding FP operations on the host's SSE unit. x86 SSE single precision is IEEE 754 binary32
// with tininess detected after rounding, as RISC-V requires; MXCSR gives the four directed/nearest
// modes and the five flags. RISC-V's fifth mode, RMM (nearest, ties away), has no x86
// equivalent and is derived from an RTZ result (see round_ties_away).
//
// Compiled with -frounding-math; in addition every operation is fenced by empty volatile asm so
// the compiler can neither fold it nor move it across the MXCSR writes and reads.
#include "isa/fpu.hpp"

#include <cmath>
#include <type_traits>
#include <xmmintrin.h>

namespace tpsim::isa::fpu {
namespace {

/// MXCSR with all exceptions masked, flags clear, round-to-nearest, no FTZ/DAZ: the host default.
constexpr uint32_t kMxcsrDefault = 0x1f80;
/// MXCSR RC field (bits 14:13) for RNE, RTZ, RDN, RUP.
constexpr uint32_t kMxcsrRounding[4] = {0u << 13, 3u << 13, 1u << 13, 2u << 13};

/// Maps MXCSR flag bits IE DE ZE OE UE PE (0..5) to RISC-V NV DZ OF UF NX; DE has no RISC-V twin.
uint32_t riscv_flags(uint32_t mxcsr) {
    return ((mxcsr & 0x01) ? NV : 0) | ((mxcsr & 0x04) ? DZ : 0) | ((mxcsr & 0x08) ? OF : 0) |
           ((mxcsr & 0x10) ? UF : 0) | ((mxcsr & 0x20) ? NX : 0);
}

/// The value, hidden from the optimizer: an operation on it cannot move above this point.
template <class T> inline T opaque(T value) {
    if constexpr (std::is_integral_v<T>)
        asm volatile("" : "+r"(value));
    else
        asm volatile("" : "+x"(value));
    return value;
}

/// Runs `op` (float or double) in x86 rounding mode `rm` (0..3) with cleared host flags, adds the
/// raised flags to fflags and restores the host default mode.
template <class Op> inline auto run_rounded(unsigned rm, uint32_t& fflags, Op op) {
    _mm_setcsr(kMxcsrDefault | kMxcsrRounding[rm]);
    const auto result = opaque(op());
    const uint32_t mxcsr = _mm_getcsr();
    if (rm != RNE) _mm_setcsr(kMxcsrDefault);
    fflags |= riscv_flags(mxcsr);
    return result;
}

uint32_t canonical(float result) {
    return std::isnan(result) ? kCanonicalNaN : std::bit_cast<uint32_t>(result);
}

/// RMM from RTZ: the tie-away result differs from the truncated one t only when the exact result
/// lies at or beyond the midpoint between t and its neighbour away from zero. That midpoint has
/// 25 significant bits, so it is exact in double, and `exact_rtz` (the op evaluated in double
/// with RTZ) compares against it exactly as the infinitely precise result would.
uint32_t round_ties_away(float truncated, uint32_t truncated_flags, double exact_rtz,
                         uint32_t& fflags) {
    uint32_t bits = std::bit_cast<uint32_t>(truncated);
    if ((truncated_flags & NX) && std::isfinite(truncated)) {
        const uint32_t away = bits + 1;  // next magnitude up; FLT_MAX + 1 ulp is +-inf
        const double midpoint = (away & 0x7fff'ffff) == 0x7f80'0000
                                    ? 0x1.ffffffp+127  // halfway between FLT_MAX and 2^128
                                    : (double(truncated) + double(std::bit_cast<float>(away))) / 2;
        if (std::fabs(exact_rtz) >= std::fabs(midpoint)) {
            bits = away;
            if ((away & 0x7fff'ffff) == 0x7f80'0000) truncated_flags |= OF;
        }
        // Tininess after rounding, at RMM: results that round (unbounded exponent) up to 2^-126
        // are not tiny although RTZ found them tiny.
        if ((truncated_flags & UF) && std::fabs(exact_rtz) >= 0x1p-126 - 0x1p-151)
            truncated_flags &= ~uint32_t{UF};
    }
    fflags |= truncated_flags;
    return std::isnan(truncated) ? kCanonicalNaN : bits;
}

/// Evaluates a rounding operation in any RISC-V mode: `single` computes in float, `wide` the
/// same operation in double (only needed for RMM).
template <class Single, class Wide>
inline uint32_t rounded(unsigned rm, uint32_t& fflags, Single single, Wide wide) {
    if (rm != RMM) [[likely]]
        return canonical(run_rounded(rm, fflags, single));
    uint32_t truncated_flags = 0;
    const float truncated = run_rounded(RTZ, truncated_flags, single);
    uint32_t ignored = 0;
    const double exact_rtz = run_rounded(RTZ, ignored, wide);
    return round_ties_away(truncated, truncated_flags, exact_rtz, fflags);
}

float as_float(uint32_t bits) {
    return std::bit_cast<float>(bits);
}

/// A two-operand rounding operation, `op` written once for float and double.
template <class Op> uint32_t binary(uint32_t a, uint32_t b, unsigned rm, uint32_t& fflags, Op op) {
    const float x = as_float(a), y = as_float(b);
    return rounded(
        rm, fflags, [&] { return op(opaque(x), opaque(y)); },
        [&] { return op(opaque(double(x)), opaque(double(y))); });
}

}  // namespace

uint32_t reference::add(uint32_t a, uint32_t b, unsigned rm, uint32_t& fflags) {
    return binary(a, b, rm, fflags, [](auto x, auto y) { return x + y; });
}

uint32_t reference::sub(uint32_t a, uint32_t b, unsigned rm, uint32_t& fflags) {
    return binary(a, b, rm, fflags, [](auto x, auto y) { return x - y; });
}

uint32_t reference::mul(uint32_t a, uint32_t b, unsigned rm, uint32_t& fflags) {
    return binary(a, b, rm, fflags, [](auto x, auto y) { return x * y; });
}

uint32_t reference::div(uint32_t a, uint32_t b, unsigned rm, uint32_t& fflags) {
    return binary(a, b, rm, fflags, [](auto x, auto y) { return x / y; });
}

uint32_t reference::sqrt(uint32_t a, unsigned rm, uint32_t& fflags) {
    const float x = as_float(a);
    return rounded(
        rm, fflags, [&] { return std::sqrt(opaque(x)); },
        [&] { return std::sqrt(opaque(double(x))); });
}

uint32_t reference::fma(uint32_t a, uint32_t b, uint32_t c, unsigned rm, uint32_t& fflags) {
    const float x = as_float(a), y = as_float(b), z = as_float(c);
    // RISC-V requires NV for inf*0 even when the addend is a quiet NaN (IEEE leaves it open).
    if (((std::isinf(x) && y == 0) || (x == 0 && std::isinf(y))) && std::isnan(z)) fflags |= NV;
    return rounded(
        rm, fflags, [&] { return std::fma(opaque(x), opaque(y), opaque(z)); },
        [&] { return std::fma(opaque(double(x)), opaque(double(y)), opaque(double(z))); });
}

namespace {

/// Whether a result rounded in the host default mode, RNE, needs no flag but NX: it is finite,
/// normal and above the smallest normal (biased exponent 2..254). Then OF is impossible (finite
/// at RNE), UF too (the exact value exceeds 2^-126: not tiny), and NV and DZ give only NaN or
/// infinity. 2^-126 itself is left to MXCSR: a tiny exact value can round up to it and raise UF.
bool flags_at_most_nx(float result) {
    return ((std::bit_cast<uint32_t>(result) >> 23) & 0xff) - 2 < 0xfd;
}

/// Knuth's TwoSum: the exact rounding error of s = x + y, in round-to-nearest without overflow.
template <class T> T sum_error(T x, T y, T s) {
    const T y_part = s - x, x_part = s - y_part;
    return (x - x_part) + (y - y_part);
}

uint32_t nearest(float result, bool inexact, uint32_t& fflags) {
    if (inexact) fflags |= NX;
    return std::bit_cast<uint32_t>(result);
}

}  // namespace

// RNE fast paths. The host MXCSR is at its default whenever fpu code runs (run_rounded leaves it
// there), so plain host arithmetic already rounds RNE; when flags_at_most_nx holds, NX is decided
// by an exact test below and MXCSR is never touched. Other results and modes take the exact path.

uint32_t add(uint32_t a, uint32_t b, unsigned rm, uint32_t& fflags) {
    if (rm == RNE) [[likely]] {
        const float x = opaque(as_float(a)), y = opaque(as_float(b)), s = x + y;
        if (flags_at_most_nx(s)) [[likely]]
            return nearest(s, sum_error(x, y, s) != 0, fflags);
    }
    return reference::add(a, b, rm, fflags);
}

uint32_t sub(uint32_t a, uint32_t b, unsigned rm, uint32_t& fflags) {
    if (rm == RNE) [[likely]] {
        const float x = opaque(as_float(a)), y = -opaque(as_float(b)), s = x + y;
        if (flags_at_most_nx(s)) [[likely]]
            return nearest(s, sum_error(x, y, s) != 0, fflags);
    }
    return reference::sub(a, b, rm, fflags);
}

// A product of two floats has at most 48 significant bits and an exponent within double's normal
// range, so it is exact in double: x * y, r * y (for r = x / y) and r * r (for r = sqrt(x)).

uint32_t mul(uint32_t a, uint32_t b, unsigned rm, uint32_t& fflags) {
    if (rm == RNE) [[likely]] {
        const float x = opaque(as_float(a)), y = opaque(as_float(b)), r = x * y;
        if (flags_at_most_nx(r)) [[likely]]
            return nearest(r, double(r) != double(x) * double(y), fflags);
    }
    return reference::mul(a, b, rm, fflags);
}

uint32_t div(uint32_t a, uint32_t b, unsigned rm, uint32_t& fflags) {
    if (rm == RNE) [[likely]] {
        const float x = opaque(as_float(a)), y = opaque(as_float(b)), r = x / y;
        if (flags_at_most_nx(r)) [[likely]]
            return nearest(r, double(r) * double(y) != double(x), fflags);
    }
    return reference::div(a, b, rm, fflags);
}

uint32_t sqrt(uint32_t a, unsigned rm, uint32_t& fflags) {
    if (rm == RNE) [[likely]] {
        const float x = opaque(as_float(a)), r = std::sqrt(x);
        if (flags_at_most_nx(r)) [[likely]]
            return nearest(r, double(r) * double(r) != double(x), fflags);
    }
    return reference::sqrt(a, rm, fflags);
}

uint32_t fma(uint32_t a, uint32_t b, uint32_t c, unsigned rm, uint32_t& fflags) {
    if (rm == RNE) [[likely]] {
        const float x = opaque(as_float(a)), y = opaque(as_float(b)), z = opaque(as_float(c));
        const float r = std::fma(x, y, z);
        if (flags_at_most_nx(r)) [[likely]] {
            // x * y is exact in double and TwoSum splits p + z exactly into s + e (no overflow:
            // |p + z| < 2^257), so the result r is exact iff s == r and e == 0.
            const double p = double(x) * double(y), s = p + double(z);
            return nearest(r, s != double(r) || sum_error(p, double(z), s) != 0, fflags);
        }
    }
    return reference::fma(a, b, c, rm, fflags);
}

uint32_t cvt_s_w(int32_t a, unsigned rm, uint32_t& fflags) {
    return rounded(
        rm, fflags, [&] { return float(opaque(a)); }, [&] { return double(a); });
}

uint32_t cvt_s_wu(uint32_t a, unsigned rm, uint32_t& fflags) {
    return rounded(
        rm, fflags, [&] { return float(opaque(a)); }, [&] { return double(a); });
}

namespace {

/// Rounds a finite float to an integer-valued double per rm; sets `inexact` if it changed.
/// Pure arithmetic on exact values: trunc and the subtraction below are exact in double.
double round_to_integer(float value, unsigned rm, bool& inexact) {
    const double v = value, truncated = std::trunc(v), fraction = v - truncated;
    inexact = fraction != 0;
    const double away = truncated + (v < 0 ? -1 : 1);
    switch (rm) {
    case RTZ:
        return truncated;
    case RDN:
        return fraction < 0 ? truncated - 1 : truncated;
    case RUP:
        return fraction > 0 ? truncated + 1 : truncated;
    case RMM:
        return std::fabs(fraction) >= 0.5 ? away : truncated;
    default:  // RNE
        if (std::fabs(fraction) > 0.5) return away;
        if (std::fabs(fraction) < 0.5) return truncated;
        return std::fmod(truncated, 2) == 0 ? truncated : away;
    }
}

/// Shared by fcvt.w.s and fcvt.wu.s: saturate to [lowest, highest] with NV, else NX if inexact.
uint32_t convert_to_integer(uint32_t a, unsigned rm, uint32_t& fflags, double lowest,
                            double highest, uint32_t nan_result) {
    if (is_nan(a)) return fflags |= NV, nan_result;
    const float value = as_float(a);
    if (std::isinf(value)) return fflags |= NV, uint32_t(int64_t(value < 0 ? lowest : highest));
    bool inexact = false;
    const double r = round_to_integer(value, rm, inexact);
    if (r < lowest) return fflags |= NV, uint32_t(int64_t(lowest));
    if (r > highest) return fflags |= NV, uint32_t(int64_t(highest));
    if (inexact) fflags |= NX;
    return uint32_t(int64_t(r));
}

}  // namespace

uint32_t cvt_w_s(uint32_t a, unsigned rm, uint32_t& fflags) {
    return convert_to_integer(a, rm, fflags, -2147483648.0, 2147483647.0, 0x7fff'ffff);
}

uint32_t cvt_wu_s(uint32_t a, unsigned rm, uint32_t& fflags) {
    return convert_to_integer(a, rm, fflags, 0.0, 4294967295.0, 0xffff'ffff);
}

}  // namespace tpsim::isa::fpu
