// CSRs of a single thread: ids, the tp.* geometry (32 threads per TM) and instret/cycle counting.
#include "check.h"
    .text
    .globl _start
_start:
    csrr t0, mhartid;  CHECK(1, t0, 0)
    csrr t0, 0xcc0;    CHECK(2, t0, 1)    // tp.nthreads
    csrr t0, 0xcc1;    CHECK(3, t0, 0)    // tp.tmid
    csrr t0, 0xcc2;    CHECK(4, t0, 1)    // tp.ntms
    csrr t0, 0xcc3;    CHECK(5, t0, 0)    // tp.tpid
    csrr t0, 0xcc4;    CHECK(6, t0, 32)   // tp.tmsize
    rdinstret t1
    nop
    nop
    rdinstret t2
    sub t2, t2, t1;    CHECK(7, t2, 3)
    rdcycle t1
    nop
    rdcycle t2
    sub t2, t2, t1;    CHECK(8, t2, 2)    // functional mode: one instruction per cycle
    rdinstreth t1;     CHECK(9, t1, 0)
    PASS_AND_FAIL
