#include "sim/core/host_threads.hpp"

#include <algorithm>
#include <memory>
#include <thread>

#include <oneapi/tbb/global_control.h>

namespace tpsim::core {
namespace {

uint32_t chosen = 0;  // 0: not set
std::unique_ptr<tbb::global_control> tbb_limit;

}  // namespace

uint32_t host_threads() {
    return chosen != 0 ? chosen : std::max(1u, std::thread::hardware_concurrency());
}

bool host_threads_set() {
    return chosen != 0;
}

void set_host_threads(uint32_t threads) {
    chosen = std::max(1u, threads);
    tbb_limit.reset();  // one global_control at a time
    tbb_limit =
        std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, chosen);
}

void HostThreadChoice::ran(uint64_t work, double seconds) {
    if (most_ <= 1) return;
    work_ += work;
    seconds_ += seconds;
    if (seconds_ < phase_seconds_) return;
    rate_of(on_) = double(work_) / seconds_;
    work_ = 0;
    seconds_ = 0;
    if (trying_) {
        const bool won = rate_of(on_) > rate_of(best_);
        if (won) {
            best_ = on_;
            tries_apart_ = 4;
        }
        on_ = best_;
        phase_seconds_ = tries_apart_ * kTrySeconds;
        if (!won) tries_apart_ = std::min(tries_apart_ * 2, 1024u);
    } else {
        on_ = best_ == 1 ? most_ : 1;
        phase_seconds_ = kTrySeconds;
    }
    trying_ = !trying_;
}

}  // namespace tpsim::core
