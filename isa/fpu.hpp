// RISC-V F arithmetic on raw single-precision bit patterns, exact to the unprivileged spec
// (20191213): five rounding modes, accrued flags, canonical NaN. Operations that round run on the
// host SSE unit in fpu.cpp (compiled with -frounding-math); the rest are exact bit logic here.
#pragma once
#include <bit>
#include <cstdint>

namespace tpsim::isa::fpu {

/// fflags bits (RISC-V order).
constexpr uint32_t NX = 1, UF = 2, OF = 4, DZ = 8, NV = 16;

/// Static rounding modes (the rm field and frm). 5 and 6 are reserved, 7 means "use frm".
enum RoundingMode : unsigned { RNE = 0, RTZ = 1, RDN = 2, RUP = 3, RMM = 4, DYN = 7 };

constexpr uint32_t kSignBit = 0x8000'0000;
constexpr uint32_t kCanonicalNaN = 0x7fc0'0000;

// Rounding arithmetic. rm must be 0..4 (already resolved); flags are OR-ed into `fflags`.
// At RNE, add/sub/mul/div/sqrt/fma take a fast path that leaves MXCSR alone when the result is
// a normal above 2^-126 (see fpu.cpp); everything else goes to the exact MXCSR path, `reference`.
uint32_t add(uint32_t a, uint32_t b, unsigned rm, uint32_t& fflags);
uint32_t sub(uint32_t a, uint32_t b, unsigned rm, uint32_t& fflags);
uint32_t mul(uint32_t a, uint32_t b, unsigned rm, uint32_t& fflags);
uint32_t div(uint32_t a, uint32_t b, unsigned rm, uint32_t& fflags);
uint32_t sqrt(uint32_t a, unsigned rm, uint32_t& fflags);
/// a*b + c rounded once; the fmsub/fnm* variants pass a and/or c with the sign bit flipped.
uint32_t fma(uint32_t a, uint32_t b, uint32_t c, unsigned rm, uint32_t& fflags);
namespace reference {
/// The exact MXCSR path for every operand and mode: the fast paths' fallback and test oracle.
uint32_t add(uint32_t a, uint32_t b, unsigned rm, uint32_t& fflags);
uint32_t sub(uint32_t a, uint32_t b, unsigned rm, uint32_t& fflags);
uint32_t mul(uint32_t a, uint32_t b, unsigned rm, uint32_t& fflags);
uint32_t div(uint32_t a, uint32_t b, unsigned rm, uint32_t& fflags);
uint32_t sqrt(uint32_t a, unsigned rm, uint32_t& fflags);
uint32_t fma(uint32_t a, uint32_t b, uint32_t c, unsigned rm, uint32_t& fflags);
}  // namespace reference
uint32_t cvt_s_w(int32_t a, unsigned rm, uint32_t& fflags);
uint32_t cvt_s_wu(uint32_t a, unsigned rm, uint32_t& fflags);
/// Float to integer: rounds per rm, saturates out-of-range values (NaN -> largest) with NV.
uint32_t cvt_w_s(uint32_t a, unsigned rm, uint32_t& fflags);
uint32_t cvt_wu_s(uint32_t a, unsigned rm, uint32_t& fflags);

// Exact operations: bit logic only, no host FP state involved.
constexpr bool is_nan(uint32_t a) {
    return (a & 0x7fff'ffff) > 0x7f80'0000;
}
constexpr bool is_signaling_nan(uint32_t a) {
    return is_nan(a) && !(a & 0x0040'0000);
}
constexpr bool is_zero(uint32_t a) {
    return (a & 0x7fff'ffff) == 0;
}

/// Orders non-NaN floats as the integers -|x| < ... < +|x|, with -0 below +0.
constexpr int64_t total_key(uint32_t a) {
    const int64_t magnitude = a & 0x7fff'ffff;
    return (a & kSignBit) ? -magnitude - 1 : magnitude;
}

/// IEEE 754-2019 minimumNumber/maximumNumber, as fmin.s/fmax.s define them.
constexpr uint32_t min_max(uint32_t a, uint32_t b, bool want_max, uint32_t& fflags) {
    if (is_signaling_nan(a) || is_signaling_nan(b)) fflags |= NV;
    if (is_nan(a) && is_nan(b)) return kCanonicalNaN;
    if (is_nan(a)) return b;
    if (is_nan(b)) return a;
    return (total_key(a) < total_key(b)) == want_max ? b : a;
}
constexpr uint32_t min(uint32_t a, uint32_t b, uint32_t& fflags) {
    return min_max(a, b, false, fflags);
}
constexpr uint32_t max(uint32_t a, uint32_t b, uint32_t& fflags) {
    return min_max(a, b, true, fflags);
}

/// Numeric comparison key: like total_key but with -0 == +0.
constexpr int64_t numeric_key(uint32_t a) {
    return is_zero(a) ? 0 : total_key(a);
}

/// feq.s is a quiet comparison: only signaling NaNs raise NV.
constexpr uint32_t eq(uint32_t a, uint32_t b, uint32_t& fflags) {
    if (is_nan(a) || is_nan(b)) {
        if (is_signaling_nan(a) || is_signaling_nan(b)) fflags |= NV;
        return 0;
    }
    return numeric_key(a) == numeric_key(b);
}
/// flt.s/fle.s are signaling comparisons: any NaN raises NV.
constexpr uint32_t lt(uint32_t a, uint32_t b, uint32_t& fflags) {
    if (is_nan(a) || is_nan(b)) return fflags |= NV, 0;
    return numeric_key(a) < numeric_key(b);
}
constexpr uint32_t le(uint32_t a, uint32_t b, uint32_t& fflags) {
    if (is_nan(a) || is_nan(b)) return fflags |= NV, 0;
    return numeric_key(a) <= numeric_key(b);
}

/// fclass.s: exactly one of bits 0..9 set (-inf, -normal, -subnormal, -0, +0, +subnormal,
/// +normal, +inf, signaling NaN, quiet NaN).
constexpr uint32_t classify(uint32_t a) {
    const bool negative = a & kSignBit;
    const uint32_t exponent = (a >> 23) & 0xff, fraction = a & 0x7f'ffff;
    if (exponent == 0xff) {
        if (fraction == 0) return negative ? 1u << 0 : 1u << 7;
        return is_signaling_nan(a) ? 1u << 8 : 1u << 9;
    }
    if (exponent == 0) {
        if (fraction == 0) return negative ? 1u << 3 : 1u << 4;
        return negative ? 1u << 2 : 1u << 5;
    }
    return negative ? 1u << 1 : 1u << 6;
}

}  // namespace tpsim::isa::fpu
