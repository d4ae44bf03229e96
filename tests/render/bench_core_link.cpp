// How far apart two host cores are (scripts/bench-threads): the time one cache line takes to
// go from core A to core B and back, as the parallel simulation's lanes pass their stretch
// counts and turns every few microseconds. On a virtual machine it changes with where the
// host places the virtual cores (docs/performance.md, "Host threads").
//   bench_core_link [CORE_A CORE_B]     (default: cores 0 and 1) -> "round trip: N ns"
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>

#include <pthread.h>
#include <sched.h>

#include "sim/core/host_spacing.hpp"

namespace {

bool pin_to(int core) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(core, &set);
    return pthread_setaffinity_np(pthread_self(), sizeof set, &set) == 0;
}

}  // namespace

int main(int argc, char** argv) {
    const int a = argc > 2 ? std::atoi(argv[1]) : 0, b = argc > 2 ? std::atoi(argv[2]) : 1;
    constexpr int kTrips = 200'000;
    alignas(tpsim::core::kHostSpacing) std::atomic<int> ball{0};
    bool pinned = true;
    std::thread back([&] {
        pinned = pin_to(b);
        for (int i = 0; i < kTrips; ++i) {
            while (ball.load(std::memory_order_acquire) != 2 * i + 1) {
            }
            ball.store(2 * i + 2, std::memory_order_release);
        }
    });
    if (!pin_to(a)) pinned = false;
    const auto start = std::chrono::steady_clock::now();
    for (int i = 0; i < kTrips; ++i) {
        ball.store(2 * i + 1, std::memory_order_release);
        while (ball.load(std::memory_order_acquire) != 2 * i + 2) {
        }
    }
    const std::chrono::duration<double, std::nano> took = std::chrono::steady_clock::now() - start;
    back.join();
    if (!pinned) {
        std::fprintf(stderr, "bench_core_link: cannot pin threads to cores %d and %d\n", a, b);
        return 2;
    }
    std::printf("round trip: %.0f ns\n", took.count() / kTrips);
}
