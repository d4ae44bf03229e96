// Chips the timing tests count by hand.
#pragma once
#include "sim/timing/config.hpp"

/// One TM of one TP with its own L2: every cycle belongs to one thread.
inline tpsim::timing::ChipConfig one_tp() {
    tpsim::timing::ChipConfig c;
    c.chip.num_tms = 1;
    c.chip.tps_per_tm = 1;
    c.chip.tms_per_l2 = 1;
    return c;
}
