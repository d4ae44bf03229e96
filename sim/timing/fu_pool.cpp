#include "sim/timing/fu_pool.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>

namespace tpsim::timing {

Pool pool_of(isa::FuClass fu) {
    using isa::FuClass;
    switch (fu) {
    case FuClass::IntAlu:
    case FuClass::System:
    case FuClass::Print:
        return Pool::IntAlu;
    case FuClass::IntMul:
    case FuClass::IntDiv:
        return Pool::IntMulDiv;
    case FuClass::FpAdd:
        return Pool::FpAdd;
    case FuClass::FpMul:
        return Pool::FpMul;
    case FuClass::FpDiv:
    case FuClass::FpSqrt:
        return Pool::FpDivSqrt;
    case FuClass::FpMisc:
        return Pool::FpMisc;
    case FuClass::Branch:
        return Pool::Branch;
    case FuClass::Load:
    case FuClass::Store:
        return Pool::LoadStore;
    case FuClass::Atomic:
    case FuClass::Sync:  // served by the global-register unit, as atomics are
        return Pool::Atomic;
    case FuClass::Count:
        break;
    }
    throw std::invalid_argument(
        fmt::format("pool_of: FuClass {} has no pool", static_cast<int>(fu)));
}

std::string_view to_string(Pool pool) {
    constexpr std::string_view kNames[] = {"int_alu", "int_muldiv", "fp_add",
                                           "fp_mul",  "fp_divsqrt", "fp_misc",
                                           "branch",  "load_store", "atomic"};
    static_assert(std::size(kNames) == static_cast<size_t>(Pool::Count));
    return kNames[static_cast<size_t>(pool)];
}

const FuConfig& pool_config(const FuPoolsConfig& p, Pool pool) {
    const FuConfig* configs[] = {&p.int_alu, &p.int_muldiv, &p.fp_add,     &p.fp_mul, &p.fp_divsqrt,
                                 &p.fp_misc, &p.branch,     &p.load_store, &p.atomic};
    static_assert(std::size(configs) == static_cast<size_t>(Pool::Count));
    return *configs[static_cast<size_t>(pool)];
}

FuPool::FuPool(const FuConfig& config, uint32_t num_requesters)
    : config_(config), num_requesters_(num_requesters),
      requested_((size_t{num_requesters} + 63) / 64, 0), unit_free_at_(config.count, 0) {
    if (num_requesters == 0 || config.count == 0)
        throw std::invalid_argument("FuPool: needs at least one requester and one unit");
}

void FuPool::register_stats(stats::Registry& r, std::string_view prefix) const {
    r.add_counter(fmt::format("{}/issued", prefix), counters_.issued, "operations started");
    r.add_counter(fmt::format("{}/denied", prefix), counters_.denied,
                  "requests refused because all units were busy (FU-busy stalls)", "requests");
    r.add_counter(fmt::format("{}/unit_busy_cycles", prefix), counters_.unit_busy_cycles,
                  "unit-cycles occupied by operations", "unit-cycles");
}

}  // namespace tpsim::timing
