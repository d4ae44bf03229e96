// Loads and stores of every width on .data, .bss and the stack, with sign/zero extension.
#include "check.h"
    .data
    .p2align 2
word:  .word 0x8081f0f1
    .bss
    .p2align 2
slot:  .space 8
    .text
    .globl _start
_start:
    la t0, word
    lw t1, 0(t0);   CHECK(1, t1, 0x8081f0f1)
    lb t1, 0(t0);   CHECK(2, t1, 0xfffffff1)
    lbu t1, 0(t0);  CHECK(3, t1, 0xf1)
    lb t1, 3(t0);   CHECK(4, t1, 0xffffff80)
    lh t1, 2(t0);   CHECK(5, t1, 0xffff8081)
    lhu t1, 2(t0);  CHECK(6, t1, 0x8081)
    lhu t1, 0(t0);  CHECK(7, t1, 0xf0f1)
    la t2, slot
    lw t1, 0(t2);   CHECK(8, t1, 0)          // .bss starts zeroed
    li t3, 0x11223344
    sw t3, 0(t2)
    li t3, 0xaa
    sb t3, 1(t2)                              // little-endian byte 1
    lw t1, 0(t2);   CHECK(9, t1, 0x1122aa44)
    li t3, 0xbeef
    sh t3, 6(t2)
    lw t1, 4(t2);   CHECK(10, t1, 0xbeef0000)
    // The stack lives in the local store below kLocalTop.
    li t3, 0x80000000
    CHECK_EQ(11, sp, t3)
    addi sp, sp, -16
    li t3, -5
    sw t3, 12(sp)
    sh t3, 2(sp)
    lw t1, 12(sp);  CHECK(12, t1, -5)
    lh t1, 2(sp);   CHECK(13, t1, -5)
    addi sp, sp, 16
    PASS_AND_FAIL
