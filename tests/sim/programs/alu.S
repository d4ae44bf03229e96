// Integer ALU: register and immediate forms, shifts, compares, lui/auipc.
#include "check.h"
    .text
    .globl _start
_start:
    li t0, 100
    li t1, -7
    add t2, t0, t1;   CHECK(1, t2, 93)
    sub t2, t0, t1;   CHECK(2, t2, 107)
    addi t2, t1, -1;  CHECK(3, t2, -8)
    li t3, 0x0ff0
    li t4, 0x00ff
    and t2, t3, t4;   CHECK(4, t2, 0x00f0)
    or t2, t3, t4;    CHECK(5, t2, 0x0fff)
    xor t2, t3, t4;   CHECK(6, t2, 0x0f0f)
    andi t2, t3, 0x0f0; CHECK(7, t2, 0x0f0)
    ori t2, t4, 0x700;  CHECK(8, t2, 0x7ff)
    xori t2, t4, -1;    CHECK(9, t2, -256)
    li t3, 3
    sll t2, t4, t3;   CHECK(10, t2, 0x7f8)
    srl t2, t1, t3;   CHECK(11, t2, 0x1fffffff)   // -7 >> 3 logical: 0xfffffff9 >> 3
    sra t2, t1, t3;   CHECK(12, t2, -1)
    slli t2, t4, 24;  CHECK(13, t2, 0xff000000)
    srli t2, t2, 28;  CHECK(14, t2, 0xf)
    li t2, 0x80000000
    srai t2, t2, 31;  CHECK(15, t2, -1)
    slt t2, t1, t0;   CHECK(16, t2, 1)
    sltu t2, t1, t0;  CHECK(17, t2, 0)            // 0xfffffff9 is large unsigned
    slti t2, t1, -6;  CHECK(18, t2, 1)
    sltiu t2, t0, 101; CHECK(19, t2, 1)
    li t5, 37
    sll t2, t4, t5;   CHECK(20, t2, 0x1fe0)       // shift amount uses the low 5 bits only (37 -> 5)
    lui t2, 0x12345;  CHECK(21, t2, 0x12345000)
here:
    auipc t2, 0
    lui t3, %hi(here)
    addi t3, t3, %lo(here)
    CHECK_EQ(22, t2, t3)
    addi zero, zero, 5   // writes to x0 are discarded
    CHECK(23, zero, 0)
    PASS_AND_FAIL
