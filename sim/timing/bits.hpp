// Bit sets over TPs (bit i of word i / 64), the form in which the cycle loop keeps per-TP flags
// so that it can test many TPs at once.
#pragma once
#include <bit>
#include <cstdint>
#include <vector>

namespace tpsim::timing {

/// std::popcount, inline: built for the x86-64 baseline (no POPCNT instruction), GCC calls
/// libgcc for it, several times per TM and cycle.
constexpr uint32_t count_bits(uint64_t x) {
    x -= (x >> 1) & 0x5555'5555'5555'5555;
    x = (x & 0x3333'3333'3333'3333) + ((x >> 2) & 0x3333'3333'3333'3333);
    x = (x + (x >> 4)) & 0x0f0f'0f0f'0f0f'0f0f;
    return static_cast<uint32_t>((x * 0x0101'0101'0101'0101) >> 56);
}
static_assert(count_bits(0) == 0 && count_bits(~uint64_t{0}) == 64 && count_bits(0x8001) == 2);

inline void set_bit(std::vector<uint64_t>& bits, uint32_t i) {
    bits[i >> 6] |= uint64_t{1} << (i & 63);
}
inline bool test_bit(const std::vector<uint64_t>& bits, uint32_t i) {
    return bits[i >> 6] >> (i & 63) & 1;
}
inline void clear_bit(std::vector<uint64_t>& bits, uint32_t i) {
    bits[i >> 6] &= ~(uint64_t{1} << (i & 63));
}

/// Calls f(i) for each set bit of `word`, lowest first; i counts from bit 0 of word `w`.
template <class F> void for_each_bit(uint32_t w, uint64_t word, F&& f) {
    for (; word != 0; word &= word - 1)
        f((w << 6) + static_cast<uint32_t>(std::countr_zero(word)));
}

/// One part of a walk over a bit set in rotating order: the bits of word `w` under `mask`,
/// rotated right by `shift`, so that bit b stands for index (w << 6) + (b + shift) % 64.
struct RotatedPart {
    uint32_t w;
    uint64_t mask;
    int shift;

    /// The part of `word` (word w of the set), rotated: its bits in visiting order.
    uint64_t of(uint64_t word) const { return std::rotr(word & mask, shift); }
    /// Rotated bits back in place, to update word w.
    uint64_t back(uint64_t bits) const { return std::rotl(bits, shift); }
    uint32_t index(uint32_t bit) const {
        return (w << 6) + ((bit + static_cast<uint32_t>(shift)) & 63);
    }
};

/// Calls f(part) so that the parts' bits, taken in order, visit every index of a set of
/// `words` words in rotating order: start, start + 1, ..., wrapping to 0. A one-word set (up
/// to 64 indices, the usual TM) is one part, the word rotated by `start`; a larger one is its
/// words from start's on, the first one twice: its bits from start up first, the ones below
/// last.
template <class F>
[[gnu::always_inline]] inline void for_each_rotated_part(uint32_t words, uint32_t start, F&& f) {
    if (words == 1) {
        f(RotatedPart{0, ~uint64_t{0}, static_cast<int>(start)});
        return;
    }
    const uint32_t first_word = start >> 6;
    const uint64_t below_start = (uint64_t{1} << (start & 63)) - 1;
    f(RotatedPart{first_word, ~below_start, 0});
    for (uint32_t k = 1, w = first_word; k < words; ++k) {
        w = w + 1 == words ? 0 : w + 1;
        f(RotatedPart{w, ~uint64_t{0}, 0});
    }
    f(RotatedPart{first_word, below_start, 0});
}

}  // namespace tpsim::timing
