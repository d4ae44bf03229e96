#include "sim/course/assignment.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <initializer_list>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <toml++/toml.h>

#include "sim/core/error.hpp"
#include "sim/core/input_file.hpp"
#include "sim/core/toml_nesting.hpp"

namespace tpsim::course {
namespace {

constexpr std::uintmax_t kMaxAssignmentBytes = 1 << 20;

/// Reads typed values out of the parsed file, failing with "FILE:LINE:COL: key: problem".
class Reader {
public:
    explicit Reader(std::string file) : file_(std::move(file)) {}

    [[noreturn]] void fail(const toml::source_region& where, std::string_view message) const {
        throw Error(
            fmt::format("{}:{}:{}: {}", file_, where.begin.line, where.begin.column, message));
    }

    void allow_keys(const toml::table& table, std::string_view prefix,
                    std::initializer_list<std::string_view> allowed) const {
        for (auto&& [key, node] : table) {
            if (std::find(allowed.begin(), allowed.end(), key.str()) != allowed.end()) continue;
            fail(key.source(), fmt::format("unknown key {}{} (allowed: {})", prefix, key.str(),
                                           fmt::join(allowed, ", ")));
        }
    }

    const toml::table& table(const toml::node& node, const std::string& name) const {
        if (!node.is_table()) fail(node.source(), fmt::format("{} must be a table", name));
        return *node.as_table();
    }

    std::string string(const toml::node& node, const std::string& name) const {
        if (!node.is_string() || node.as_string()->get().empty())
            fail(node.source(), fmt::format("{} must be a non-empty string", name));
        return node.as_string()->get();
    }

    double number(const toml::node& node, const std::string& name, double lo, double hi) const {
        if (!node.is_number()) fail(node.source(), fmt::format("{} must be a number", name));
        const double v = node.is_integer() ? double(*node.value<int64_t>()) : *node.value<double>();
        if (!std::isfinite(v) || v < lo || v > hi)
            fail(node.source(),
                 fmt::format("{} must be in [{:g}, {:g}], got {:g}", name, lo, hi, v));
        return v;
    }

    uint64_t integer(const toml::node& node, const std::string& name, int64_t lo,
                     int64_t hi) const {
        if (!node.is_integer()) fail(node.source(), fmt::format("{} must be an integer", name));
        const int64_t v = *node.value<int64_t>();
        if (v < lo || v > hi)
            fail(node.source(), fmt::format("{} must be in [{}, {}], got {}", name, lo, hi, v));
        return uint64_t(v);
    }

