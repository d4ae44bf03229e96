// One fault per build: compiled once per -D<KIND>; the faulting instruction sits in victim().
#include "check.h"
    .text
    .globl _start
_start:
    call victim
    li a0, 0
    EXIT_WITH_A0

    .globl victim
    .type victim, @function
victim:
    nop
#if defined(NULL_LOAD)
    lw a0, 8(zero)
#elif defined(UNMAPPED_LOAD)
    li t0, 0x40000000
    lw a0, 0(t0)
#elif defined(MISALIGNED_LOAD)
    la t0, data
    lw a0, 2(t0)
#elif defined(WRITE_CODE)
    la t0, _start
    sw zero, 0(t0)
#elif defined(ILLEGAL)
    .word 0
#elif defined(EBREAK)
    ebreak
#elif defined(ENDLESS)
    j victim
#elif defined(BAD_ECALL)
    li a7, 64
    ecall
#elif defined(JUMP_NULL)
    jr zero
#elif defined(THREAD17_EBREAK)
    csrr t0, mhartid
    li t1, 17
    bne t0, t1, 1f
    ebreak
1:
#else
#error "define the fault kind"
#endif
    ret
    .size victim, .-victim

    .data
    .p2align 2
data: .word 0, 0
