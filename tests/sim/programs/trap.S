// An ecall other than exit traps to mtvec when a handler is installed (mcause 11, mepc = ecall).
#include "check.h"
    .text
    .globl _start
_start:
    la t0, handler
    csrw mtvec, t0
    li a7, 64
the_ecall:
    ecall
    li a0, 99         // not reached: the handler exits
    EXIT_WITH_A0
    .p2align 2
handler:
    csrr t1, mcause;   CHECK(1, t1, 11)
    csrr t1, mepc
    la t2, the_ecall
    CHECK_EQ(2, t1, t2)
    PASS_AND_FAIL
