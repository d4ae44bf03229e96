// The functional machine (sim/core) as the timing model's instruction source: thread ids are
// tm * tps_per_tm + tp on both sides, so MachineConfig::threads_per_tm must equal
// chip.tps_per_tm (machine_config_for() builds a matching one).
#pragma once
#include "sim/core/machine.hpp"
#include "sim/core/thread_env.hpp"
#include "timing/chip.hpp"

namespace tpsim::timing {

/// The machine shape a chip needs: one thread per TP, the chip's TM size and local store.
inline core::MachineConfig machine_config_for(const ChipConfig& chip) {
    core::MachineConfig config;
    config.threads = chip.chip.num_tms * chip.chip.tps_per_tm;
    config.threads_per_tm = chip.chip.tps_per_tm;
    config.local_store_bytes = chip.tp.local_store_bytes;
    return config;
}

class MachineSource final : public InstructionSource {
public:
    explicit MachineSource(core::Machine& machine) : machine_(machine) {}

    core::Machine& machine() const { return machine_; }

    uint32_t next_pc(uint32_t thread) const override { return machine_.next_pc(thread); }

    void step(uint32_t thread, StepInfo& out) override { machine_.step_inline(thread, out); }

private:
    core::Machine& machine_;
};

}  // namespace tpsim::timing
