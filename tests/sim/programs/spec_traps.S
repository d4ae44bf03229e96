// With a trap handler in mtvec, ebreak, a misaligned load, a misaligned store and a jump to a
// misaligned target trap as the privileged spec has it (mcause, mepc at the instruction, mtval)
// and mret returns; csrw minstret replaces that instruction's own increment.
#include "check.h"
    .text
    .globl _start
_start:
    la t0, handler
    csrw mtvec, t0
    la s1, data
    // s2: the mcause the handler expects, s3: the mepc, s4: the mtval; s5 counts traps.
    li s2, 3
    la s3, the_ebreak
    la s4, the_ebreak
the_ebreak:
    ebreak
    li s2, 4
    la s3, the_load
    addi s4, s1, 2
the_load:
    lw a1, 2(s1)
    li s2, 6
    la s3, the_store
    addi s4, s1, 1
the_store:
    sh zero, 1(s1)
    li s2, 0
    la s3, the_jump
    la t3, target
    addi t3, t3, 2
    mv s4, t3
    li ra, 0x55
the_jump:
    jalr ra, 0(t3)
    CHECK(20, ra, 0x55)      // the jump did not complete: ra kept
    CHECK(21, s5, 4)
    // Zicsr: the next instruction reads exactly the value written to minstret.
    li t0, 1000
    csrw minstret, t0
    csrr t1, minstret
    CHECK(22, t1, 1000)
    PASS_AND_FAIL
target:
    li a0, 30                // not reached: the jump traps
    EXIT_WITH_A0

    .p2align 2
handler:
    csrr t1, mcause;   CHECK_EQ(10, t1, s2)
    csrr t1, mepc;     CHECK_EQ(11, t1, s3)
    csrr t1, mtval;    CHECK_EQ(12, t1, s4)
    addi s5, s5, 1
    addi t1, s3, 4     // resume after the trapping instruction
    csrw mepc, t1
    mret

    .data
    .p2align 2
data: .word 0, 0
