// Branches (taken and not taken, signed and unsigned), jal and jalr with link registers.
#include "check.h"
    .text
    .globl _start
_start:
    li t0, -1
    li t1, 1
    li a0, 1;  beq t0, t1, fail
    li a0, 2;  bne t0, t0, fail
    li a0, 3;  blt t1, t0, fail      // 1 < -1 is false signed
    li a0, 4;  bltu t0, t1, fail     // 0xffffffff < 1 is false unsigned
    li a0, 5;  bge t0, t1, fail
    li a0, 6;  bgeu t1, t0, fail
    li a0, 7;  blt t0, t1, 1f;  j fail
1:  li a0, 8;  bltu t1, t0, 1f; j fail
1:  li a0, 9;  bge t1, t0, 1f;  j fail
1:  li a0, 10; bgeu t0, t1, 1f; j fail
1:  li a0, 11; beq t1, t1, 1f;  j fail
1:  li a0, 12; bne t0, t1, 1f;  j fail
1:  jal ra, double_t1
    CHECK(13, t1, 2)
    la t2, double_t1
    jalr ra, 0(t2)
    CHECK(14, t1, 4)
    // A counted loop: sum 1..10 backwards.
    li t3, 10
    li t4, 0
2:  add t4, t4, t3
    addi t3, t3, -1
    bnez t3, 2b
    CHECK(15, t4, 55)
    PASS_AND_FAIL

double_t1:
    add t1, t1, t1
    ret
