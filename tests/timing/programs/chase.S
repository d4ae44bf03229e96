// Dependent pointer chase: thread 0 follows STEPS pointers starting at the address in global
// word 0, each load's address being the previous load's value, and stores the last one in
// global word 1. Fully unrolled (no loop overhead), so two builds with different STEPS differ
// by exactly STEPS loads: their cycle difference is STEPS x the load-to-use latency.
    .text
    .globl _start
_start:
    csrr t1, mhartid
    bnez t1, 1f
    li t2, 0x10000000       // kGlobalBase
    lw t0, 0(t2)
    .rept STEPS
    lw t0, 0(t0)
    .endr
    sw t0, 4(t2)
1:  li a0, 0
    li a7, 93
    ecall
