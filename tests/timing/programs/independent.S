// STEPS independent operations of one kind (INDEPENDENT_<KIND>) per thread, destinations
// rotating over eight registers so no operand or destination waits on the unit's latency:
// with N threads and K units the pool limits throughput to K per cycle.
    .text
    .globl _start
_start:
    li t1, 3
    fcvt.s.w f1, t1
    .rept STEPS / 8
    .irp rd, f2, f3, f4, f5, f6, f7, f8, f9
#if defined(INDEPENDENT_FMUL)
    fmul.s \rd, f1, f1
#elif defined(INDEPENDENT_FDIV)
    fdiv.s \rd, f1, f1
#else
#error "define one INDEPENDENT_<KIND>"
#endif
    .endr
    .endr
    li a0, 0
    li a7, 93
    ecall
