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
constexpr double kFloatMax = std::numeric_limits<float>::max();
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
            return std::isinf(v) ? std::string(v < 0 ? "-inf" : "inf") : fmt::format("{:.7g}", v);
        };
        return fmt::format("{}{}, {}{}", lo_open ? '(' : '[', bound(lo), bound(hi),
                           hi_open ? ')' : ']');
    }
};
constexpr Interval kAnyFinite{};
constexpr Interval kNonNegative{0, kInf, false, true};
constexpr Interval kUnit{0, 1, false, false};
/// What goes to the kernel as a float unchanged (colours, ambient): float must hold it.
constexpr Interval kFloatNonNegative{0, kFloatMax, false, false};
/// Mesh scales and generator sizes: every decade in here renders alike (tests/scene).
constexpr Interval kLengthScale{1e-30, 1e30, false, false};

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
        // toml++ gives no double for an integer beyond 2^53 (intensity = 90000000000000000).
        const double v = node.is_integer() ? double(*node.value<int64_t>()) : *node.value<double>();
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

    /// World positions and directions stay double until the scene is camera-relative.
    glm::dvec3 dvec3(const toml::node& node, const std::string& name,
                     const Interval& allowed = kAnyFinite) const {
        const auto v = numbers(node, name, 3, allowed);
        return {v[0], v[1], v[2]};
    }
    /// Values that go to the kernel as they are: `allowed` must lie within float's range.
    glm::vec3 vec3(const toml::node& node, const std::string& name, const Interval& allowed) const {
        return glm::vec3(dvec3(node, name, allowed));
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
    glm::dvec3 dvec3(const toml::table& t, std::string_view prefix, std::string_view key,
                     const Interval& allowed, glm::dvec3 fallback) const {
        const toml::node* node = t.get(key);
        return node ? dvec3(*node, join(prefix, key), allowed) : fallback;
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
            if (list_[i].name == material.name && list_[i].diffuse == material.diffuse &&
                list_[i].emission == material.emission)
                return i;
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

// --- Geometry in double: the world as the scene file describes it -------------------------------

double max_abs(const glm::dvec3& v) {
    return std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)});
}

/// Unit vector along v, without the overflow or underflow of v·v at 1e200 or 1e-200.
glm::dvec3 direction_of(const glm::dvec3& v) {
    const glm::dvec3 w = v / max_abs(v);
    return w / glm::length(w);
}

/// Axis-aligned bounds in world coordinates.
struct WorldBox {
    glm::dvec3 lo{kInf}, hi{-kInf};
    void grow(const glm::dvec3& p) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    void grow(const WorldBox& b) {
        lo = glm::min(lo, b.lo);
        hi = glm::max(hi, b.hi);
    }
    glm::dvec3 center() const { return 0.5 * lo + 0.5 * hi; }
    bool finite() const {
        return std::isfinite(lo.x + lo.y + lo.z + hi.x + hi.y + hi.z) &&
               std::isfinite(max_abs(hi - lo));
    }
};

/// Geometry as read, in its own coordinates (a mesh file's, a generator's around its centre):
/// Scene::triangles[first, first + count), placed in the world by `to_world`, applied in double
/// by the scene compiler once the camera is known.
struct Placement {
    std::string name;  ///< for messages: "meshes[0] (x.obj)", a generator, a bare mesh's path
    size_t first = 0, count = 0;
    glm::dmat4 to_world{1.0};
    /// The farthest vertex from the geometry's own origin, in world units (scaled and turned):
    /// float in a mesh file rounds its coordinates to about 2^-24 of this.
    double own_reach = 0;
};

/// World bounds of a placement's vertices; sets its own_reach.
WorldBox place_in_world(Placement& p, std::span<const Triangle> triangles) {
    const glm::dmat3 linear(p.to_world);
    WorldBox box;
    for (const Triangle& t : triangles.subspan(p.first, p.count))
        for (const glm::vec3& v : {t.v0, t.v1, t.v2}) {
            box.grow(glm::dvec3(p.to_world * glm::dvec4(glm::dvec3(v), 1.0)));
            p.own_reach = std::max(p.own_reach, max_abs(linear * glm::dvec3(v)));
        }
    return box;
}

