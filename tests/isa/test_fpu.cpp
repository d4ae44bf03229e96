// F-extension corner cases through execute(). Every expected value is derived by hand from the
// RISC-V unprivileged spec (ch. 11) and IEEE 754-2008; the derivation is in the comment.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>

#include "tests/isa/test_support.hpp"

using namespace tpsim::isa;
using namespace tpsim::isa::test;
using namespace tpsim::isa::fpu;

namespace {

struct FpResult {
    uint32_t value;
    uint32_t flags;
    bool operator==(const FpResult&) const = default;
};

std::ostream& operator<<(std::ostream& os, const FpResult& r) {
    return os << std::hex << "{0x" << r.value << ", flags 0x" << r.flags << "}";
}

/// Runs `op` with rs1 = a, rs2 = b, rs3 = c (in both register files, so integer-source ops see
/// them too) and static rounding mode rm; returns rd and the accrued flags.
FpResult fp(Op op, uint32_t a, uint32_t b = 0, uint32_t rm = RNE, uint32_t c = 0) {
    Hart h;
    FakeEnv env;
    h.reg[1] = h.reg[kFpBase + 1] = a;
    h.reg[2] = h.reg[kFpBase + 2] = b;
    h.reg[kFpBase + 3] = c;
    run(h, env, encode(op, 10, 1, 2, 0, rm, 3));
    REQUIRE(env.illegals == 0);
    const bool fp_destination = info(op).operands.rd == RegKind::Fp;
    return {h.reg[fp_destination ? kFpBase + 10 : 10], h.fflags};
}

constexpr uint32_t kOne = 0x3f80'0000, kTwo = 0x4000'0000, kThree = 0x4040'0000;
constexpr uint32_t kOneUlp = 0x3f80'0001;   // 1 + 2^-23
constexpr uint32_t kTwoUlps = 0x3f80'0002;  // 1 + 2^-22
constexpr uint32_t kHalfUlp = 0x3380'0000;  // 2^-24: half an ulp of 1.0
constexpr uint32_t kMinusOne = 0xbf80'0000, kMinusOneUlp = 0xbf80'0001;
constexpr uint32_t kInf = 0x7f80'0000, kMinusInf = 0xff80'0000;
constexpr uint32_t kMax = 0x7f7f'ffff;        // FLT_MAX
constexpr uint32_t kMinNormal = 0x0080'0000;  // 2^-126
constexpr uint32_t kMinSub = 0x0000'0001;     // 2^-149
constexpr uint32_t kQNaN = 0x7fc0'0000, kSNaN = 0x7f80'0001, kPayloadQNaN = 0x7fc1'2345;
constexpr uint32_t kPlusZero = 0, kMinusZero = 0x8000'0000;

}  // namespace

