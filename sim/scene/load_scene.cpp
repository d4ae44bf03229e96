#include "sim/scene/load_scene.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string_view>

#include <fmt/format.h>
#include <glm/gtc/matrix_transform.hpp>
#include <toml++/toml.h>

#include "sim/core/input_file.hpp"
#include "sim/core/toml_nesting.hpp"
#include "sim/scene/mesh_import.hpp"
#include "sim/scene/procedural.hpp"

namespace tpsim::scene {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
/// Keeps a typo such as cells = [1e6, 1e6] from exhausting host memory.
constexpr size_t kMaxTriangles = size_t{1} << 26;
/// A scene file is a page of settings; its geometry is in the meshes it names.
constexpr std::uintmax_t kMaxSceneFileBytes = 1 << 24;

/// A set of allowed values, printed the way the error messages show it: "(0, 180)", "[1, 16384]".
struct Interval {
    double lo = -kInf, hi = kInf;
    bool lo_open = true, hi_open = true;
    bool contains(double v) const {
        return (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
    }
    std::string text() const {
        const auto bound = [](double v) {
            return std::isinf(v) ? std::string(v < 0 ? "-inf" : "inf") : fmt::format("{}", v);
        };
        return fmt::format("{}{}, {}{}", lo_open ? '(' : '[', bound(lo), bound(hi),
                           hi_open ? ')' : ']');
    }
};
constexpr Interval kAnyFinite{};
constexpr Interval kPositive{0, kInf, true, true};
constexpr Interval kNonNegative{0, kInf, false, true};
constexpr Interval kUnit{0, 1, false, false};

std::string_view type_name(const toml::node& node) {
    switch (node.type()) {
    case toml::node_type::table:
        return "table";
    case toml::node_type::array:
        return "array";
    case toml::node_type::string:
        return "string";
    case toml::node_type::integer:
        return "integer";
    case toml::node_type::floating_point:
        return "float";
    case toml::node_type::boolean:
        return "boolean";
    default:
        return "date/time";
    }
}

std::string join(std::string_view prefix, std::string_view key) {
    return prefix.empty() ? std::string(key) : fmt::format("{}.{}", prefix, key);
}

/// Reads typed, range-checked values out of a parsed TOML file; every failure names the file,
/// the position, the dotted key and what would have been accepted.
class Reader {
public:
    explicit Reader(std::string file) : file_(std::move(file)) {}

    [[noreturn]] void fail(const toml::source_region& where, std::string_view message) const {
        throw SceneError(
            fmt::format("{}:{}:{}: {}", file_, where.begin.line, where.begin.column, message));
    }

    const std::string& file() const { return file_; }

    /// Rejects keys that are not in `allowed`, so typos are not silently ignored.
    void allow_keys(const toml::table& table, std::string_view prefix,
                    std::initializer_list<std::string_view> allowed) const {
        for (auto&& [key, node] : table) {
            if (std::find(allowed.begin(), allowed.end(), key.str()) != allowed.end()) continue;
            fail(key.source(), fmt::format("unknown key {} (allowed: {})", join(prefix, key.str()),
                                           fmt::join(allowed.begin(), allowed.end(), ", ")));
        }
    }

    double number(const toml::node& node, const std::string& name, const Interval& allowed) const {
        if (!node.is_number())
            fail(node.source(),
                 fmt::format("{} must be a number, got a {}", name, type_name(node)));
        const double v = *node.value<double>();
        if (!std::isfinite(v) || !allowed.contains(v))
            fail(node.source(), fmt::format("{} must be in {}, got {}", name, allowed.text(), v));
        return v;
    }

    uint32_t integer(const toml::node& node, const std::string& name, uint32_t lo,
                     uint32_t hi) const {
        if (!node.is_integer())
            fail(node.source(),
                 fmt::format("{} must be an integer, got a {}", name, type_name(node)));
        const int64_t v = *node.value<int64_t>();
        if (v < lo || v > hi)
            fail(node.source(), fmt::format("{} must be in [{}, {}], got {}", name, lo, hi, v));
        return uint32_t(v);
    }

