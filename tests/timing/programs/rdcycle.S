// A kernel that times itself: reads the cycle CSR around a chain of STEPS dependent fdiv.s and
// exits with the difference, so the test sees what the guest measured.
    .text
    .globl _start
_start:
    li t1, 3
    li t2, 7
    fcvt.s.w f1, t1
    fcvt.s.w f0, t2
    rdcycle s0
    .rept STEPS
    fdiv.s f0, f0, f1
    .endr
    fmv.x.w t3, f0          // waits for the chain's result before the second read
    rdcycle s1
    sub a0, s1, s0
    li a7, 93
    ecall
