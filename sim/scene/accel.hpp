// The acceleration structures tpsim builds for a kernel: which one follows from the marker the
// kernel's ELF defines (TRAX_USES_BVH, TRAX_USES_GRID); `render --accel` and the sweep key
// `accel` name one and pick its default kernel.
#pragma once
#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace tpsim::scene {

enum class AccelStructure {
    none,  ///< brute force: the kernel tests every triangle
    bvh2,  ///< the binary BVH (sim/scene/bvh.hpp)
    grid,  ///< the uniform grid (sim/scene/grid.hpp)
};

struct AccelInfo {
    AccelStructure structure;
    std::string_view name;            ///< as --accel and the statistics file spell it
    std::string_view default_kernel;  ///< the tracer that traverses it
    std::string_view description;     ///< for messages: "the uniform grid"
};

/// Every structure --accel may name (not `none`: brute force is chosen by its kernel).
constexpr std::array kAccelStructures = {
    AccelInfo{AccelStructure::bvh2, "bvh2", "tracer", "the binary BVH"},
    AccelInfo{AccelStructure::grid, "grid", "tracer_grid", "the uniform grid"},
};

constexpr AccelInfo accel_info(AccelStructure structure) {
    for (const AccelInfo& info : kAccelStructures)
        if (info.structure == structure) return info;
    return {AccelStructure::none, "none", "primary_brute", "no structure (every triangle tested)"};
}

constexpr std::string_view to_string(AccelStructure structure) {
    return accel_info(structure).name;
}

/// The structures' names, for the command line's and the sweep file's choices.
inline std::vector<std::string> accel_names() {
    std::vector<std::string> names;
    for (const AccelInfo& info : kAccelStructures)
        names.emplace_back(info.name);
    return names;
}

constexpr std::optional<AccelInfo> find_accel(std::string_view name) {
    for (const AccelInfo& info : kAccelStructures)
        if (info.name == name) return info;
    return std::nullopt;
}

}  // namespace tpsim::scene
