// Startup for the C test programs: _start calls main and exits with its result.
#pragma once

static inline __attribute__((noreturn)) void guest_exit(int code) {
    register int a0 __asm__("a0") = code;
    register int a7 __asm__("a7") = 93;
    __asm__ volatile("ecall" : : "r"(a0), "r"(a7));
    __builtin_unreachable();
}

int main(void);

__attribute__((section(".text.start"), noreturn)) void _start(void) {
    guest_exit(main());
}