/// The camera as the scene file gives it (or framing makes it), in world coordinates.
struct WorldCamera {
    glm::dvec3 eye{0, 0, 1}, look_at{0.0}, up{0, 1, 0};
    double fov = 45;
};

/// A point light in world coordinates, and where the file wrote it (for checks that need the
/// whole scene); a default light has no place in the file and needs no checks.
struct WorldLight {
    glm::dvec3 position{0.0};
    glm::dvec3 intensity{1.0};  ///< color * intensity
    std::optional<toml::source_region> position_at, intensity_at;
};

/// Rotation by `degrees` about coordinate axis 0, 1 or 2 (right-handed). Quarter turns are exact
/// (cos 90° is 0, not 6e-17), so an up-axis change or a rotate = [-90, 0, 0] only permutes axes.
glm::dmat4 rotation(double degrees, int axis) {
    double c = 0, s = 0;
    if (const double quarters = degrees / 90; quarters == std::round(quarters)) {
        const int q = (int(quarters) % 4 + 4) % 4;
        c = q == 0 ? 1 : q == 2 ? -1 : 0;
        s = q == 1 ? 1 : q == 3 ? -1 : 0;
    } else {
        c = std::cos(glm::radians(degrees));
        s = std::sin(glm::radians(degrees));
    }
    glm::dmat4 m(1.0);
    const int i = (axis + 1) % 3, j = (axis + 2) % 3;  // the plane turned: i towards j
    m[i][i] = m[j][j] = c;
    m[i][j] = s;
    m[j][i] = -s;
    return m;
}

/// Turns a mesh's `up` axis to +y: z-up becomes (x, z, -y), so the file's -y (the front of a
/// z-up model) faces the default camera at +z.
glm::dmat4 up_to_y(UpAxis up) {
    switch (up) {
    case UpAxis::pos_x:
        return rotation(90, 2);
    case UpAxis::neg_x:
        return rotation(-90, 2);
    case UpAxis::pos_z:
        return rotation(-90, 0);
    case UpAxis::neg_z:
        return rotation(90, 0);
    case UpAxis::neg_y:
        return rotation(180, 0);
    case UpAxis::pos_y:
        break;
    }
    return glm::dmat4(1.0);
}

/// A camera that sees the whole bounding sphere of `bounds` at the given image aspect
/// (width / height), looking from the front (+z), a little right and above, y up. Everything is
/// relative to the box, so a scaled or moved scene gets the scaled or moved camera.
WorldCamera frame_bounds(const WorldBox& bounds, double aspect) {
    WorldCamera camera;
    const glm::dvec3 center = bounds.center();
    const glm::dvec3 extent = bounds.hi - bounds.lo;
    // A box that is one point still needs a distance: one relative to where the point lies.
    const double radius = max_abs(extent) > 0
                              ? 0.5 * max_abs(extent) * glm::length(extent / max_abs(extent))
                          : max_abs(center) > 0 ? 0x1p-20 * max_abs(center)
                                                : 1.0;
    // The sphere must fit the narrower of the two fields of view; 5% margin around it.
    const double half_vertical = glm::radians(camera.fov) * 0.5;
    const double half_horizontal = std::atan(std::tan(half_vertical) * aspect);
    const double distance = 1.05 * radius / std::sin(std::min(half_vertical, half_horizontal));
    camera.eye = center + distance * direction_of(glm::dvec3(0.6, 0.45, 1.0));
    camera.look_at = center;
    return camera;
}