    /// An array of exactly `size` numbers, each in `allowed`.
    std::vector<double> numbers(const toml::node& node, const std::string& name, size_t size,
                                const Interval& allowed) const {
        const toml::array* array = node.as_array();
        if (array == nullptr || array->size() != size)
            fail(node.source(), fmt::format("{} must be an array of {} numbers", name, size));
        std::vector<double> values;
        for (size_t i = 0; i < size; ++i)
            values.push_back(number((*array)[i], fmt::format("{}[{}]", name, i), allowed));
        return values;
    }

    glm::vec3 vec3(const toml::node& node, const std::string& name,
                   const Interval& allowed = kAnyFinite) const {
        const auto v = numbers(node, name, 3, allowed);
        return {float(v[0]), float(v[1]), float(v[2])};
    }

    const toml::node& required(const toml::table& table, std::string_view prefix,
                               std::string_view key) const {
        const toml::node* node = table.get(key);
        if (node == nullptr) fail(table.source(), fmt::format("{} is required", join(prefix, key)));
        return *node;
    }

    // Optional fields: the fallback when the key is absent.
    double number(const toml::table& t, std::string_view prefix, std::string_view key,
                  const Interval& allowed, double fallback) const {
        const toml::node* node = t.get(key);
        return node ? number(*node, join(prefix, key), allowed) : fallback;
    }
    uint32_t integer(const toml::table& t, std::string_view prefix, std::string_view key,
                     uint32_t lo, uint32_t hi, uint32_t fallback) const {
        const toml::node* node = t.get(key);
        return node ? integer(*node, join(prefix, key), lo, hi) : fallback;
    }
    glm::vec3 vec3(const toml::table& t, std::string_view prefix, std::string_view key,
                   const Interval& allowed, glm::vec3 fallback) const {
        const toml::node* node = t.get(key);
        return node ? vec3(*node, join(prefix, key), allowed) : fallback;
    }

    bool boolean(const toml::table& t, std::string_view prefix, std::string_view key,
                 bool fallback) const {
        const toml::node* node = t.get(key);
        if (node == nullptr) return fallback;
        if (!node->is_boolean())
            fail(node->source(), fmt::format("{} must be true or false, got a {}",
                                             join(prefix, key), type_name(*node)));
        return *node->value<bool>();
    }

    std::string text(const toml::node& node, const std::string& name) const {
        if (!node.is_string())
            fail(node.source(),
                 fmt::format("{} must be a string, got a {}", name, type_name(node)));
        return std::string(*node.value<std::string_view>());
    }

    const toml::table& table(const toml::node& node, const std::string& name) const {
        if (!node.is_table())
            fail(node.source(), fmt::format("{} must be a table, got a {}", name, type_name(node)));
        return *node.as_table();
    }

    /// `[[name]]` entries (or an inline array of tables).
    std::vector<const toml::table*> tables(const toml::node& node, const std::string& name) const {
        const toml::array* array = node.as_array();
        if (array == nullptr)
            fail(node.source(), fmt::format("{} must be an array of tables ([[{}]])", name, name));
        std::vector<const toml::table*> result;
        for (size_t i = 0; i < array->size(); ++i)
            result.push_back(&table((*array)[i], fmt::format("{}[{}]", name, i)));
        return result;
    }

private:
    std::string file_;
};

/// Scene materials first (they override same-named file materials), then file materials as met.
class MaterialTable {
public:
    void define(const Material& material) {
        list_.push_back(material);
        ++defined_;
    }

    std::optional<uint32_t> defined(std::string_view name) const {
        for (uint32_t i = 0; i < defined_; ++i)
            if (list_[i].name == name) return i;
        return std::nullopt;
    }

    uint32_t intern(const Material& material) {
        if (auto index = defined(material.name)) return *index;
        for (uint32_t i = defined_; i < list_.size(); ++i)
            if (list_[i].name == material.name && list_[i].diffuse == material.diffuse) return i;
        list_.push_back(material);
        return uint32_t(list_.size() - 1);
    }

