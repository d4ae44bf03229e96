// A loop of LINES instruction lines (16 words each, line-aligned) run LOOPS times, then exit:
// a finite I-cache fetches line 0 (the prologue, padded to the line), the loop's LINES lines
// LOOPS times, and the epilogue's line. Code larger than the I-cache misses on every line of
// every lap; code that fits misses once per line.
    .text
    .globl _start
_start:
    li t0, LOOPS
    .balign 64
loop:
    .rept LINES * 16 - 2
    addi t1, t1, 1
    .endr
    addi t0, t0, -1
    bnez t0, loop
    li a0, 0
    li a7, 93
    ecall
