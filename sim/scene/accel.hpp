// The acceleration structures tpsim builds for a kernel: which one follows from the marker the
// kernel's ELF defines (TRAX_USES_BVH, TRAX_USES_WIDE_BVH, TRAX_USES_GRID, TRAX_USES_KDTREE,
// TRAX_USES_OCTREE, TRAX_USES_BSP);
// `render --accel` and the sweep key `accel` name one (for a marker that several share, the one to
// build) and pick its default kernel.
#pragma once
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "kernel/scene_layout.hpp"

namespace tpsim::scene {

enum class AccelStructure {
    none,    ///< brute force: the kernel tests every triangle
    bvh2,    ///< the binary BVH (sim/scene/bvh.hpp)
    bvh4,    ///< the binary BVH collapsed to 4 children per node (sim/scene/wide_bvh.hpp)
    bvh8,    ///< ... to 8 children per node
    grid,    ///< the uniform grid (sim/scene/grid.hpp)
    kdtree,  ///< the kd-tree (sim/scene/kdtree.hpp)
    octree,  ///< the octree (sim/scene/octree.hpp)
    bsp,     ///< the BSP tree with general planes (sim/scene/kdtree.hpp, general_planes)
};

struct AccelInfo {
    AccelStructure structure;
    std::string_view name;            ///< as --accel and the statistics file spell it
    std::string_view default_kernel;  ///< the tracer that traverses it
    std::string_view marker;          ///< the symbol a kernel that traverses it defines
    std::string_view description;     ///< for messages: "the uniform grid"
};

/// Every structure --accel may name (not `none`: brute force is chosen by its kernel).
constexpr std::array kAccelStructures = {
    AccelInfo{AccelStructure::bvh2, "bvh2", "tracer", trax::layout::kUsesBvhSymbol,
              "the binary BVH"},
    AccelInfo{AccelStructure::bvh4, "bvh4", "tracer_wide", trax::layout::kUsesWideBvhSymbol,
              "the 4-wide BVH"},
    AccelInfo{AccelStructure::bvh8, "bvh8", "tracer_wide", trax::layout::kUsesWideBvhSymbol,
              "the 8-wide BVH"},
    AccelInfo{AccelStructure::grid, "grid", "tracer_grid", trax::layout::kUsesGridSymbol,
              "the uniform grid"},
    AccelInfo{AccelStructure::kdtree, "kdtree", "tracer_kdtree", trax::layout::kUsesKdTreeSymbol,
              "the kd-tree"},
    AccelInfo{AccelStructure::octree, "octree", "tracer_octree", trax::layout::kUsesOctreeSymbol,
              "the octree"},
    AccelInfo{AccelStructure::bsp, "bsp", "tracer_bsp", trax::layout::kUsesBspSymbol,
              "the BSP tree"},
};

constexpr AccelInfo accel_info(AccelStructure structure) {
    for (const AccelInfo& info : kAccelStructures)
        if (info.structure == structure) return info;
    return {AccelStructure::none, "none", "primary_brute", "",
            "no structure (every triangle tested)"};
}

/// Children per node of a wide BVH; 0 for the other structures.
constexpr uint32_t wide_bvh_width(AccelStructure structure) {
    return structure == AccelStructure::bvh4 ? 4 : structure == AccelStructure::bvh8 ? 8 : 0;
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

enum class BvhBuilder;  // sim/scene/bvh.hpp
enum class BvhOrder;
enum class BvhBoxes;

/// Which structure to build and how, as one of the places that choose gives it (a scene file's
/// [accel] table, a sweep's keys, render's options), unset where it does not choose; the keys,
/// their checks and how the levels stack are in sim/scene/accel_settings.hpp.
struct AccelSettings {
    std::optional<AccelStructure> structure;      ///< key `structure` (the sweep's `accel`)
    std::optional<BvhBuilder> bvh_builder;        ///< `bvh`
    std::optional<uint32_t> max_leaf;             ///< `max_leaf`, 1..8
    std::optional<BvhOrder> bvh_order;            ///< `bvh_order`
    std::optional<bool> bvh_align_pairs;          ///< `bvh_align_pairs`
    std::optional<BvhBoxes> bvh_boxes;            ///< `bvh_boxes`
    std::optional<uint32_t> grid_resolution;      ///< `grid_resolution`
    std::optional<double> grid_density;           ///< `grid_density`
    std::optional<uint32_t> kdtree_max_depth;     ///< `kdtree_max_depth` (kd-tree and BSP)
    std::optional<double> kdtree_max_references;  ///< `kdtree_max_references`
    std::optional<uint32_t> octree_max_depth;     ///< `octree_max_depth`

    /// These settings with each one that `above` sets in its place.
    AccelSettings under(const AccelSettings& above) const;
    bool operator==(const AccelSettings&) const = default;
};

/// The structure `name` names, or nullopt.
constexpr std::optional<AccelStructure> find_accel_structure(std::string_view name) {
    if (const auto info = find_accel(name)) return info->structure;
    return std::nullopt;
}

}  // namespace tpsim::scene
