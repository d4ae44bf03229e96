// Shared helpers of the assembly test programs. Each program exits with 0 when every CHECK
// passes and with the number of the first failed check otherwise.
#define EXIT_WITH_A0                                                                               \
    li a7, 93;                                                                                     \
    ecall
// CHECK(n, reg, value): fail with code n unless reg == value.
#define CHECK(n, reg, value)                                                                       \
    li a0, n;                                                                                      \
    li t6, value;                                                                                  \
    bne reg, t6, fail
// CHECK_EQ(n, a, b): fail with code n unless registers a and b are equal.
#define CHECK_EQ(n, a, b)                                                                          \
    li a0, n;                                                                                      \
    bne a, b, fail
// The common epilogue: success, and the failure exit that CHECK jumps to.
#define PASS_AND_FAIL                                                                              \
    li a0, 0;                                                                                      \
    fail:                                                                                          \
    EXIT_WITH_A0
