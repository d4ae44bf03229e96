// Framebuffer writes: threads take pixels with tp.atominc on global register 0 (as the render
// kernels do) until PIXELS, and store each pixel's three words (12 bytes, as the tracer's RGB
// floats) at 0x10001000 + 12 * pixel: the values pixel, pixel + 1, pixel + 2.
    .text
    .globl _start
_start:
    li t0, 0x10001000
    li t1, PIXELS
1:  .insn i 0x0b, 0, a1, x0, 0  // a1 = atomicinc(0)
    bge a1, t1, 2f
    slli t2, a1, 3               // t2 = 12 * a1
    slli t3, a1, 2
    add t2, t2, t3
    add t2, t2, t0
    addi t3, a1, 1
    addi t4, a1, 2
    sw a1, 0(t2)
    sw t3, 4(t2)
    sw t4, 8(t2)
    j 1b
2:  li a0, 0
    li a7, 93
    ecall
