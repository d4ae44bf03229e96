// What a render reports: its statistics registered under hierarchical names
// (docs/statistics.md), printed as text or JSON by the stats printers.
#pragma once
#include <iosfwd>

#include "render.hpp"
#include "sim/stats/registry.hpp"

namespace tpsim::render {

/// Registers the scene, memory-image, BVH, instruction and host-time statistics of `result`.
/// `result` must outlive every use of `registry`.
void register_stats(const RenderResult& result, stats::Registry& registry);

/// The human summary printed before the counters: scene, image sections, BVH, run.
void print_summary(const RenderOptions& options, const RenderResult& result, std::ostream& out);

}  // namespace tpsim::render