    /// A path relative to the assignment's folder; the file must exist.
    std::filesystem::path existing_file(const toml::node& node, const std::string& name,
                                        const std::filesystem::path& dir) const {
        const std::filesystem::path path = dir / string(node, name);
        std::error_code ec;
        if (!std::filesystem::is_regular_file(path, ec))
            fail(node.source(), fmt::format("{}: no file {}", name, path.string()));
        return path;
    }

private:
    std::string file_;
};

void read_render(const Reader& r, const toml::table& t, const std::filesystem::path& dir,
                 Assignment& a) {
    r.allow_keys(t, "render.",
                 {"width", "height", "samples_per_pixel", "chip", "max_pixel_instructions",
                  "slow_hint", "baseline"});
    if (auto* n = t.get("width")) a.width = uint32_t(r.integer(*n, "render.width", 1, 4096));
    if (auto* n = t.get("height")) a.height = uint32_t(r.integer(*n, "render.height", 1, 4096));
    if (auto* n = t.get("samples_per_pixel"))
        a.samples_per_pixel = uint32_t(r.integer(*n, "render.samples_per_pixel", 1, 65536));
    if (auto* n = t.get("chip")) a.chip_config = r.existing_file(*n, "render.chip", dir);
    if (auto* n = t.get("max_pixel_instructions"))
        a.max_pixel_instructions =
            r.integer(*n, "render.max_pixel_instructions", 1, int64_t(1) << 40);
    if (auto* n = t.get("slow_hint")) a.slow_hint = r.string(*n, "render.slow_hint");
    if (auto* n = t.get("baseline")) {
        a.baseline = r.string(*n, "render.baseline");
        if (!std::all_of(a.baseline.begin(), a.baseline.end(), [](char c) {
                return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
            }))
            r.fail(n->source(), fmt::format("render.baseline must name one of tpsim's kernels "
                                            "(e.g. \"tracer\"), got \"{}\"",
                                            a.baseline));
    }
}

void read_image(const Reader& r, const toml::table& t, Assignment& a) {
    r.allow_keys(
        t, "image.",
        {"min_psnr", "tolerance", "max_differing", "block", "brighter", "darker", "mixed"});
    if (auto* n = t.get("min_psnr")) a.image.min_psnr = r.number(*n, "image.min_psnr", 0, 200);
    if (auto* n = t.get("tolerance"))
        a.image.tolerance = int(r.integer(*n, "image.tolerance", 0, 255));
    if (auto* n = t.get("max_differing"))
        a.image.max_differing = r.number(*n, "image.max_differing", 0, 1);
    if (auto* n = t.get("block")) a.image.block = int(r.integer(*n, "image.block", 1, 64));
    if (auto* n = t.get("brighter")) a.hints.brighter = r.string(*n, "image.brighter");
    if (auto* n = t.get("darker")) a.hints.darker = r.string(*n, "image.darker");
    if (auto* n = t.get("mixed")) a.hints.mixed = r.string(*n, "image.mixed");
}

/// Each entry of an array of tables, with its "name[i]" for messages.
template <class F>
void for_each_table(const Reader& r, const toml::node& node, const std::string& name, F&& f) {
    const toml::array* array = node.as_array();
    if (!array)
        r.fail(node.source(), fmt::format("{} must be an array of tables ([[{}]])", name, name));
    for (size_t i = 0; i < array->size(); ++i) {
        const std::string entry = fmt::format("{}[{}]", name, i);
        f(r.table((*array)[i], entry), entry);
    }
}

}  // namespace

bool Budget::applies_to(std::string_view scene) const {
    return scenes.empty() || std::find(scenes.begin(), scenes.end(), scene) != scenes.end();
}

std::string Budget::label() const {
    return per.empty() ? stat : stat + " per " + per;
}

Assignment load_assignment(const std::filesystem::path& toml_file) {
    const std::string source = toml_file.string();
    const std::string text = read_input_file(toml_file, "assignment", kMaxAssignmentBytes);
    check_toml_nesting(text, source);
    toml::table root;
    try {
        root = toml::parse(text, source);
    } catch (const toml::parse_error& e) {
        throw Error(fmt::format("{}:{}:{}: {}", source, e.source().begin.line,
                                e.source().begin.column, e.description()));
    }
    const Reader r(source);
    Assignment a;
    a.dir = toml_file.parent_path().empty() ? std::filesystem::path(".") : toml_file.parent_path();
    a.id = std::filesystem::absolute(a.dir).lexically_normal().filename().string();
    if (a.id.empty()) a.id = std::filesystem::absolute(a.dir).parent_path().filename().string();
    r.allow_keys(root, "", {"title", "render", "image", "scenes", "budgets"});
    if (auto* n = root.get("title")) a.title = r.string(*n, "title");
    if (auto* n = root.get("render")) read_render(r, r.table(*n, "render"), a.dir, a);
    if (auto* n = root.get("image")) read_image(r, r.table(*n, "image"), a);

    const toml::node* scenes = root.get("scenes");
    if (!scenes)
        throw Error(
            fmt::format("{}: no [[scenes]]: an assignment renders at least one scene", source));
    for_each_table(r, *scenes, "scenes", [&](const toml::table& t, const std::string& entry) {
        r.allow_keys(t, entry + ".", {"name", "file", "reference"});
        AssignmentScene s;
        const auto required = [&](const char* key) -> const toml::node& {
            if (auto* n = t.get(key)) return *n;
            r.fail(t.source(), fmt::format("{} has no {} (required)", entry, key));
        };
        s.name = r.string(required("name"), entry + ".name");
        if (std::find_if(a.scenes.begin(), a.scenes.end(), [&](const AssignmentScene& o) {
                return o.name == s.name;
            }) != a.scenes.end())
            r.fail(t.get("name")->source(),
                   fmt::format("{}.name '{}' is used twice; give each scene its own name", entry,
                               s.name));
        s.file = r.existing_file(required("file"), entry + ".file", a.dir);
        // The reference may be missing: the checker says how to make it.
        s.reference = a.dir / r.string(required("reference"), entry + ".reference");
        a.scenes.push_back(std::move(s));
    });
    if (a.scenes.empty())
        throw Error(
            fmt::format("{}: scenes is empty: an assignment renders at least one scene", source));

    if (auto* budgets = root.get("budgets"))
        for_each_table(r, *budgets, "budgets", [&](const toml::table& t, const std::string& entry) {
            r.allow_keys(t, entry + ".",
                         {"stat", "per", "max", "min", "max_ratio", "min_ratio", "scenes", "hint"});
            Budget b;
            const toml::node* stat = t.get("stat");
            if (!stat ||
                !(t.get("max") || t.get("min") || t.get("max_ratio") || t.get("min_ratio")))
                r.fail(t.source(),
                       fmt::format("{} needs stat and max, min, max_ratio or min_ratio", entry));
            b.stat = r.string(*stat, entry + ".stat");
            if (auto* n = t.get("max")) b.max = r.number(*n, entry + ".max", 0, 1e300);
            if (auto* n = t.get("min")) b.min = r.number(*n, entry + ".min", 0, 1e300);
            const auto ratio = [&](const char* key) -> std::optional<double> {
                const toml::node* n = t.get(key);
                if (!n) return std::nullopt;
                if (a.baseline.empty())
                    r.fail(n->source(),
                           fmt::format("{}.{} compares with a baseline kernel, but the assignment "
                                       "names none: set render.baseline (e.g. \"tracer\")",
                                       entry, key));
                return r.number(*n, entry + "." + key, 0, 1e6);
            };
            b.max_ratio = ratio("max_ratio");
            b.min_ratio = ratio("min_ratio");
            if (auto* n = t.get("per")) b.per = r.string(*n, entry + ".per");
            if (auto* n = t.get("hint")) b.hint = r.string(*n, entry + ".hint");
            if (auto* n = t.get("scenes")) {
                const toml::array* names = n->as_array();
                if (!names) r.fail(n->source(), entry + ".scenes must be an array of scene names");
                for (const toml::node& name : *names) {
                    const std::string scene = r.string(name, entry + ".scenes");
                    if (std::none_of(a.scenes.begin(), a.scenes.end(),
                                     [&](const AssignmentScene& s) { return s.name == scene; }))
                        r.fail(name.source(),
                               fmt::format("{}.scenes names '{}', which no [[scenes]] entry has",
                                           entry, scene));
                    b.scenes.push_back(scene);
                }
            }
            a.budgets.push_back(std::move(b));
        });
    return a;
}

std::filesystem::path find_assignment(const std::filesystem::path& course_dir,
                                      std::string_view name) {
    const std::filesystem::path root = course_dir / "assignments";
    std::error_code ec;
    if (!std::filesystem::is_directory(root, ec))
        throw Error(fmt::format("no course folder at {} (it holds assignments/<N-name>/); give "
                                "the course folder with --course DIR",
                                course_dir.string()));
    std::vector<std::string> ids;
    for (const auto& entry : std::filesystem::directory_iterator(root, ec))
        if (entry.is_directory() && std::filesystem::exists(entry.path() / "assignment.toml"))
            ids.push_back(entry.path().filename().string());
    std::sort(ids.begin(), ids.end());
    for (const std::string& id : ids)
        if (id == name ||
            (id.starts_with(std::string(name) + "-") &&
             std::all_of(name.begin(), name.end(), [](char c) { return c >= '0' && c <= '9'; }) &&
             !name.empty()))
            return root / id;
    throw Error(fmt::format("no assignment '{}' in {}; the assignments are {} (give the folder "
                            "name or its number)",
                            name, root.string(),
                            ids.empty() ? "none" : fmt::format("{}", fmt::join(ids, ", "))));
}

}  // namespace tpsim::course
