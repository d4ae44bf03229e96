# Per-thread start-up: every hardware thread begins here with its own registers.
# The loader has already placed .data and zeroed .bss (shared by all threads).
    .section .text.start, "ax", @progbits
    .globl _start
    .type _start, @function
_start:
    # Standard RISC-V: FP instructions are illegal until mstatus.FS leaves Off (set it Initial).
    li      t0, 0x2000
    csrs    mstatus, t0
    # The stack sits at the top of this thread's private local store (kernel/memory_map.hpp).
    li      sp, 0x80000000
    call    trax_main
    # Exit: a7 = 93 (exit), a0 = 0.
    li      a0, 0
    li      a7, 93
    ecall
    # ecall exit never returns; stay put if a simulator lets it.
1:  j       1b
    .size _start, . - _start
