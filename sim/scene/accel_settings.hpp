// Which acceleration structure to build and how, as the three places that choose give it: a
// scene file's [accel] table, a sweep file's keys and `render`'s options. Each leaves unset what
// it does not choose, so the levels stack: the command line over the scene file, the scene file
// over the kernel's own structure and the builders' defaults (docs/accel.md, docs/scenes.md).
// The setting names are the scene file's and the sweep file's keys, one table for both.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include "sim/scene/accel.hpp"
#include "sim/scene/bvh.hpp"
#include "sim/scene/grid.hpp"
#include "sim/scene/kdtree.hpp"
#include "sim/scene/octree.hpp"

namespace tpsim::scene {

/// The builders' configurations: their defaults with the settings given applied.
struct AccelConfigs {
    BvhConfig bvh;
    GridConfig grid;
    KdTreeConfig kdtree;
    OctreeConfig octree;
};
AccelConfigs accel_configs(const AccelSettings& settings);

/// A setting's value as a file writes it: a boolean, an integer, a number or a string.
using AccelValue = std::variant<bool, int64_t, double, std::string>;

/// The setting names, in the order accel_setting_values() lists them.
std::vector<std::string> accel_setting_names();

/// Sets the setting `name` from `value`, checked against the setting's type and range (the
/// same as `render`'s option of that name). Returns what is wrong, for the caller to report
/// with the file and line ("must be one of bvh2, bvh4 ..., got \"quadtree\""); empty when set,
/// and when `name` is not a setting: the caller asks is_accel_setting first.
std::string set_accel_setting(AccelSettings& settings, std::string_view name,
                              const AccelValue& value);
bool is_accel_setting(std::string_view name);

/// Every setting that is set, by name (a sweep plan stores them so).
std::vector<std::pair<std::string, AccelValue>> accel_setting_values(const AccelSettings& settings);

}  // namespace tpsim::scene