/// A light above and behind the camera, bright enough that the irradiance at the centre of
/// `bounds` is 1 (with falloff, I / d^2; without, I).
WorldLight default_light(const WorldCamera& camera, const WorldBox& bounds, bool light_falloff) {
    const glm::dvec3 center = bounds.center();
    const glm::dvec3 back = camera.eye - center;
    WorldLight light;
    light.position = camera.eye + glm::dvec3(0, 0.5 * glm::length(back), 0) + 0.25 * back;
    const glm::dvec3 to_center = light.position - center;
    light.intensity = glm::dvec3(light_falloff ? glm::dot(to_center, to_center) : 1.0);
    return light;
}

// --- The scene compiler's last step: camera-relative float -----------------------------------

/// Beyond this many times its extent from the world origin, double rounding of the world
/// coordinates (2^-53 of them) exceeds an eighth of float's resolution of the scene (2^-24 of
/// its extent): translating the scene then moves vertices, and the user is warned.
constexpr double kFarFromOriginRatio = 0x1p26;
/// A mesh whose file coordinates reach more than this many frame units from the file's own
/// origin was rounded by float in the file more coarsely (8x) than the compiled scene resolves.
constexpr double kCoarseFileRatio = 8;
/// Lights farther than this from the eye, in frame units (the scene fits in [-1, 1]), would
/// overflow the kernel's float squared distance (2^128).
constexpr double kMaxLightDistance = 0x1p60;

/// The frame of a scene seen by `camera`: origin at the eye, unit the power of two that brings
/// every vertex into [-1, 1] (0.5 <= max |v - eye| / unit < 1).
Frame frame_of(const WorldCamera& camera, const WorldBox& bounds, const std::string& source) {
    const double reach = std::max(max_abs(bounds.lo - camera.eye), max_abs(bounds.hi - camera.eye));
    // Within 2^+-1000, unit and 1 / unit are both normal doubles.
    if (!(reach < 0x1p1000) || (reach > 0 && reach < 0x1p-1000))
        throw SceneError(fmt::format("{}: the scene reaches {:.3g} from the camera; double "
                                     "precision holds 1e-301 to 1e301: scale it",
                                     source, reach));
    return {camera.eye, reach > 0 ? std::ldexp(1.0, std::ilogb(reach) + 1) : 1.0};
}

/// Narrows the world to float in `frame`: vertices (placed in double first), camera and lights.
/// Where double rounding of far-off world coordinates limits what float could resolve, warns.
void compile(Scene& scene, std::span<const Placement> placements, const WorldBox& bounds,
             const WorldCamera& camera, const std::vector<WorldLight>& lights, const Frame& frame,
             const std::string& source) {
    const glm::dmat4 world_to_frame = glm::scale(glm::dmat4(1.0), glm::dvec3(1.0 / frame.unit)) *
                                      glm::translate(glm::dmat4(1.0), -frame.origin);
    for (const Placement& p : placements) {
        // Translation and recentring combine first: a mesh moved by T seen by a camera moved by
        // T gives the same numbers, however large T.
        const glm::dmat4 m = world_to_frame * p.to_world;
        const auto place = [&m](glm::vec3& v) {
            v = glm::vec3(m * glm::dvec4(glm::dvec3(v), 1.0));
        };
        for (Triangle& t : std::span(scene.triangles).subspan(p.first, p.count)) {
            place(t.v0);
            place(t.v1);
            place(t.v2);
        }
    }
    scene.camera.eye = glm::vec3(0.f);
    scene.camera.look_at = glm::vec3(direction_of(camera.look_at - camera.eye));
    scene.camera.up = glm::vec3(direction_of(camera.up));
    scene.camera.vertical_fov_degrees = camera.fov;
    // I / d^2 is the same when d and I / unit^2 are used: irradiance does not change.
    const double intensity_unit = scene.light_falloff ? frame.unit * frame.unit : 1.0;
    scene.lights.clear();
    for (const WorldLight& light : lights)
        scene.lights.push_back({glm::vec3((light.position - frame.origin) / frame.unit),
                                glm::vec3(light.intensity / intensity_unit)});
    scene.frame = frame;

    const double from_origin =
        std::max({max_abs(camera.eye), max_abs(bounds.lo), max_abs(bounds.hi)});
    const double extent = 0.5 * frame.unit;  // within a factor 2 of the farthest vertex
    if (from_origin > kFarFromOriginRatio * extent)
        scene.warnings.push_back(fmt::format(
            "{}: the scene lies {:.3g} from the world origin, {:.3g} times its extent seen from "
            "the camera; beyond {:.3g} times, double rounding of world coordinates moves vertices "
            "by more than float resolves, so moving the scene changes pixels: translate the "
            "meshes, camera and lights nearer the origin",
            source, from_origin, from_origin / extent, kFarFromOriginRatio));
    for (const Placement& p : placements)
        if (p.own_reach > kCoarseFileRatio * frame.unit)
            scene.warnings.push_back(fmt::format(
                "{}: {}: its coordinates lie up to {:.3g} from the mesh file's own origin, {:.3g} "
                "times the scene's extent seen from the camera; float in the file rounds them to "
                "about {:.2g}, coarser than the image resolves: export the mesh centred on its "
                "origin and place it with translate",
                source, p.name, p.own_reach, p.own_reach / extent, p.own_reach * 0x1p-24));
}

