// A dependency chain of STEPS instructions of one kind (CHAIN_<KIND>), each reading the
// previous one's result: the cycle difference of two builds is STEPS x that unit's latency.
// Every thread runs it.
    .text
    .globl _start
_start:
    li t1, 3
    li t2, 7
    fcvt.s.w f1, t1
    fcvt.s.w f0, t2
    .rept STEPS
#if defined(CHAIN_FADD)
    fadd.s f0, f0, f1
#elif defined(CHAIN_FMUL)
    fmul.s f0, f0, f1
#elif defined(CHAIN_FDIV)
    fdiv.s f0, f0, f1
#elif defined(CHAIN_FSQRT)
    fsqrt.s f0, f0
#elif defined(CHAIN_FMIN)
    fmin.s f0, f0, f1
#elif defined(CHAIN_MUL)
    mul t2, t2, t1
#elif defined(CHAIN_ADD)
    add t2, t2, t1
#else
#error "define one CHAIN_<KIND>"
#endif
    .endr
    fmv.x.w t3, f0          // both results are used, so the chain is on the critical path
    add a0, t3, t2
    li a0, 0
    li a7, 93
    ecall
