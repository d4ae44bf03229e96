// Compiled C with calls, recursion and the stack: fib(20) = 6765, the 20th Fibonacci number.
#include "guest.h"

__attribute__((noinline)) int fib(int n) { return n < 2 ? n : fib(n - 1) + fib(n - 2); }

int main(void) {
    int squares[16];
    for (int i = 0; i < 16; ++i) squares[i] = i * i;
    int sum = 0;
    for (int i = 0; i < 16; ++i) sum += squares[i];
    if (sum != 1240) return 1;  // sum of i^2 for i < 16 = 15*16*31/6
    if (fib(20) != 6765) return 2;
    return 0;
}