    const std::vector<Material>& list() const { return list_; }

private:
    std::vector<Material> list_;
    uint32_t defined_ = 0;
};

const Material kDefaultMaterial{"default", glm::vec3(0.8f)};

/// Drops materials no triangle uses and renumbers the rest in order of first use.
void keep_used_materials(Scene& scene, const std::vector<Material>& all) {
    std::vector<uint32_t> remap(all.size(), UINT32_MAX);
    scene.materials.clear();
    for (Triangle& t : scene.triangles) {
        if (remap[t.material] == UINT32_MAX) {
            remap[t.material] = uint32_t(scene.materials.size());
            scene.materials.push_back(all[t.material]);
        }
        t.material = remap[t.material];
    }
}

Camera read_camera(const Reader& r, const toml::table& t) {
    r.allow_keys(t, "camera", {"eye", "look_at", "up", "fov"});
    Camera camera;
    camera.eye = r.vec3(r.required(t, "camera", "eye"), "camera.eye");
    camera.look_at = r.vec3(r.required(t, "camera", "look_at"), "camera.look_at");
    camera.up = r.vec3(t, "camera", "up", kAnyFinite, camera.up);
    camera.vertical_fov_degrees =
        float(r.number(t, "camera", "fov", Interval{0, 180, true, true}, 45.0));
    const glm::vec3 view = camera.look_at - camera.eye;
    if (glm::length(view) == 0.f) r.fail(t.source(), "camera.eye and camera.look_at must differ");
    if (glm::length(camera.up) == 0.f ||
        glm::length(glm::cross(glm::normalize(view), glm::normalize(camera.up))) < 1e-6f)
        r.fail(t.source(), "camera.up must be non-zero and not parallel to look_at - eye");
    return camera;
}

std::vector<PointLight> read_lights(const Reader& r, const toml::node& node) {
    std::vector<PointLight> lights;
    const auto tables = r.tables(node, "lights");
    for (size_t i = 0; i < tables.size(); ++i) {
        const std::string prefix = fmt::format("lights[{}]", i);
        const toml::table& t = *tables[i];
        r.allow_keys(t, prefix, {"position", "color", "intensity"});
        const glm::vec3 position =
            r.vec3(r.required(t, prefix, "position"), join(prefix, "position"));
        const glm::vec3 color = r.vec3(t, prefix, "color", kNonNegative, glm::vec3(1.f));
        const float intensity = float(r.number(t, prefix, "intensity", kNonNegative, 1.0));
        lights.push_back({position, color * intensity});
    }
    return lights;
}

std::optional<uint32_t> read_material_ref(const Reader& r, const toml::table& t,
                                          const std::string& prefix,
                                          const MaterialTable& materials) {
    const toml::node* node = t.get("material");
    if (node == nullptr) return std::nullopt;
    const std::string name = r.text(*node, join(prefix, "material"));
    if (auto index = materials.defined(name)) return index;
    r.fail(node->source(),
           fmt::format("{}.material '{}' is not defined in [materials]", prefix, name));
}

glm::mat4 read_transform(const Reader& r, const toml::table& t, const std::string& prefix) {
    glm::vec3 scale(1.f);
    if (const toml::node* node = t.get("scale")) {
        const std::string name = join(prefix, "scale");
        const Interval allowed{1e-30, 1e30, false, false};
        // A negative or zero scale would mirror or flatten the mesh: almost always a typo.
        scale = node->is_array() ? r.vec3(*node, name, allowed)
                                 : glm::vec3(float(r.number(*node, name, allowed)));
    }
    const glm::vec3 rotate =
        r.vec3(t, prefix, "rotate", Interval{-360, 360, false, false}, glm::vec3(0.f));
    const glm::vec3 translate = r.vec3(t, prefix, "translate", kAnyFinite, glm::vec3(0.f));
    // Applied to the mesh in this order: scale, rotate about x, then y, then z, translate.
    glm::mat4 m = glm::translate(glm::mat4(1.f), translate);
    m = glm::rotate(m, glm::radians(rotate.z), glm::vec3(0, 0, 1));
    m = glm::rotate(m, glm::radians(rotate.y), glm::vec3(0, 1, 0));
    m = glm::rotate(m, glm::radians(rotate.x), glm::vec3(1, 0, 0));
    return glm::scale(m, scale);
}

void read_mesh(const Reader& r, const toml::table& t, const std::string& prefix,
               const std::filesystem::path& base, MaterialTable& materials, Scene& scene) {
    r.allow_keys(t, prefix, {"path", "scale", "rotate", "translate", "material"});
    const toml::node& path_node = r.required(t, prefix, "path");
    const std::filesystem::path path = base / r.text(path_node, join(prefix, "path"));
    const glm::mat4 transform = read_transform(r, t, prefix);
    const std::optional<uint32_t> material = read_material_ref(r, t, prefix, materials);

    ImportedMesh mesh;
    try {
        mesh = import_mesh(path);
    } catch (const std::runtime_error& e) {
        r.fail(path_node.source(), fmt::format("{}: {}", join(prefix, "path"), e.what()));
    }
    if (scene.triangles.size() + mesh.triangles.size() > kMaxTriangles)
        r.fail(t.source(),
               fmt::format("{} would take the scene past {} triangles", prefix, kMaxTriangles));
    std::vector<uint32_t> file_to_scene;
    for (const Material& m : mesh.materials)
        file_to_scene.push_back(material ? *material : materials.intern(m));
    const auto apply = [&](const glm::vec3& v) { return glm::vec3(transform * glm::vec4(v, 1.f)); };
    for (const Triangle& t : mesh.triangles)
        scene.triangles.push_back(
            {apply(t.v0), apply(t.v1), apply(t.v2), file_to_scene[t.material]});
    scene.sources.push_back(mesh.summary);
}

SphereParams read_sphere_shape(const Reader& r, const toml::table& t, const std::string& prefix) {
    SphereParams sphere;
    sphere.radius =
        float(r.number(r.required(t, prefix, "radius"), join(prefix, "radius"), kPositive));
    sphere.segments = r.integer(t, prefix, "segments", 3, 4096, sphere.segments);
    sphere.rings = r.integer(t, prefix, "rings", 2, 4096, sphere.rings);
    return sphere;
}

glm::uvec2 read_uvec2(const Reader& r, const toml::node& node, const std::string& name, uint32_t lo,
                      uint32_t hi) {
    const toml::array* array = node.as_array();
    if (array == nullptr || array->size() != 2)
        r.fail(node.source(), fmt::format("{} must be an array of 2 integers", name));
    return {r.integer((*array)[0], name + "[0]", lo, hi),
            r.integer((*array)[1], name + "[1]", lo, hi)};
}

void read_generator(const Reader& r, const toml::table& t, const std::string& prefix,
                    MaterialTable& materials, Scene& scene) {
    const std::string type = r.text(r.required(t, prefix, "type"), join(prefix, "type"));
    const uint32_t material =
        read_material_ref(r, t, prefix, materials).value_or(materials.intern(kDefaultMaterial));
    const auto check_size = [&](uint64_t adding) {
        if (scene.triangles.size() + adding > kMaxTriangles)
            r.fail(t.source(), fmt::format("{} adds {} triangles, taking the scene past {}", prefix,
                                           adding, kMaxTriangles));
    };
    const size_t first = scene.triangles.size();
    if (type == "sphere") {
        r.allow_keys(t, prefix, {"type", "material", "center", "radius", "segments", "rings"});
        SphereParams sphere = read_sphere_shape(r, t, prefix);
        sphere.center = r.vec3(r.required(t, prefix, "center"), join(prefix, "center"));
        check_size(uint64_t{2} * sphere.segments * sphere.rings);
        generate_sphere(sphere, material, scene.triangles);
    } else if (type == "terrain") {
        r.allow_keys(t, prefix, {"type", "material", "center", "size", "cells", "height", "seed"});
        TerrainParams terrain;
        terrain.center = r.vec3(t, prefix, "center", kAnyFinite, terrain.center);
        if (const toml::node* size = t.get("size")) {
            const auto v = r.numbers(*size, join(prefix, "size"), 2, kPositive);
            terrain.size = {float(v[0]), float(v[1])};
        }
        if (const toml::node* cells = t.get("cells"))
            terrain.cells = read_uvec2(r, *cells, join(prefix, "cells"), 1, 16384);
        terrain.height = float(r.number(t, prefix, "height", kNonNegative, terrain.height));
        terrain.seed = r.integer(t, prefix, "seed", 0, UINT32_MAX, terrain.seed);
        check_size(uint64_t{2} * terrain.cells.x * terrain.cells.y);
        generate_terrain(terrain, material, scene.triangles);
    } else if (type == "sphere_grid") {
        r.allow_keys(
            t, prefix,
            {"type", "material", "center", "count", "spacing", "radius", "segments", "rings"});
        SphereGridParams grid;
        grid.sphere = read_sphere_shape(r, t, prefix);
        grid.center = r.vec3(r.required(t, prefix, "center"), join(prefix, "center"));
        grid.count = read_uvec2(r, r.required(t, prefix, "count"), join(prefix, "count"), 1, 4096);
        grid.spacing =
            float(r.number(r.required(t, prefix, "spacing"), join(prefix, "spacing"), kPositive));
        check_size(uint64_t{2} * grid.count.x * grid.count.y * grid.sphere.segments *
                   grid.sphere.rings);
        generate_sphere_grid(grid, material, scene.triangles);
    } else {
        r.fail(r.required(t, prefix, "type").source(),
               fmt::format("{}.type must be one of sphere, terrain, sphere_grid, got '{}'", prefix,
                           type));
    }
    scene.sources.push_back(
        {fmt::format("generator {} ({})", type, prefix), scene.triangles.size() - first, 0, 0});
}

}  // namespace

Aabb bounds_of(std::span<const Triangle> triangles) {
    Aabb box{triangles.front().v0, triangles.front().v0};
    for (const Triangle& t : triangles)
        for (const glm::vec3& v : {t.v0, t.v1, t.v2}) {
            box.lo = glm::min(box.lo, v);
            box.hi = glm::max(box.hi, v);
        }
    return box;
}

Camera frame_bounds(const Aabb& bounds, float aspect) {
    Camera camera;
    const glm::vec3 center = 0.5f * (bounds.lo + bounds.hi);
    const float radius = std::max(0.5f * glm::length(bounds.hi - bounds.lo),
                                  1e-6f * std::max(1.f, glm::length(center)));
    // The sphere must fit the narrower of the two fields of view; 5% margin around it.
    const float half_vertical = glm::radians(camera.vertical_fov_degrees) * 0.5f;
    const float half_horizontal = std::atan(std::tan(half_vertical) * aspect);
    const float distance = 1.05f * radius / std::sin(std::min(half_vertical, half_horizontal));
    const glm::vec3 direction = glm::normalize(glm::vec3(0.6f, 0.45f, 1.f));
    camera.eye = center + distance * direction;
    camera.look_at = center;
    return camera;
}

PointLight default_light(const Camera& camera, const Aabb& bounds, bool light_falloff) {
    const glm::vec3 center = 0.5f * (bounds.lo + bounds.hi);
    const float distance = glm::length(camera.eye - center);
    const glm::vec3 position =
        camera.eye + glm::vec3(0.f, 0.5f * distance, 0.f) + 0.25f * (camera.eye - center);
    const glm::vec3 to_center = position - center;
    return {position, glm::vec3(light_falloff ? glm::dot(to_center, to_center) : 1.f)};
}

Scene scene_from_mesh(const std::filesystem::path& mesh_path) {
    ImportedMesh mesh;
    try {
        mesh = import_mesh(mesh_path);
    } catch (const std::runtime_error& e) {
        throw SceneError(e.what());
    }
    Scene scene;
    scene.name = mesh_path.stem().string();
    scene.triangles = std::move(mesh.triangles);
    scene.sources.push_back(mesh.summary);
    keep_used_materials(scene, mesh.materials);
    const Aabb bounds = bounds_of(scene.triangles);
    scene.camera = frame_bounds(bounds, float(scene.width) / float(scene.height));
    scene.lights.push_back(default_light(scene.camera, bounds, scene.light_falloff));
    return scene;
}

Scene load_scene_file(const std::filesystem::path& toml_path) {
    const Reader r(toml_path.string());
    std::error_code error;
    if (!std::filesystem::exists(toml_path, error))
        throw SceneError(fmt::format("{}: scene file not found", r.file()));
    std::string text;
    try {
        text = read_input_file(toml_path, "scene", kMaxSceneFileBytes,
                               "put the geometry in mesh files the scene names");
        check_toml_nesting(text, r.file());
    } catch (const Error& e) {
        throw SceneError(e.what());
    }
    toml::table root;
    try {
        root = toml::parse(text, r.file());
    } catch (const toml::parse_error& e) {
        r.fail(e.source(), fmt::format("TOML syntax: {}", e.description()));
    }
    r.allow_keys(root, "",
                 {"name", "image", "shading", "camera", "ambient", "background", "lights",
                  "materials", "meshes", "generators"});
    Scene scene;
    scene.name = root.get("name") ? r.text(*root.get("name"), "name") : toml_path.stem().string();
    if (const toml::node* node = root.get("image")) {
        const toml::table& image = r.table(*node, "image");
        r.allow_keys(image, "image", {"width", "height", "samples_per_pixel"});
        scene.width = r.integer(image, "image", "width", 1, 16384, scene.width);
        scene.height = r.integer(image, "image", "height", 1, 16384, scene.height);
        scene.samples_per_pixel =
            r.integer(image, "image", "samples_per_pixel", 1, 65536, scene.samples_per_pixel);
    }
    if (const toml::node* node = root.get("shading")) {
        const toml::table& shading = r.table(*node, "shading");
        r.allow_keys(shading, "shading", {"shadows", "light_falloff"});
        scene.shadows = r.boolean(shading, "shading", "shadows", scene.shadows);
        scene.light_falloff = r.boolean(shading, "shading", "light_falloff", scene.light_falloff);
    }
    scene.ambient = r.vec3(root, "", "ambient", kNonNegative, scene.ambient);
    scene.background = r.vec3(root, "", "background", kNonNegative, scene.background);

    MaterialTable materials;
    if (const toml::node* node = root.get("materials"))
        for (auto&& [name, value] : r.table(*node, "materials"))
            materials.define(
                {std::string(name.str()), r.vec3(value, join("materials", name.str()), kUnit)});

    // Camera and lights are read before the geometry so their mistakes are reported even when
    // a mesh is missing too; their defaults need the geometry's bounds, so they come last.
    std::optional<Camera> camera;
    if (const toml::node* node = root.get("camera"))
        camera = read_camera(r, r.table(*node, "camera"));
    std::optional<std::vector<PointLight>> lights;
    if (const toml::node* node = root.get("lights")) lights = read_lights(r, *node);

    const std::filesystem::path base = toml_path.parent_path();
    if (const toml::node* node = root.get("meshes")) {
        const auto meshes = r.tables(*node, "meshes");
        for (size_t i = 0; i < meshes.size(); ++i)
            read_mesh(r, *meshes[i], fmt::format("meshes[{}]", i), base, materials, scene);
    }
    if (const toml::node* node = root.get("generators")) {
        const auto generators = r.tables(*node, "generators");
        for (size_t i = 0; i < generators.size(); ++i)
            read_generator(r, *generators[i], fmt::format("generators[{}]", i), materials, scene);
    }
    if (scene.triangles.empty())
        r.fail(root.source(), "the scene has no geometry; add [[meshes]] or [[generators]]");
    keep_used_materials(scene, materials.list());

    const Aabb bounds = bounds_of(scene.triangles);
    scene.camera =
        camera ? *camera : frame_bounds(bounds, float(scene.width) / float(scene.height));
    scene.lights =
        lights ? *lights : std::vector{default_light(scene.camera, bounds, scene.light_falloff)};
    return scene;
}

Scene load_scene(const std::filesystem::path& path) {
    if (path.extension() == ".toml") return load_scene_file(path);
    if (is_mesh_file(path)) return scene_from_mesh(path);
    throw SceneError(fmt::format("{}: not a scene file (.toml), and '{}' is not a mesh format "
                                 "tpsim reads ({})",
                                 path.string(), path.extension().string(), mesh_format_list()));
}

}  // namespace tpsim::scene
