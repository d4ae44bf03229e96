// Every thread loads from global address 0x10002000 + (thread id << SHIFT) in the
// same cycle if it can: SHIFT 2 puts all threads on one line (MSHR merges), SHIFT 7 on
// distinct lines of one L1 bank when the L1 has two banks (bank conflicts).
    .text
    .globl _start
_start:
    csrr t1, mhartid
    slli t1, t1, SHIFT
    li t0, 0x10002000
    add t0, t0, t1
    lw a1, 0(t0)
    add a0, a1, a1
    li a0, 0
    li a7, 93
    ecall
