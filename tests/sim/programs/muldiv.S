// M extension, including the results the RISC-V spec defines for division by zero and overflow.
#include "check.h"
    .text
    .globl _start
_start:
    li t0, -6
    li t1, 7
    mul t2, t0, t1;     CHECK(1, t2, -42)
    li t3, 0x80000000
    li t4, 2
    mulh t2, t3, t4;    CHECK(2, t2, -1)          // -2^31 * 2 = -2^32: high word all ones
    mulhu t2, t3, t4;   CHECK(3, t2, 1)           // 2^31 * 2 = 2^32
    li t5, -1
    mulhsu t2, t5, t4;  CHECK(4, t2, -1)          // -1 * 2 = -2: high word -1
    mulhu t2, t5, t5;   CHECK(5, t2, 0xfffffffe)  // (2^32-1)^2 = 2^64 - 2^33 + 1
    div t2, t0, t4;     CHECK(6, t2, -3)
    li t6, -7
    li s0, 2
    div t2, t6, s0;     CHECK(7, t2, -3)          // rounds toward zero
    rem t2, t6, s0;     CHECK(8, t2, -1)          // sign of the dividend
    divu t2, t5, s0;    CHECK(9, t2, 0x7fffffff)
    remu t2, t1, s0;    CHECK(10, t2, 1)
    div t2, t1, zero;   CHECK(11, t2, -1)         // x / 0 = -1
    divu t2, t1, zero;  CHECK(12, t2, -1)         // = 2^32 - 1
    rem t2, t1, zero;   CHECK(13, t2, 7)          // x % 0 = x
    remu t2, t1, zero;  CHECK(14, t2, 7)
    div t2, t3, t5;     CHECK(15, t2, 0x80000000) // INT_MIN / -1 overflows to INT_MIN
    rem t2, t3, t5;     CHECK(16, t2, 0)
    PASS_AND_FAIL
