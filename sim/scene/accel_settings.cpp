#include "sim/scene/accel_settings.hpp"

#include <functional>

#include <fmt/format.h>
#include <fmt/ranges.h>

namespace tpsim::scene {
namespace {

std::string shown(const AccelValue& value) {
    return std::visit(
        [](const auto& v) -> std::string {
            using T = std::decay_t<decltype(v)>;
            if constexpr (std::is_same_v<T, std::string>)
                return fmt::format("\"{}\"", v);
            else if constexpr (std::is_same_v<T, bool>)
                return v ? "true" : "false";
            else
                return fmt::format("{}", v);
        },
        value);
}

/// One setting: its name, how it is read from a value and written back.
struct SettingKey {
    std::string_view name;
    std::function<std::string(AccelSettings&, const AccelValue&)> set;
    std::function<std::optional<AccelValue>(const AccelSettings&)> get;
};

/// A setting that names one of a list (structure, bvh ...): `names` lists the spellings,
/// `find` turns one into the value.
template <class T>
SettingKey choice(std::string_view name, std::optional<T> AccelSettings::*field,
                  std::vector<std::string> (*names)(), std::optional<T> (*find)(std::string_view),
                  std::string (*spell)(T)) {
    return {name,
            [=](AccelSettings& s, const AccelValue& v) -> std::string {
                if (const auto* text = std::get_if<std::string>(&v))
                    if (const std::optional<T> found = find(*text)) {
                        s.*field = *found;
                        return "";
                    }
                return fmt::format("must be one of {}, got {}", fmt::join(names(), ", "), shown(v));
            },
            [=](const AccelSettings& s) -> std::optional<AccelValue> {
                if (!(s.*field)) return std::nullopt;
                return AccelValue(spell(*(s.*field)));
            }};
}

SettingKey whole(std::string_view name, std::optional<uint32_t> AccelSettings::*field, uint32_t lo,
                 uint32_t hi) {
    return {name,
            [=](AccelSettings& s, const AccelValue& v) -> std::string {
                const auto* n = std::get_if<int64_t>(&v);
                if (!n || *n < lo || *n > hi)
                    return fmt::format("must be a whole number in [{}, {}], got {}", lo, hi,
                                       shown(v));
                s.*field = uint32_t(*n);
                return "";
            },
            [=](const AccelSettings& s) -> std::optional<AccelValue> {
                if (!(s.*field)) return std::nullopt;
                return AccelValue(int64_t(*(s.*field)));
            }};
}

SettingKey real(std::string_view name, std::optional<double> AccelSettings::*field, double lo,
                double hi) {
    return {name,
            [=](AccelSettings& s, const AccelValue& v) -> std::string {
                const double* x = std::get_if<double>(&v);
                const int64_t* n = std::get_if<int64_t>(&v);
                const std::optional<double> value = x   ? std::optional(*x)
                                                    : n ? std::optional(double(*n))
                                                        : std::nullopt;
                if (!value || !(*value >= lo && *value <= hi))
                    return fmt::format("must be a number in [{}, {}], got {}", lo, hi, shown(v));
                s.*field = *value;
                return "";
            },
            [=](const AccelSettings& s) -> std::optional<AccelValue> {
                if (!(s.*field)) return std::nullopt;
                return AccelValue(*(s.*field));
            }};
}

SettingKey flag(std::string_view name, std::optional<bool> AccelSettings::*field) {
    return {name,
            [=](AccelSettings& s, const AccelValue& v) -> std::string {
                const bool* b = std::get_if<bool>(&v);
                if (!b) return fmt::format("must be true or false, got {}", shown(v));
                s.*field = *b;
                return "";
            },
            [=](const AccelSettings& s) -> std::optional<AccelValue> {
                if (!(s.*field)) return std::nullopt;
                return AccelValue(*(s.*field));
            }};
}

template <class T> std::string spelt(T value) {
    return std::string(to_string(value));
}

const std::vector<SettingKey>& keys() {
    static const std::vector<SettingKey> table = {
        choice("structure", &AccelSettings::structure, accel_names, find_accel_structure,
               spelt<AccelStructure>),
        choice("bvh", &AccelSettings::bvh_builder, bvh_builder_names, find_bvh_builder,
               spelt<BvhBuilder>),
        whole("max_leaf", &AccelSettings::max_leaf, 1, 8),
        choice("bvh_order", &AccelSettings::bvh_order, bvh_order_names, find_bvh_order,
               spelt<BvhOrder>),
        flag("bvh_align_pairs", &AccelSettings::bvh_align_pairs),
        choice("bvh_boxes", &AccelSettings::bvh_boxes, bvh_boxes_names, find_bvh_boxes,
               spelt<BvhBoxes>),
        whole("grid_resolution", &AccelSettings::grid_resolution, 0, kGridMaxResolution),
        real("grid_density", &AccelSettings::grid_density, 1.0 / 1024, kGridMaxDensity),
        whole("kdtree_max_depth", &AccelSettings::kdtree_max_depth, 0, kKdMaxDepth),
        real("kdtree_max_references", &AccelSettings::kdtree_max_references, 1.0, 1e6),
        whole("octree_max_depth", &AccelSettings::octree_max_depth, 0, kOctreeMaxDepth),
    };
    return table;
}

const SettingKey* find_key(std::string_view name) {
    for (const SettingKey& key : keys())
        if (key.name == name) return &key;
    return nullptr;
}

}  // namespace

AccelSettings AccelSettings::under(const AccelSettings& above) const {
    AccelSettings merged = *this;
    for (const SettingKey& key : keys())
        if (const std::optional<AccelValue> value = key.get(above)) key.set(merged, *value);
    return merged;
}

AccelConfigs accel_configs(const AccelSettings& s) {
    AccelConfigs c;
    c.bvh.builder = s.bvh_builder.value_or(c.bvh.builder);
    c.bvh.max_leaf_size = s.max_leaf.value_or(c.bvh.max_leaf_size);
    c.bvh.order = s.bvh_order.value_or(c.bvh.order);
    c.bvh.align_pairs = s.bvh_align_pairs.value_or(c.bvh.align_pairs);
    c.bvh.boxes = s.bvh_boxes.value_or(c.bvh.boxes);
    c.grid.resolution = s.grid_resolution.value_or(c.grid.resolution);
    c.grid.density = s.grid_density.value_or(c.grid.density);
    c.kdtree.max_depth = s.kdtree_max_depth.value_or(c.kdtree.max_depth);
    c.kdtree.max_references_per_triangle =
        s.kdtree_max_references.value_or(c.kdtree.max_references_per_triangle);
    c.octree.max_depth = s.octree_max_depth.value_or(c.octree.max_depth);
    return c;
}

std::vector<std::string> accel_setting_names() {
    std::vector<std::string> names;
    for (const SettingKey& key : keys())
        names.emplace_back(key.name);
    return names;
}

bool is_accel_setting(std::string_view name) {
    return find_key(name) != nullptr;
}

std::string set_accel_setting(AccelSettings& settings, std::string_view name,
                              const AccelValue& value) {
    const SettingKey* key = find_key(name);
    return key ? key->set(settings, value) : "";
}

std::vector<std::pair<std::string, AccelValue>> accel_setting_values(const AccelSettings& s) {
    std::vector<std::pair<std::string, AccelValue>> values;
    for (const SettingKey& key : keys())
        if (const std::optional<AccelValue> value = key.get(s))
            values.emplace_back(std::string(key.name), *value);
    return values;
}

}  // namespace tpsim::scene
