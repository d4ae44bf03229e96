// Waiting between host threads that meet every few microseconds (the parallel simulation's
// stretches of cycles and turns). Sleeping in the kernel costs more than such a wait: a futex
// wake of a thread whose core went idle takes tens of microseconds on a virtual machine, longer
// than a stretch's work. So a waiter spins, with the CPU's pause hint, and only after a while
// yields its core on every try (on a busy host the thread it waits for may need that core).
#pragma once
#include "sim/core/host_spacing.hpp"

#include <atomic>
#include <cstdint>
#include <thread>
#include <utility>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

namespace tpsim::core {

/// Tells the CPU this is a spin-wait loop (fewer wasted cycles, the sibling hyper-thread runs).
inline void cpu_relax() {
#if defined(__x86_64__) || defined(__i386__)
    _mm_pause();
#elif defined(__aarch64__)
    asm volatile("yield");
#endif
}

/// How long `lanes` threads that wait for each other should spin before yielding: about ten
/// 6-cycle windows of 4 TMs (2^14 pauses, 0.19 ms at the 11 ns a pause takes on this project's
/// machine; 2^11 measured no faster than one thread on a busy machine, where a yield hands the
/// core to another process for its whole time slice) when each can have a core of its own;
/// barely, when there are more of them than cores (the one waited for needs a core).
inline uint32_t spins_for(uint32_t lanes) {
    return lanes <= std::thread::hardware_concurrency() ? 1u << 14 : 64;
}

/// Returns once ready() is true: spins `spins` times, then yields between tries.
template <class Ready> void spin_until(Ready&& ready, uint32_t spins) {
    for (uint32_t tries = 0; !ready(); ++tries)
        if (tries < spins)
            cpu_relax();
        else
            std::this_thread::yield();
}

/// No completion step.
struct NoCompletion {
    void operator()() noexcept {}
};

/// A reusable barrier for `count` threads, like std::barrier, that spins (spins_for) before it
/// sleeps: threads meeting every few microseconds then meet without a system call, and a
/// thread left waiting long (another has no core, or the run is between chunks) stops using
/// its core. The last thread to arrive runs `completion` before any is let go; everything each
/// thread did before arriving happens before the completion, and the completion before
/// everything each does after.
template <class Completion = NoCompletion> class SpinBarrier {
public:
    explicit SpinBarrier(uint32_t count, Completion completion = {})
        : spins_(spins_for(count)), completion_(std::move(completion)), count_(count) {}

    void arrive_and_wait() { arrive(false); }
    /// Arrives without waiting, and leaves: later phases wait for one thread fewer.
    void arrive_and_drop() { arrive(true); }

private:
    void arrive(bool drop) {
        // Neither can change before this thread arrives, so reading them first is exact.
        const uint32_t phase = phase_.load(std::memory_order_acquire);
        const uint32_t count = count_.load(std::memory_order_relaxed);
        if (drop) dropping_.fetch_add(1, std::memory_order_relaxed);
        if (arrived_.fetch_add(1, std::memory_order_acq_rel) + 1 == count) {
            complete(phase, count);
        } else if (!drop) {
            for (uint32_t tries = 0; phase_.load(std::memory_order_acquire) == phase; ++tries)
                if (tries < spins_)
                    cpu_relax();
                else
                    phase_.wait(phase, std::memory_order_acquire);
        }
    }

    /// Every thread of `phase` has arrived: runs the completion, then lets them go.
    void complete(uint32_t phase, uint32_t count) {
        completion_();
        count_.store(count - dropping_.exchange(0, std::memory_order_relaxed),
                     std::memory_order_relaxed);
        arrived_.store(0, std::memory_order_relaxed);  // both published by the release below
        phase_.store(phase + 1, std::memory_order_release);
        phase_.notify_all();  // no system call unless a thread sleeps
    }

    const uint32_t spins_;
    Completion completion_;
    // Own cache lines: every arrival writes the first, every waiter reads the second.
    alignas(kHostSpacing) std::atomic<uint32_t> arrived_{0};
    std::atomic<uint32_t> dropping_{0};
    alignas(kHostSpacing) std::atomic<uint32_t> phase_{0};
    std::atomic<uint32_t> count_;
};

}  // namespace tpsim::core