// --- Reading the scene file ----------------------------------------------------------------

/// Neighbouring pixels' rays are float directions of length about 1: they must differ by many
/// float steps (2^-24) for the image not to come out quantised. 2^-19 radians is 32 steps.
constexpr double kMinRadiansPerPixel = 0x1p-19;

/// The smallest 3-significant-digit decimal >= v, as parsed: a range printed in a message then
/// accepts its own bound.
double round_up_3(double v) {
    const int exponent = int(std::floor(std::log10(v))) - 2;
    return std::stod(fmt::format("{}e{}", std::ceil(v / std::pow(10.0, exponent)), exponent));
}

WorldCamera read_camera(const Reader& r, const toml::table& t, uint32_t image_height) {
    r.allow_keys(t, "camera", {"eye", "look_at", "up", "fov"});
    WorldCamera camera;
    camera.eye = r.dvec3(r.required(t, "camera", "eye"), "camera.eye");
    camera.look_at = r.dvec3(r.required(t, "camera", "look_at"), "camera.look_at");
    camera.up = r.dvec3(t, "camera", "up", kAnyFinite, camera.up);
    if (const toml::node* fov = t.get("fov")) {
        camera.fov = r.number(*fov, "camera.fov", Interval{0, 180, true, true});
        const double min_fov = round_up_3(glm::degrees(kMinRadiansPerPixel * image_height));
        if (camera.fov < min_fov)
            r.fail(fov->source(),
                   fmt::format("camera.fov must be in [{:.3g}, 180) for a {}-pixel-high image "
                               "(narrower, float cannot tell neighbouring pixels' rays apart), "
                               "got {}",
                               min_fov, image_height, camera.fov));
    }
    // Relative tests, in double: any scale of scene and camera passes or fails alike.
    const glm::dvec3 view = camera.look_at - camera.eye;
    if (max_abs(view) == 0) r.fail(t.source(), "camera.eye and camera.look_at must differ");
    if (!std::isfinite(max_abs(view)))
        r.fail(t.source(), "camera.look_at - camera.eye overflows double; bring them closer");
    if (max_abs(camera.up) == 0 ||
        glm::length(glm::cross(direction_of(view), direction_of(camera.up))) < 1e-6)
        r.fail(t.source(), "camera.up must be non-zero and not parallel to look_at - eye");
    return camera;
}

std::vector<WorldLight> read_lights(const Reader& r, const toml::node& node) {
    std::vector<WorldLight> lights;
    const auto tables = r.tables(node, "lights");
    for (size_t i = 0; i < tables.size(); ++i) {
        const std::string prefix = fmt::format("lights[{}]", i);
        const toml::table& t = *tables[i];
        r.allow_keys(t, prefix, {"position", "color", "intensity"});
        WorldLight light;
        const toml::node& position = r.required(t, prefix, "position");
        light.position = r.dvec3(position, join(prefix, "position"));
        light.position_at = position.source();
        const glm::dvec3 color(r.vec3(t, prefix, "color", kFloatNonNegative, glm::vec3(1.f)));
        const toml::node* intensity = t.get("intensity");
        light.intensity_at = intensity ? intensity->source() : t.source();
        light.intensity =
            color *
            (intensity ? r.number(*intensity, join(prefix, "intensity"), kNonNegative) : 1.0);
        lights.push_back(light);
    }
    return lights;
}

