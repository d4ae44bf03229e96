// Code in a second executable segment 256 MiB away runs; code in a non-executable segment
// between the two (-DJUMP_TO_DATA) is a jump outside the code.
#include "check.h"
    .section .text.start, "ax"
    .globl _start
_start:
    call far
    mv s0, a0
    CHECK(1, s0, 7)
#ifdef JUMP_TO_DATA
    la t0, data_code
    jr t0
#endif
    PASS_AND_FAIL

    .section .text.high, "ax"
    .globl far
    .type far, @function
far:
    li a0, 7
    ret
    .size far, .-far

    .section .rodata, "a"
    .p2align 2
    .globl data_code
data_code:
    li a0, 0
    EXIT_WITH_A0
