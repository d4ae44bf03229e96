// Without a trap handler, a jump to a misaligned target is reported at the jump.
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
    la t0, _start
    addi t0, t0, 2
#ifdef BRANCH
    .word 0x00000363    // beq zero, zero, +6: a taken branch to a misaligned target
#else
    jalr zero, 0(t0)
#endif
    ret
    .size victim, .-victim