TEST_CASE("fadd.s in every rounding mode", "[isa][fpu][rounding]") {
    // 1 + 2^-24 is exactly halfway between 1 and 1 + 2^-23: ties-even keeps 1 (even
    // significand), ties-away and up go to 1 + 2^-23, toward-zero and down keep 1.
    CHECK(fp(Op::fadd_s, kOne, kHalfUlp, RNE) == FpResult{kOne, NX});
    CHECK(fp(Op::fadd_s, kOne, kHalfUlp, RMM) == FpResult{kOneUlp, NX});
    CHECK(fp(Op::fadd_s, kOne, kHalfUlp, RTZ) == FpResult{kOne, NX});
    CHECK(fp(Op::fadd_s, kOne, kHalfUlp, RDN) == FpResult{kOne, NX});
    CHECK(fp(Op::fadd_s, kOne, kHalfUlp, RUP) == FpResult{kOneUlp, NX});
    // Mirrored: -1 - 2^-24: down and away go to -(1 + 2^-23), up and toward zero keep -1.
    CHECK(fp(Op::fadd_s, kMinusOne, kHalfUlp | kSignBit, RNE) == FpResult{kMinusOne, NX});
    CHECK(fp(Op::fadd_s, kMinusOne, kHalfUlp | kSignBit, RMM) == FpResult{kMinusOneUlp, NX});
    CHECK(fp(Op::fadd_s, kMinusOne, kHalfUlp | kSignBit, RTZ) == FpResult{kMinusOne, NX});
    CHECK(fp(Op::fadd_s, kMinusOne, kHalfUlp | kSignBit, RDN) == FpResult{kMinusOneUlp, NX});
    CHECK(fp(Op::fadd_s, kMinusOne, kHalfUlp | kSignBit, RUP) == FpResult{kMinusOne, NX});
    // (1 + 2^-23) + 2^-24 ties between an odd and an even significand: both nearest modes go up.
    CHECK(fp(Op::fadd_s, kOneUlp, kHalfUlp, RNE) == FpResult{kTwoUlps, NX});
    CHECK(fp(Op::fadd_s, kOneUlp, kHalfUlp, RMM) == FpResult{kTwoUlps, NX});
    // 1 + 1.5 * 2^-24 is above the midpoint: nearest modes round up, RMM included.
    CHECK(fp(Op::fadd_s, kOne, 0x33c0'0000, RMM) == FpResult{kOneUlp, NX});
    CHECK(fp(Op::fadd_s, kOne, 0x33c0'0000, RTZ) == FpResult{kOne, NX});
    // Just below the midpoint (1 + 0.75 * 2^-24... as 2^-25 + 2^-26): RMM must not round away.
    CHECK(fp(Op::fadd_s, kOne, 0x3340'0000, RMM) == FpResult{kOne, NX});
    // Exact sums raise nothing.
    CHECK(fp(Op::fadd_s, kOne, kTwo, RMM) == FpResult{kThree, 0});
}

TEST_CASE("the dynamic rounding mode reads frm; invalid frm is an illegal instruction",
          "[isa][fpu][rounding]") {
    Hart h;
    FakeEnv env;
    h.reg[kFpBase + 1] = kOne;
    h.reg[kFpBase + 2] = kHalfUlp;
    h.frm = RUP;
    run(h, env, encode(Op::fadd_s, 10, 1, 2, 0, DYN));
    CHECK(h.reg[kFpBase + 10] == kOneUlp);
    for (uint32_t bad : {5u, 6u, 7u}) {
        h.frm = bad;
        const uint32_t pc = h.pc;
        run(h, env, encode(Op::fadd_s, 10, 1, 2, 0, DYN));
        CHECK(h.pc == pc);
    }
    CHECK(env.illegals == 3);
}

TEST_CASE("exception flags", "[isa][fpu][flags]") {
    // Invalid: 0 * inf, inf - inf, sqrt(-1) all give the canonical NaN.
    CHECK(fp(Op::fmul_s, kPlusZero, kInf) == FpResult{kCanonicalNaN, NV});
    CHECK(fp(Op::fsub_s, kInf, kInf) == FpResult{kCanonicalNaN, NV});
    CHECK(fp(Op::fsqrt_s, kMinusOne) == FpResult{kCanonicalNaN, NV});
    CHECK(fp(Op::fsqrt_s, kMinusZero) == FpResult{kMinusZero, 0});  // sqrt(-0) = -0
    // Divide by zero: exact infinity, DZ only; 0/0 is invalid instead.
    CHECK(fp(Op::fdiv_s, kMinusOne, kPlusZero) == FpResult{kMinusInf, DZ});
    CHECK(fp(Op::fdiv_s, kPlusZero, kPlusZero) == FpResult{kCanonicalNaN, NV});
    // Overflow: nearest modes give inf, RTZ gives FLT_MAX, RDN of a positive too; always OF|NX.
    CHECK(fp(Op::fmul_s, kMax, kTwo, RNE) == FpResult{kInf, OF | NX});
    CHECK(fp(Op::fmul_s, kMax, kTwo, RMM) == FpResult{kInf, OF | NX});
    CHECK(fp(Op::fmul_s, kMax, kTwo, RTZ) == FpResult{kMax, OF | NX});
    CHECK(fp(Op::fmul_s, kMax, kTwo, RDN) == FpResult{kMax, OF | NX});
    // FLT_MAX + half its ulp (2^103) is exactly the RMM overflow threshold: rounds away to inf,
    // while RNE ties to the even FLT_MAX?  No: FLT_MAX's significand is odd, so RNE also goes to
    // inf. 2^103 = 0x7300'0000.
    CHECK(fp(Op::fadd_s, kMax, 0x7300'0000, RMM) == FpResult{kInf, OF | NX});
    CHECK(fp(Op::fadd_s, kMax, 0x7300'0000, RNE) == FpResult{kInf, OF | NX});
    CHECK(fp(Op::fadd_s, kMax, 0x7300'0000, RTZ) == FpResult{kMax, NX});  // RTZ: no overflow
    // Exact subnormal result: 2^-126 * 0.5 = 2^-127, no flags (underflow needs inexactness).
    CHECK(fp(Op::fmul_s, kMinNormal, 0x3f00'0000) == FpResult{0x0040'0000, 0});
    // 2^-149 * 0.5 = 2^-150 ties between 0 and 2^-149: RNE gives 0, RMM and RUP give 2^-149.
    CHECK(fp(Op::fmul_s, kMinSub, 0x3f00'0000, RNE) == FpResult{kPlusZero, UF | NX});
    CHECK(fp(Op::fmul_s, kMinSub, 0x3f00'0000, RMM) == FpResult{kMinSub, UF | NX});
    CHECK(fp(Op::fmul_s, kMinSub, 0x3f00'0000, RUP) == FpResult{kMinSub, UF | NX});
    // Tininess is detected after rounding: (1 + 2^-23) 2^-60 * (1 - 2^-23) 2^-66
    // = (1 - 2^-46) 2^-126 rounds (unbounded exponent, 24 bits) to 2^-126 in the nearest modes,
    // so it is not tiny: NX without UF. RTZ rounds it below 2^-126: tiny, UF.
    const uint32_t a = 0x2180'0001, b = 0x1e7f'fffe;
    CHECK(fp(Op::fmul_s, a, b, RNE) == FpResult{kMinNormal, NX});
    CHECK(fp(Op::fmul_s, a, b, RMM) == FpResult{kMinNormal, NX});
    CHECK(fp(Op::fmul_s, a, b, RTZ) == FpResult{0x007f'ffff, UF | NX});
}

TEST_CASE("NaN results are canonical", "[isa][fpu][nan]") {
    CHECK(fp(Op::fadd_s, kPayloadQNaN, kOne) == FpResult{kCanonicalNaN, 0});
    CHECK(fp(Op::fmul_s, kOne, 0xffc0'0000) == FpResult{kCanonicalNaN, 0});  // negative qNaN in
    CHECK(fp(Op::fdiv_s, kSNaN, kOne) == FpResult{kCanonicalNaN, NV});
    CHECK(fp(Op::fadd_s, kSNaN, kOne, RMM) == FpResult{kCanonicalNaN, NV});
    CHECK(fp(Op::fnmadd_s, kPayloadQNaN, kOne, RNE, kOne) == FpResult{kCanonicalNaN, 0});
    // Sign injection and moves are bit operations: NaN payloads pass through untouched.
    CHECK(fp(Op::fsgnjn_s, kPayloadQNaN, kOne) == FpResult{kPayloadQNaN | kSignBit, 0});
    CHECK(fp(Op::fsgnj_s, kSNaN, kMinusOne) == FpResult{kSNaN | kSignBit, 0});
    CHECK(fp(Op::fsgnjx_s, kPayloadQNaN | kSignBit, kMinusOne) == FpResult{kPayloadQNaN, 0});
    CHECK(fp(Op::fmv_x_w, kSNaN) == FpResult{kSNaN, 0});
    CHECK(fp(Op::fmv_w_x, kSNaN) == FpResult{kSNaN, 0});
}

TEST_CASE("fmin.s and fmax.s", "[isa][fpu][minmax]") {
    CHECK(fp(Op::fmin_s, kQNaN, kOne) == FpResult{kOne, 0});  // one NaN: the other operand
    CHECK(fp(Op::fmax_s, kTwo, kPayloadQNaN) == FpResult{kTwo, 0});
    CHECK(fp(Op::fmin_s, kSNaN, kOne) == FpResult{kOne, NV});  // sNaN still signals
    CHECK(fp(Op::fmax_s, kSNaN, kPayloadQNaN) == FpResult{kCanonicalNaN, NV});
    CHECK(fp(Op::fmin_s, kPayloadQNaN, kPayloadQNaN) == FpResult{kCanonicalNaN, 0});
    CHECK(fp(Op::fmin_s, kPlusZero, kMinusZero) == FpResult{kMinusZero, 0});  // -0 < +0
    CHECK(fp(Op::fmax_s, kMinusZero, kPlusZero) == FpResult{kPlusZero, 0});
    CHECK(fp(Op::fmin_s, kMinusOne, kMinusInf) == FpResult{kMinusInf, 0});
    CHECK(fp(Op::fmax_s, kMinusOne, kMinSub) == FpResult{kMinSub, 0});
}

TEST_CASE("comparisons", "[isa][fpu][compare]") {
    CHECK(fp(Op::feq_s, kQNaN, kQNaN) == FpResult{0, 0});  // quiet: qNaN raises nothing
    CHECK(fp(Op::feq_s, kSNaN, kOne) == FpResult{0, NV});
    CHECK(fp(Op::flt_s, kQNaN, kOne) == FpResult{0, NV});  // signaling: any NaN raises NV
    CHECK(fp(Op::fle_s, kOne, kQNaN) == FpResult{0, NV});
    CHECK(fp(Op::feq_s, kMinusZero, kPlusZero) == FpResult{1, 0});
    CHECK(fp(Op::fle_s, kPlusZero, kMinusZero) == FpResult{1, 0});
    CHECK(fp(Op::flt_s, kMinusZero, kPlusZero) == FpResult{0, 0});
    CHECK(fp(Op::flt_s, kMinusInf, kMinusOne) == FpResult{1, 0});
    CHECK(fp(Op::flt_s, kMinusOne, kMinusOneUlp) == FpResult{0, 0});
    CHECK(fp(Op::fle_s, kMinusOneUlp, kMinusOne) == FpResult{1, 0});
}

TEST_CASE("fcvt.w[u].s rounds, saturates and flags", "[isa][fpu][convert]") {
    constexpr uint32_t k2_5 = 0x4020'0000, kMinus2_5 = 0xc020'0000;
    CHECK(fp(Op::fcvt_w_s, k2_5, 0, RNE) == FpResult{2, NX});  // tie to even
    CHECK(fp(Op::fcvt_w_s, k2_5, 0, RMM) == FpResult{3, NX});  // tie away
    CHECK(fp(Op::fcvt_w_s, kMinus2_5, 0, RNE) == FpResult{uint32_t(-2), NX});
    CHECK(fp(Op::fcvt_w_s, kMinus2_5, 0, RMM) == FpResult{uint32_t(-3), NX});
    CHECK(fp(Op::fcvt_w_s, kMinus2_5, 0, RTZ) == FpResult{uint32_t(-2), NX});
    CHECK(fp(Op::fcvt_w_s, kMinus2_5, 0, RDN) == FpResult{uint32_t(-3), NX});
    CHECK(fp(Op::fcvt_w_s, kMinus2_5, 0, RUP) == FpResult{uint32_t(-2), NX});
    CHECK(fp(Op::fcvt_w_s, 0x3fc0'0000, 0, RNE) == FpResult{2, NX});  // 1.5 ties to even 2
    CHECK(fp(Op::fcvt_w_s, kOne) == FpResult{1, 0});
    CHECK(fp(Op::fcvt_w_s, 0xcf00'0000) == FpResult{0x8000'0000, 0});  // -2^31 is in range
    // Table 11.4: NaN and +inf -> 2^31 - 1, -inf -> -2^31, out-of-range -> the bound; NV only.
    CHECK(fp(Op::fcvt_w_s, kQNaN) == FpResult{0x7fff'ffff, NV});
    CHECK(fp(Op::fcvt_w_s, kInf) == FpResult{0x7fff'ffff, NV});
    CHECK(fp(Op::fcvt_w_s, kMinusInf) == FpResult{0x8000'0000, NV});
    CHECK(fp(Op::fcvt_w_s, 0x4f00'0000) == FpResult{0x7fff'ffff, NV});  // 2^31
    CHECK(fp(Op::fcvt_w_s, 0xcf00'0001) == FpResult{0x8000'0000, NV});  // just below -2^31
    CHECK(fp(Op::fcvt_wu_s, kQNaN) == FpResult{0xffff'ffff, NV});
    CHECK(fp(Op::fcvt_wu_s, kMinusOne) == FpResult{0, NV});
    CHECK(fp(Op::fcvt_wu_s, kMinusInf) == FpResult{0, NV});
    CHECK(fp(Op::fcvt_wu_s, 0x4f80'0000) == FpResult{0xffff'ffff, NV});  // 2^32
    // -0.5 truncates to 0, which is representable: inexact, not invalid. RDN gives -1: invalid.
    CHECK(fp(Op::fcvt_wu_s, 0xbf00'0000, 0, RTZ) == FpResult{0, NX});
    CHECK(fp(Op::fcvt_wu_s, 0xbf00'0000, 0, RDN) == FpResult{0, NV});
    CHECK(fp(Op::fcvt_wu_s, 0x4f6e'6b28) == FpResult{4'000'000'000u, 0});  // 4e9 is a float
}

TEST_CASE("fcvt.s.w[u] rounds", "[isa][fpu][convert]") {
    // 2^24 + 1 needs 25 bits: it ties between 2^24 (even) and 2^24 + 2.
    CHECK(fp(Op::fcvt_s_w, 16'777'217, 0, RNE) == FpResult{0x4b80'0000, NX});
    CHECK(fp(Op::fcvt_s_w, 16'777'217, 0, RMM) == FpResult{0x4b80'0001, NX});
    CHECK(fp(Op::fcvt_s_w, 16'777'217, 0, RUP) == FpResult{0x4b80'0001, NX});
    CHECK(fp(Op::fcvt_s_w, uint32_t(-16'777'217), 0, RDN) == FpResult{0xcb80'0001, NX});
    CHECK(fp(Op::fcvt_s_w, uint32_t(-7)) == FpResult{0xc0e0'0000, 0});
    // 2^32 - 1 rounds to 2^32 to nearest, to 2^32 - 256 toward zero.
    CHECK(fp(Op::fcvt_s_wu, 0xffff'ffff, 0, RNE) == FpResult{0x4f80'0000, NX});
    CHECK(fp(Op::fcvt_s_wu, 0xffff'ffff, 0, RTZ) == FpResult{0x4f7f'ffff, NX});
    CHECK(fp(Op::fcvt_s_wu, 0xffff'ffff, 0, RMM) == FpResult{0x4f80'0000, NX});
}

TEST_CASE("fclass.s distinguishes all ten classes", "[isa][fpu][classify]") {
    const std::pair<uint32_t, unsigned> cases[] = {
        {kMinusInf, 0}, {kMinusOne, 1}, {0x8000'0001, 2}, {kMinusZero, 3}, {kPlusZero, 4},
        {kMinSub, 5},   {kOne, 6},      {kInf, 7},        {kSNaN, 8},      {kQNaN, 9}};
    for (auto [value, bit] : cases)
        CHECK(fp(Op::fclass_s, value) == FpResult{1u << bit, 0});
}

TEST_CASE("fused multiply-add rounds once", "[isa][fpu][fma]") {
    // (1 + 2^-12)^2 - 1 = 2^-11 + 2^-24 exactly, representable as (1 + 2^-13) 2^-11. A separate
    // multiply would round the product's 2^-24 away (tie to even) and return 2^-11.
    constexpr uint32_t a = 0x3f80'0800;  // 1 + 2^-12
    CHECK(fp(Op::fmadd_s, a, a, RNE, kMinusOne) == FpResult{0x3a00'0400, 0});
    CHECK(fp(Op::fmul_s, a, a) == FpResult{0x3f80'1000, NX});  // the unfused product: 1 + 2^-11
    // Sign conventions with a=2, b=3, c=1: fmsub 6-1, fnmsub -6+1, fnmadd -6-1.
    CHECK(fp(Op::fmadd_s, kTwo, kThree, RNE, kOne) == FpResult{0x40e0'0000, 0});   // 7
    CHECK(fp(Op::fmsub_s, kTwo, kThree, RNE, kOne) == FpResult{0x40a0'0000, 0});   // 5
    CHECK(fp(Op::fnmsub_s, kTwo, kThree, RNE, kOne) == FpResult{0xc0a0'0000, 0});  // -5
    CHECK(fp(Op::fnmadd_s, kTwo, kThree, RNE, kOne) == FpResult{0xc0e0'0000, 0});  // -7
    // inf * 0 + qNaN must raise NV (spec 11.6), result canonical.
    CHECK(fp(Op::fmadd_s, kInf, kPlusZero, RNE, kPayloadQNaN) == FpResult{kCanonicalNaN, NV});
    // RMM on a fused tie: 1 * 1 + 2^-24 ties; away from zero gives 1 + 2^-23, RNE keeps 1.
    CHECK(fp(Op::fmadd_s, kOne, kOne, RMM, kHalfUlp) == FpResult{kOneUlp, NX});
    CHECK(fp(Op::fmadd_s, kOne, kOne, RNE, kHalfUlp) == FpResult{kOne, NX});
}

TEST_CASE("directed FP ops leave the host in round-to-nearest", "[isa][fpu]") {
    fp(Op::fadd_s, kOne, kHalfUlp, RUP);
    volatile float one = 1.0f, half_ulp = 0x1p-24f;
    CHECK(one + half_ulp == 1.0f);  // would be 1 + 2^-23 if RUP leaked
}

TEST_CASE("integer instructions do not touch fflags", "[isa][fpu]") {
    Hart h;
    FakeEnv env;
    h.fflags = NX;
    h.reg[1] = 1;
    run(h, env, encode(Op::div, x(3), x(1), x(0)));  // divide by zero: no FP flag
    CHECK(h.fflags == NX);
}

namespace {

/// The float after `value` toward +inf (finite, non-NaN input).
double next_up(float value) {
    return std::nextafter(value, std::numeric_limits<float>::infinity());
}
double next_down(float value) {
    return std::nextafter(value, -std::numeric_limits<float>::infinity());
}

}  // namespace

TEST_CASE("fmul.s rounds correctly in every mode on random operands", "[isa][fpu][rounding]") {
    // A float product is exact in double (48 significant bits), so each mode's defining property
    // can be checked directly against the exact value: RDN gives the largest float <= exact, RUP
    // the smallest >= exact, RTZ the one of those nearer zero, RNE/RMM the nearest (ties: even
    // significand / larger magnitude). Exponents span normal and subnormal results.
    std::mt19937 rng(2024);
    std::uniform_int_distribution<uint32_t> significand(0, 0x7f'ffff), exponent(40, 170),
        sign(0, 1);
    auto random_float = [&] { return sign(rng) << 31 | exponent(rng) << 23 | significand(rng); };
    for (int trial = 0; trial < 20'000; ++trial) {
        const uint32_t a = random_float(), b = random_float();
        const double exact = double(std::bit_cast<float>(a)) * double(std::bit_cast<float>(b));
        const float down = std::bit_cast<float>(fp(Op::fmul_s, a, b, RDN).value);
        const float up = std::bit_cast<float>(fp(Op::fmul_s, a, b, RUP).value);
        INFO(std::hex << a << " * " << b);
        REQUIRE(double(down) <= exact);
        REQUIRE(next_up(down) > exact);
        REQUIRE(double(up) >= exact);
        REQUIRE(next_down(up) < exact);
        const float toward_zero = std::bit_cast<float>(fp(Op::fmul_s, a, b, RTZ).value);
        REQUIRE(toward_zero == (exact < 0 ? up : down));
        const bool tie = exact - double(down) == double(up) - exact;
        const float nearer = exact - double(down) < double(up) - exact ? down : up;
        const float even = (std::bit_cast<uint32_t>(down) & 1) ? up : down;
        const float away = exact < 0 ? down : up;
        CHECK(std::bit_cast<float>(fp(Op::fmul_s, a, b, RNE).value) == (tie ? even : nearer));
        CHECK(std::bit_cast<float>(fp(Op::fmul_s, a, b, RMM).value) == (tie ? away : nearer));
        // Inexact exactly when the two directed results differ.
        CHECK(bool(fp(Op::fmul_s, a, b, RMM).flags & NX) == (down != up));
    }
}

namespace {

/// Operands for the fast-path equivalence test below.
class Operands {
public:
    explicit Operands(uint32_t seed) : rng_(seed) {}
    int pick(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng_); }
    uint32_t uniform() { return uint32_t(rng_()); }
    /// Random sign, biased exponent clamped to 0..254 (0: subnormal or zero), random significand
    /// with a random number of trailing zeros so that exact results are common.
    uint32_t with_exponent(int exponent) {
        const uint32_t significand = uniform() & 0x7f'ffff & (~0u << pick(0, 23));
        return (uniform() & kSignBit) | uint32_t(std::clamp(exponent, 0, 254)) << 23 | significand;
    }
    /// Small integers and powers of two: exact sums, products and quotients.
    uint32_t simple() {
        if (pick(0, 1)) return std::bit_cast<uint32_t>(float(pick(-64, 64)));
        return (uniform() & kSignBit) | uint32_t(pick(100, 154)) << 23;
    }
    /// Zeros, infinities, NaNs, subnormals, the normal extremes, one; either sign.
    uint32_t special() {
        static constexpr uint32_t kSpecials[] = {kPlusZero,    kInf,    kQNaN,       kSNaN,
                                                 kPayloadQNaN, kMinSub, 0x007f'ffff, kMinNormal,
                                                 kMax,         kOne};
        return (uniform() & kSignBit) | kSpecials[pick(0, std::size(kSpecials) - 1)];
    }

private:
    std::mt19937 rng_;
};

/// The operations as (a, b, c) functions; unused operands are ignored.
using Operation = uint32_t (*)(uint32_t, uint32_t, uint32_t, unsigned, uint32_t&);
template <auto F> uint32_t unary(uint32_t a, uint32_t, uint32_t, unsigned rm, uint32_t& fflags) {
    return F(a, rm, fflags);
}
template <auto F> uint32_t binary(uint32_t a, uint32_t b, uint32_t, unsigned rm, uint32_t& fflags) {
    return F(a, b, rm, fflags);
}
template <auto F>
uint32_t ternary(uint32_t a, uint32_t b, uint32_t c, unsigned rm, uint32_t& fflags) {
    return F(a, b, c, rm, fflags);
}

/// Biased operand exponents that aim the result of an operation at biased exponent e.
using Aim = std::array<int, 3> (*)(Operands&, int e);
std::array<int, 3> sum_near(Operands& g, int e) {
    return {e + g.pick(-2, 2), e + g.pick(-2, 2), 0};
}
std::array<int, 3> product_near(Operands& g, int e) {  // the third exponent is fma's addend
    const int ea = g.pick(std::max(0, e - 127), std::min(254, e + 127));
    return {ea, e - ea + 127 + g.pick(-2, 2), e + g.pick(-2, 2)};
}
std::array<int, 3> quotient_near(Operands& g, int e) {
    const int eb = g.pick(std::max(0, 127 - e), std::min(254, 381 - e));
    return {e + eb - 127 + g.pick(-2, 2), eb, 0};
}
std::array<int, 3> root_near(Operands& g, int e) {
    return {2 * e - 127 + g.pick(-2, 2), 0, 0};
}

/// A fast-pathed operation, its exact MXCSR reference, and the flags the operand mix must raise.
struct FastPathOp {
    const char* name;
    Operation fast, reference;
    Aim aim;
    uint32_t flags_expected;
};

const FastPathOp kFastPathOps[] = {
    {"add", binary<fpu::add>, binary<reference::add>, sum_near, NX | OF | NV},
    {"sub", binary<fpu::sub>, binary<reference::sub>, sum_near, NX | OF | NV},
    {"mul", binary<fpu::mul>, binary<reference::mul>, product_near, NX | UF | OF | NV},
    {"div", binary<fpu::div>, binary<reference::div>, quotient_near, NX | UF | OF | DZ | NV},
    {"sqrt", unary<fpu::sqrt>, unary<reference::sqrt>, root_near, NX | NV},
    {"fma", ternary<fpu::fma>, ternary<reference::fma>, product_near, NX | UF | OF | NV},
};

}  // namespace

TEST_CASE("the RNE fast paths agree with the MXCSR path on result and flags",
          "[isa][fpu][rounding]") {
    // Hand-derived corner: (1 - 2^-24) * 2^-126 = 2^-126 - 2^-150 ties (bounded exponent) up to
    // the normal 2^-126, but is tiny before and after rounding: UF | NX, the case the fast path
    // must leave alone although the result is normal.
    uint32_t corner_flags = 0;
    CHECK(fpu::mul(0x3f7f'ffff, kMinNormal, RNE, corner_flags) == kMinNormal);
    CHECK(corner_flags == (UF | NX));
    for (const FastPathOp& op : kFastPathOps) {
        Operands g(2025);
        uint32_t flags_seen = 0, exact_normal = 0;
        for (int trial = 0; trial < 200'000; ++trial) {
            std::array<uint32_t, 3> in{};
            const int kind = g.pick(0, 5);
            if (kind == 0 || kind == 5) {  // uniform bit patterns; specials mixed into them
                for (uint32_t& v : in)
                    v = kind == 5 && g.pick(0, 1) ? g.special() : g.uniform();
            } else if (kind == 4) {
                for (uint32_t& v : in)
                    v = g.simple();
            } else {  // results anywhere (close exponents), near 2^-126 or near FLT_MAX
                const int target = kind == 1   ? g.pick(1, 254)
                                   : kind == 2 ? g.pick(0, 3)
                                               : g.pick(252, 254);
                const std::array<int, 3> exponents = op.aim(g, target);
                for (int i = 0; i < 3; ++i)
                    in[i] = g.with_exponent(exponents[i]);
            }
            FpResult fast{}, reference{};
            fast.value = op.fast(in[0], in[1], in[2], RNE, fast.flags);
            reference.value = op.reference(in[0], in[1], in[2], RNE, reference.flags);
            INFO(op.name << std::hex << " 0x" << in[0] << " 0x" << in[1] << " 0x" << in[2]);
            REQUIRE(fast == reference);
            flags_seen |= reference.flags;
            const uint32_t exponent = reference.value >> 23 & 0xff;
            exact_normal += reference.flags == 0 && exponent != 0 && exponent != 0xff;
        }
        INFO(op.name);
        CHECK(flags_seen == op.flags_expected);
        CHECK(exact_normal > 5'000);  // exact results are common enough to test "no NX"
    }
}
