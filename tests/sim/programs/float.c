// F extension through compiled C. Every expected value is exact in binary32, so the results do
// not depend on the compiler; volatile keeps clang from folding them at compile time.
#include "guest.h"

volatile float a = 1.5f, b = 2.25f, c = 16.0f, d = 7.0f, e = -3.75f;

int main(void) {
    if (a + b != 3.75f) return 1;
    if (b - a != 0.75f) return 2;
    if (a * b != 3.375f) return 3;
    if (d / 2.0f != 3.5f) return 4;
    if (__builtin_sqrtf(c) != 4.0f) return 5;
    if ((int)e != -3) return 6;  // conversion to int truncates toward zero
    if ((float)(int)d != 7.0f) return 7;
    if (__builtin_fminf(a, e) != e) return 8;
    if (__builtin_fmaxf(a, e) != a) return 9;
    if (!(e < a) || a <= e || a == b) return 10;
    if (__builtin_fabsf(e) != 3.75f) return 11;
    if (__builtin_fmaf(a, b, d) != 10.375f) return 12;
    if ((unsigned)c != 16u) return 13;
    // 1/3 rounded to nearest even is 0x3eaaaaab.
    union { float f; unsigned u; } third = {1.0f / (d - 4.0f)};
    if (third.u != 0x3eaaaaabu) return 14;
    return 0;
}
