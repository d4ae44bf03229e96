#include "sim/core/host_threads.hpp"

#include <algorithm>
#include <memory>

#include <oneapi/tbb/global_control.h>

namespace tpsim::core {
namespace {

uint32_t chosen = 0;  // 0: not set
std::unique_ptr<tbb::global_control> tbb_limit;

}  // namespace

uint32_t host_threads() {
    return chosen != 0 ? chosen : 1;
}

void set_host_threads(uint32_t threads) {
    chosen = std::max(1u, threads);
    tbb_limit.reset();  // one global_control at a time
    tbb_limit =
        std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, chosen);
}

}  // namespace tpsim::core
