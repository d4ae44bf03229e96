/* The native twin's entry point: every kernel also builds as libNAME_native.so exporting
 * tpsim_native_run(), which the simulator (or a test) dlopen()s to render the same image on the
 * host. Plain C so any host code can call it. See docs/kernel-api.md. */
#ifndef TPSIM_KERNEL_NATIVE_TWIN_H
#define TPSIM_KERNEL_NATIVE_TWIN_H
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/** Everything the twin needs to run a kernel over a memory image. */
typedef struct TraxNativeContext {
    uint32_t* global_words;     /**< global memory: word 0 is at guest address kGlobalBase */
    uint32_t global_word_count; /**< accesses at or past this word are reported as errors */
    uint32_t num_threads;       /**< trax_main() runs once per thread id (see tpsim_native_run) */
    uint32_t num_tms;           /**< thread i is in TM i / tm_size, at index i % tm_size */
    uint32_t tm_size;
    char* error;             /**< receives a one-line message when the run fails */
    uint32_t error_capacity; /**< bytes at error, including the terminating NUL */
    /** What the kernel printed (trax_printf), kept up to output_capacity bytes in thread order
     * (trax::KernelOutput): each thread's bytes, thread 0's first, of the lengths written to
     * output_lengths (num_threads entries), and the bytes dropped beyond the capacity. */
    char* output;
    uint32_t output_capacity;
    uint32_t* output_lengths;
    uint64_t* output_dropped;
} TraxNativeContext;

/** Runs the kernel; global registers start at 0. Each thread runs trax_main() on its own stack,
 * in thread-id order, one at a time: a thread that waits (barrier, semaphore) lets the next one
 * run, and one that may go on again runs after those ready before it, so every run of a kernel
 * is the same. Returns 0 on success, nonzero after writing the reason (bad memory access, bad
 * atomic register, deadlock, bad context) to ctx->error; the output is written either way. */
int tpsim_native_run(const TraxNativeContext* ctx);

/** The symbol name, for dlsym(). */
#define TPSIM_NATIVE_RUN_SYMBOL "tpsim_native_run"
typedef int (*TpsimNativeRunFn)(const TraxNativeContext*);

#ifdef __cplusplus
}
#endif
#endif