/// What float can hold of the lights once the frame is known: their distance from the eye
/// and their intensity in frame units.
void check_lights(const Reader& r, const std::vector<WorldLight>& lights, const Frame& frame,
                  bool light_falloff) {
    const double intensity_unit = light_falloff ? frame.unit * frame.unit : 1.0;
    for (size_t i = 0; i < lights.size(); ++i) {
        const WorldLight& light = lights[i];
        const double distance = max_abs(light.position - frame.origin);
        if (light.position_at && !(distance <= kMaxLightDistance * frame.unit))
            r.fail(*light.position_at,
                   fmt::format("lights[{}].position is {:.3g} from camera.eye, more than {:.3g} "
                               "times the scene's extent ({:.3g}); float cannot hold the "
                               "squared distance: move the light nearer",
                               i, distance, kMaxLightDistance, frame.unit));
        const double brightest =
            std::max({light.intensity.x, light.intensity.y, light.intensity.z});
        if (light.intensity_at && brightest / intensity_unit > kFloatMax)
            r.fail(*light.intensity_at,
                   fmt::format("lights[{}]: color x intensity = {:.3g} is more than float holds "
                               "for a scene this size{} (at most {:.3g})",
                               i, brightest,
                               light_falloff ? " with light_falloff (I / d^2, d in units of "
                                               "the scene's extent)"
                                             : "",
                               kFloatMax * intensity_unit));
    }
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

glm::dmat4 read_transform(const Reader& r, const toml::table& t, const std::string& prefix) {
    UpAxis up = UpAxis::pos_y;
    if (const toml::node* node = t.get("up")) {
        const auto axis = parse_up_axis(r.text(*node, join(prefix, "up")));
        if (!axis)
            r.fail(node->source(), fmt::format("{} must be one of {}, got '{}'", join(prefix, "up"),
                                               kUpAxisNames, *node->value<std::string_view>()));
        up = *axis;
    }
    glm::dvec3 scale(1.0);
    if (const toml::node* node = t.get("scale")) {
        const std::string name = join(prefix, "scale");
        // A negative or zero scale would mirror or flatten the mesh: almost always a typo.
        scale = node->is_array() ? r.dvec3(*node, name, kLengthScale)
                                 : glm::dvec3(r.number(*node, name, kLengthScale));
    }
    const glm::dvec3 rotate =
        r.dvec3(t, prefix, "rotate", Interval{-360, 360, false, false}, glm::dvec3(0.0));
    const glm::dvec3 translate = r.dvec3(t, prefix, "translate", kAnyFinite, glm::dvec3(0.0));
    // Applied to the mesh in this order: up axis to +y, scale, rotate about x, then y, then z,
    // translate.
    return glm::translate(glm::dmat4(1.0), translate) * rotation(rotate.z, 2) *
           rotation(rotate.y, 1) * rotation(rotate.x, 0) * glm::scale(glm::dmat4(1.0), scale) *
           up_to_y(up);
}

/// Where the scene file's geometry goes: the triangles, their placements and their bounds.
struct Geometry {
    std::vector<Placement> placements;
    WorldBox bounds;

    /// Places Scene::triangles from `first` on; fails at `where` if the world cannot hold them.
    void place(const Reader& r, const toml::source_region& where, const std::string& prefix,
               const Scene& scene, size_t first, const glm::dmat4& to_world) {
        Placement p{prefix, first, scene.triangles.size() - first, to_world};
        const WorldBox box = place_in_world(p, scene.triangles);
        if (!box.finite())
            r.fail(where, fmt::format("{} reaches beyond what double precision holds "
                                      "(coordinates near 1e308); scale it down",
                                      prefix));
        placements.push_back(std::move(p));
        bounds.grow(box);
    }
};

/// `name = [r, g, b]` (the diffuse albedo) or `name = { diffuse = [r, g, b], emission = [r, g, b]
/// }`.
Material read_material(const Reader& r, const toml::node& value, const std::string& name) {
    const std::string prefix = join("materials", name);
    if (!value.is_table()) return {name, r.vec3(value, prefix, kUnit)};
    const toml::table& t = *value.as_table();
    r.allow_keys(t, prefix, {"diffuse", "emission"});
    return {name, r.vec3(t, prefix, "diffuse", kUnit, kDefaultMaterial.diffuse),
            r.vec3(t, prefix, "emission", kFloatNonNegative, glm::vec3(0.f))};
}

void read_mesh(const Reader& r, const toml::table& t, const std::string& prefix,
               const std::filesystem::path& base, MaterialTable& materials, Scene& scene,
               Geometry& geometry) {
    r.allow_keys(t, prefix, {"path", "up", "scale", "rotate", "translate", "material"});
    const toml::node& path_node = r.required(t, prefix, "path");
    const std::filesystem::path path = base / r.text(path_node, join(prefix, "path"));
    const glm::dmat4 transform = read_transform(r, t, prefix);
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
    const size_t first = scene.triangles.size();
    for (Triangle& triangle : mesh.triangles) {
        triangle.material = file_to_scene[triangle.material];
        scene.triangles.push_back(triangle);
    }
    geometry.place(r, t.source(), fmt::format("{} ({})", prefix, path.filename().string()), scene,
                   first, transform);
    scene.sources.push_back(mesh.summary);
}

SphereParams read_sphere_shape(const Reader& r, const toml::table& t, const std::string& prefix) {
    SphereParams sphere;
    sphere.radius =
        float(r.number(r.required(t, prefix, "radius"), join(prefix, "radius"), kLengthScale));
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

/// Generators build their geometry around the origin in float (sizes within kLengthScale) and
/// are moved to their centre in double, like a mesh's translate: far from the origin they lose
/// nothing, and a terrain's noise pattern moves with its centre.
void read_generator(const Reader& r, const toml::table& t, const std::string& prefix,
                    MaterialTable& materials, Scene& scene, Geometry& geometry) {
    const std::string type = r.text(r.required(t, prefix, "type"), join(prefix, "type"));
    const uint32_t material =
        read_material_ref(r, t, prefix, materials).value_or(materials.intern(kDefaultMaterial));
    const auto check_size = [&](uint64_t adding) {
        if (scene.triangles.size() + adding > kMaxTriangles)
            r.fail(t.source(), fmt::format("{} adds {} triangles, taking the scene past {}", prefix,
                                           adding, kMaxTriangles));
    };
    const size_t first = scene.triangles.size();
    glm::dvec3 center(0.0);
    if (type == "sphere") {
        r.allow_keys(t, prefix, {"type", "material", "center", "radius", "segments", "rings"});
        const SphereParams sphere = read_sphere_shape(r, t, prefix);
        center = r.dvec3(r.required(t, prefix, "center"), join(prefix, "center"));
        check_size(uint64_t{2} * sphere.segments * sphere.rings);
        generate_sphere(sphere, material, scene.triangles);
    } else if (type == "terrain") {
        r.allow_keys(t, prefix, {"type", "material", "center", "size", "cells", "height", "seed"});
        TerrainParams terrain;
        center = r.dvec3(t, prefix, "center", kAnyFinite, center);
        if (const toml::node* size = t.get("size")) {
            const auto v = r.numbers(*size, join(prefix, "size"), 2, kLengthScale);
            terrain.size = {float(v[0]), float(v[1])};
        }
        if (const toml::node* cells = t.get("cells"))
            terrain.cells = read_uvec2(r, *cells, join(prefix, "cells"), 1, 16384);
        terrain.height =
            float(r.number(t, prefix, "height", Interval{0, 1e30, false, false}, terrain.height));
        terrain.seed = r.integer(t, prefix, "seed", 0, UINT32_MAX, terrain.seed);
        check_size(uint64_t{2} * terrain.cells.x * terrain.cells.y);
        generate_terrain(terrain, material, scene.triangles);
    } else if (type == "sphere_grid") {
        r.allow_keys(
            t, prefix,
            {"type", "material", "center", "count", "spacing", "radius", "segments", "rings"});
        SphereGridParams grid;
        grid.sphere = read_sphere_shape(r, t, prefix);
        center = r.dvec3(r.required(t, prefix, "center"), join(prefix, "center"));
        grid.count = read_uvec2(r, r.required(t, prefix, "count"), join(prefix, "count"), 1, 4096);
        grid.spacing = float(
            r.number(r.required(t, prefix, "spacing"), join(prefix, "spacing"), kLengthScale));
        check_size(uint64_t{2} * grid.count.x * grid.count.y * grid.sphere.segments *
                   grid.sphere.rings);
        generate_sphere_grid(grid, material, scene.triangles);
    } else {
        r.fail(r.required(t, prefix, "type").source(),
               fmt::format("{}.type must be one of sphere, terrain, sphere_grid, got '{}'", prefix,
                           type));
    }
    geometry.place(r, t.source(), prefix, scene, first, glm::translate(glm::dmat4(1.0), center));
    scene.sources.push_back(
        {fmt::format("generator {} ({})", type, prefix), scene.triangles.size() - first, 0, 0});
}

}  // namespace

std::optional<UpAxis> parse_up_axis(std::string_view text) {
    if (text.starts_with('+')) text.remove_prefix(1);
    constexpr std::pair<std::string_view, UpAxis> kNames[] = {
        {"x", UpAxis::pos_x},  {"y", UpAxis::pos_y},  {"z", UpAxis::pos_z},
        {"-x", UpAxis::neg_x}, {"-y", UpAxis::neg_y}, {"-z", UpAxis::neg_z},
    };
    for (const auto& [name, axis] : kNames)
        if (text == name) return axis;
    return std::nullopt;
}

Aabb bounds_of(std::span<const Triangle> triangles) {
    Aabb box{triangles.front().v0, triangles.front().v0};
    for (const Triangle& t : triangles)
        for (const glm::vec3& v : {t.v0, t.v1, t.v2}) {
            box.lo = glm::min(box.lo, v);
            box.hi = glm::max(box.hi, v);
        }
    return box;
}

Scene scene_from_mesh(const std::filesystem::path& mesh_path, UpAxis up) {
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
    Placement placement{mesh_path.filename().string(), 0, scene.triangles.size(), up_to_y(up)};
    const WorldBox bounds = place_in_world(placement, scene.triangles);
    const WorldCamera camera = frame_bounds(bounds, double(scene.width) / double(scene.height));
    const std::string source = mesh_path.string();
    compile(scene, {&placement, 1}, bounds, camera,
            {default_light(camera, bounds, scene.light_falloff)}, frame_of(camera, bounds, source),
            source);
    return scene;
}
/// The scene file parsed, every failure one SceneError line; guarded before toml++ sees it.
toml::table parse_scene_file(const Reader& r, const std::filesystem::path& toml_path) {
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
    try {
        return toml::parse(text, r.file());
    } catch (const toml::parse_error& e) {
        r.fail(e.source(), fmt::format("TOML syntax: {}", e.description()));
    }
}

/// The [accel] table: the structure to build and its settings (accel_settings.hpp).
AccelSettings read_accel(const Reader& r, const toml::table& root) {
    AccelSettings settings;
    const toml::node* node = root.get("accel");
    if (!node) return settings;
    for (auto&& [key, value] : r.table(*node, "accel")) {
        const std::string name = join("accel", key.str());
        if (!is_accel_setting(key.str()))
            r.fail(key.source(), fmt::format("unknown key {} (allowed: {})", name,
                                             fmt::join(accel_setting_names(), ", ")));
        AccelValue v;
        if (const auto* text = value.as_string())
            v = text->get();
        else if (const auto* whole = value.as_integer())
            v = whole->get();
        else if (const auto* real = value.as_floating_point())
            v = real->get();
        else if (const auto* flag = value.as_boolean())
            v = flag->get();
        else
            r.fail(value.source(),
                   fmt::format("{} must be a string, a number or true/false, got {}", name,
                               type_name(value)));
        if (const std::string wrong = set_accel_setting(settings, key.str(), v); !wrong.empty())
            r.fail(value.source(), fmt::format("{} {}", name, wrong));
    }
    return settings;
}

Scene load_scene_file(const std::filesystem::path& toml_path) {
    const Reader r(toml_path.string());
    const toml::table root = parse_scene_file(r, toml_path);
    r.allow_keys(root, "",
                 {"name", "image", "shading", "camera", "ambient", "background", "lights",
                  "materials", "meshes", "generators", "accel"});
    Scene scene;
    scene.accel = read_accel(r, root);
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
    scene.ambient = r.vec3(root, "", "ambient", kFloatNonNegative, scene.ambient);
    scene.background = r.vec3(root, "", "background", kFloatNonNegative, scene.background);

    MaterialTable materials;
    if (const toml::node* node = root.get("materials"))
        for (auto&& [name, value] : r.table(*node, "materials"))
            materials.define(read_material(r, value, std::string(name.str())));

    // Camera and lights are read before the geometry so their mistakes are reported even when
    // a mesh is missing too; their defaults need the geometry's bounds, so they come last.
    std::optional<WorldCamera> camera;
    if (const toml::node* node = root.get("camera"))
        camera = read_camera(r, r.table(*node, "camera"), scene.height);
    std::optional<std::vector<WorldLight>> lights;
    if (const toml::node* node = root.get("lights")) lights = read_lights(r, *node);

    const std::filesystem::path base = toml_path.parent_path();
    Geometry geometry;
    if (const toml::node* node = root.get("meshes")) {
        const auto meshes = r.tables(*node, "meshes");
        for (size_t i = 0; i < meshes.size(); ++i)
            read_mesh(r, *meshes[i], fmt::format("meshes[{}]", i), base, materials, scene,
                      geometry);
    }
    if (const toml::node* node = root.get("generators")) {
        const auto generators = r.tables(*node, "generators");
        for (size_t i = 0; i < generators.size(); ++i)
            read_generator(r, *generators[i], fmt::format("generators[{}]", i), materials, scene,
                           geometry);
    }
    if (scene.triangles.empty())
        r.fail(root.source(), "the scene has no geometry; add [[meshes]] or [[generators]]");
    keep_used_materials(scene, materials.list());

    if (!camera) camera = frame_bounds(geometry.bounds, double(scene.width) / double(scene.height));
    if (!lights) lights = {default_light(*camera, geometry.bounds, scene.light_falloff)};
    const Frame frame = frame_of(*camera, geometry.bounds, r.file());
    check_lights(r, *lights, frame, scene.light_falloff);
    compile(scene, geometry.placements, geometry.bounds, *camera, *lights, frame, r.file());
    return scene;
}

AccelSettings load_accel_settings(const std::filesystem::path& path) {
    if (path.extension() != ".toml") return {};
    const Reader r(path.string());
    return read_accel(r, parse_scene_file(r, path));
}

Scene load_scene(const std::filesystem::path& path, UpAxis mesh_up) {
    if (path.extension() == ".toml") return load_scene_file(path);
    if (is_mesh_file(path)) return scene_from_mesh(path, mesh_up);
    throw SceneError(fmt::format("{}: not a scene file (.toml), and '{}' is not a mesh format "
                                 "tpsim reads ({})",
                                 path.string(), path.extension().string(), mesh_format_list()));
}

}  // namespace tpsim::scene
