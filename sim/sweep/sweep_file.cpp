// Reading a sweep file and expanding it into jobs; the plan file that records them.
#include <algorithm>
#include <fstream>
#include <map>
#include <set>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "sim/core/error.hpp"
#include "sim/core/input_file.hpp"
#include "sim/core/toml_nesting.hpp"
#include "sim/scene/accel_settings.hpp"
#include "sim/scene/load_scene.hpp"
#include "sim/sweep/sweep.hpp"

namespace tpsim::sweep {
namespace {

constexpr std::uintmax_t kMaxSweepFileBytes = 1 << 20;
/// More jobs than this is a mistake in the file, not a study (each job is one render).
constexpr size_t kMaxJobs = 100000;
constexpr int kPlanVersion = 4;

/// A setting's value and the line it is written on.
struct Value {
    Json value;
    int64_t line = 0;
};

/// A JSON value as the accel settings take it (an array or object: a string they refuse).
scene::AccelValue accel_value(const Json& value) {
    if (value.is_boolean()) return value.get<bool>();
    if (value.is_number_integer()) return value.get<int64_t>();
    if (value.is_number()) return value.get<double>();
    if (value.is_string()) return value.get<std::string>();
    return value.dump();
}

/// The settings a job sets, by name, for the plan.
Json accel_json(const scene::AccelSettings& settings) {
    Json object = Json::object();
    for (const auto& [name, value] : scene::accel_setting_values(settings))
        std::visit([&](const auto& v) { object[name] = v; }, value);
    return object;
}

/// One key of the file before expansion: a fixed value, or an axis (an array).
struct Entry {
    std::string name;
    std::vector<Value> values;
    bool axis = false;
    toml::source_position position;  ///< orders the entries as the file writes them
};

/// 64-bit FNV-1a: a small, fixed, documented hash (ids must not change between tpsim builds
/// or machines, so std::hash will not do). Collisions among a sweep's jobs are checked.
uint64_t fnv1a(std::string_view text) {
    uint64_t hash = 0xcbf29ce484222325ull;
    for (unsigned char ch : text) {
        hash ^= ch;
        hash *= 0x100000001b3ull;
    }
    return hash;
}

std::string job_id(std::vector<Setting> settings) {
    std::sort(settings.begin(), settings.end(),
              [](const Setting& a, const Setting& b) { return a.name < b.name; });
    std::string canonical;
    for (const Setting& s : settings)
        canonical += s.name + "=" + s.value.dump() + "\n";
    return fmt::format("{:012x}", fnv1a(canonical) >> 16);
}

std::string value_text(const Json& value) {
    return value.is_string() ? value.get<std::string>() : value.dump();
}

/// The chip configuration as the TOML lines of the fields that differ from the defaults: the
/// plan stays small (every job reads it), and parse_config reads it back.
std::string changed_fields(const timing::ChipConfig& chip) {
    const std::vector<timing::ConfigField> defaults = timing::config_fields({});
    const std::vector<timing::ConfigField> fields = timing::config_fields(chip);
    std::string lines;
    for (size_t f = 0; f < fields.size(); ++f)
        if (fields[f] != defaults[f])
            lines += fmt::format("{} = {}\n", fields[f].key, fields[f].text());
    return lines;
}

class Reader {
public:
    Reader(std::filesystem::path file, const KernelResolver& resolve_kernel)
        : file_(std::move(file)), base_(file_.parent_path()), resolve_kernel_(resolve_kernel) {}

    Sweep read() {
        const std::string text = read_input_file(file_, "sweep file", kMaxSweepFileBytes);
        check_toml_nesting(text, file_.string());
        toml::table table;
        try {
            table = toml::parse(text, file_.string());
        } catch (const toml::parse_error& e) {
            fail(e.source().begin.line, std::string(e.description()));
        }
        collect_entries(table, "");
        std::sort(entries_.begin(), entries_.end(), [](const Entry& a, const Entry& b) {
            return std::pair(a.position.line, a.position.column) <
                   std::pair(b.position.line, b.position.column);
        });
        Sweep sweep;
        sweep.file = file_;
        for (const Entry& entry : entries_) {
            for (const Value& v : entry.values)
                check_value(entry.name, v);
            if (entry.axis) {
                Axis axis{entry.name, {}};
                for (const Value& v : entry.values)
                    axis.values.push_back(v.value);
                sweep.axes.push_back(std::move(axis));
            } else {
                sweep.fixed.push_back({entry.name, entry.values[0].value});
            }
        }
        if (!has("scene"))
            fail(1, "no scene: give one or more, e.g. scene = [\"scenes/cornell.toml\"]");
        read_zip(table, sweep);
        expand(sweep);
        return sweep;
    }

private:
    [[noreturn]] void fail(int64_t line, std::string_view message) const {
        throw Error(fmt::format("{}:{}: {}", file_.string(), line, message));
    }

    bool has(std::string_view name) const {
        return std::any_of(entries_.begin(), entries_.end(),
                           [&](const Entry& e) { return e.name == name; });
    }

    static bool is_run_setting(std::string_view name) {
        return std::find(std::begin(kRunSettings), std::end(kRunSettings), name) !=
               std::end(kRunSettings);
    }

    std::optional<timing::ConfigField> config_field(std::string_view name) const {
        for (const timing::ConfigField& f : timing::config_fields(timing::ChipConfig{}))
            if (f.key == name) return f;
        return std::nullopt;
    }

    Value scalar(const toml::node& node, const std::string& name) const {
        const int64_t line = node.source().begin.line;
        if (const auto s = node.value_exact<std::string>()) return {*s, line};
        if (const auto i = node.value_exact<int64_t>()) return {*i, line};
        if (const auto b = node.value_exact<bool>()) return {*b, line};
        if (const auto d = node.value_exact<double>()) return {*d, line};
        fail(line, fmt::format("{} must be a string, a number or true/false, or an array of "
                               "them (an axis)",
                               name));
    }

    void collect_entries(const toml::table& table, const std::string& prefix) {
        for (const auto& [key, node] : table) {
            const std::string name =
                prefix.empty() ? std::string(key.str()) : prefix + "." + std::string(key.str());
            const int64_t line = node.source().begin.line;
            if (prefix.empty() && name == "zip") continue;
            if (const toml::table* sub = node.as_table()) {
                if (is_run_setting(name))
                    fail(line, fmt::format("{} takes a value or an array of values", name));
                collect_entries(*sub, name);
                continue;
            }
            if (!is_run_setting(name) && !config_field(name)) unknown(line, name);
            Entry entry{name, {}, false, node.source().begin};
            if (const toml::array* array = node.as_array()) {
                entry.axis = true;
                if (array->empty())
                    fail(line, fmt::format("the axis {} has no values: give at least one", name));
                for (const toml::node& element : *array)
                    entry.values.push_back(scalar(element, name));
                for (size_t i = 0; i < entry.values.size(); ++i)
                    for (size_t j = 0; j < i; ++j)
                        if (entry.values[i].value == entry.values[j].value)
                            fail(entry.values[i].line,
                                 fmt::format("the axis {} has the value {} twice", name,
                                             entry.values[i].value.dump()));
            } else {
                entry.values.push_back(scalar(node, name));
            }
            entries_.push_back(std::move(entry));
        }
    }

    [[noreturn]] void unknown(int64_t line, const std::string& name) const {
        fail(line, fmt::format("unknown setting '{}': give a run setting ({}), a chip "
                               "configuration key such as l1.size_bytes "
                               "(configs/trax.toml lists them), or zip",
                               name, fmt::join(kRunSettings, ", ")));
    }

    uint64_t integer(const std::string& name, const Value& v, uint64_t lo, uint64_t hi) const {
        if (!v.value.is_number_integer() || v.value.get<int64_t>() < int64_t(lo) ||
            uint64_t(v.value.get<int64_t>()) > hi)
            fail(v.line, fmt::format("{} must be a whole number in [{}, {}], got {}", name, lo, hi,
                                     v.value.dump()));
        return v.value.get<uint64_t>();
    }

    std::string one_of(const std::string& name, const Value& v,
                       const std::vector<std::string>& allowed) const {
        if (v.value.is_string())
            for (const std::string& a : allowed)
                if (v.value.get<std::string>() == a) return a;
        fail(v.line, fmt::format("{} must be one of {}, got {}", name, fmt::join(allowed, ", "),
                                 v.value.dump()));
    }

    std::filesystem::path existing_file(const std::string& name, const Value& v) const {
        if (!v.value.is_string()) fail(v.line, fmt::format("{} must be a file name", name));
        const std::filesystem::path path = base_ / v.value.get<std::string>();
        if (std::error_code ec; !std::filesystem::is_regular_file(path, ec))
            fail(v.line, fmt::format("{} '{}' does not exist (paths are relative to the sweep "
                                     "file's directory: {})",
                                     name, v.value.get<std::string>(), path.string()));
        return std::filesystem::absolute(path).lexically_normal();
    }

    /// Checks one value (each axis value once, before any job is made), so that the error
    /// names the line it is written on.
    void check_value(const std::string& name, const Value& v) {
        JobRun run;
        apply(run, name, v);
    }

    /// Sets one setting of a job. Chip configuration keys go into `chip_keys`, applied after
    /// the base configuration (`config`) is known.
    void apply(JobRun& run, const std::string& name, const Value& v,
               std::vector<std::pair<std::string, Value>>* chip_keys = nullptr) {
        if (name == "scene") {
            run.scene = existing_file(name, v);
        } else if (name == "kernel") {
            if (!v.value.is_string()) fail(v.line, "kernel must be a name or a path");
            const std::string kernel = v.value.get<std::string>();
            if (kernel.find('/') != std::string::npos || kernel.ends_with(".elf")) {
                run.kernel = existing_file(name, v);
            } else {
                try {
                    run.kernel = resolve_kernel_(kernel);
                } catch (const Error& e) {
                    fail(v.line, e.what());
                }
            }
        } else if (name == "config") {
            const std::filesystem::path path = existing_file(name, v);
            try {
                run.chip = timing::load_config(path.string());
            } catch (const Error& e) {
                fail(v.line, fmt::format("config: {}", e.what()));
            }
        } else if (name == "accel" || scene::is_accel_setting(name)) {
            // The sweep's `accel` is the scene file's [accel] structure.
            const std::string wrong = scene::set_accel_setting(
                run.accel, name == "accel" ? "structure" : name, accel_value(v.value));
            if (!wrong.empty()) fail(v.line, fmt::format("{} {}", name, wrong));
        } else if (name == "width") {
            run.width = uint32_t(integer(name, v, 1, 16384));
        } else if (name == "height") {
            run.height = uint32_t(integer(name, v, 1, 16384));
        } else if (name == "spp") {
            run.spp = uint32_t(integer(name, v, 1, 65536));
        } else if (name == "seed") {
            run.seed = uint32_t(integer(name, v, 0, UINT32_MAX));
        } else if (name == "timing") {
            run.timing = one_of(name, v, {"cycle", "sampled", "none"});
        } else {
            const timing::ConfigField field = *config_field(name);
            const bool ok = field.is_bool   ? v.value.is_boolean()
                            : field.is_real ? v.value.is_number()
                                            : v.value.is_number_integer();
            if (!ok)
                fail(v.line, fmt::format("{} must be {}, got {}", name,
                                         field.is_bool   ? "true or false"
                                         : field.is_real ? "a number"
                                                         : "an integer",
                                         v.value.dump()));
            // Ranges and cross-field rules are checked with the job's whole configuration.
            if (chip_keys) chip_keys->emplace_back(name, v);
        }
    }

    void read_zip(const toml::table& table, Sweep& sweep) const {
        const toml::node* node = table.get("zip");
        if (!node) return;
        const int64_t line = node->source().begin.line;
        const toml::array* groups = node->as_array();
        const char* usage = "zip must list the axes that advance together, e.g. zip = "
                            "[\"l1.size_bytes\", \"l2.size_bytes\"], or several groups: zip = "
                            "[[\"a\", \"b\"], [\"c\", \"d\"]]";
        if (!groups || groups->empty()) fail(line, usage);
        std::vector<const toml::array*> lists;
        if (groups->is_array_of_tables()) fail(line, usage);
        if ((*groups)[0].is_array()) {
            for (const toml::node& g : *groups) {
                if (!g.is_array()) fail(line, usage);
                lists.push_back(g.as_array());
            }
        } else {
            lists.push_back(groups);
        }
        std::set<std::string> zipped;
        for (const toml::array* list : lists) {
            std::vector<std::string> group;
            size_t length = 0;
            for (const toml::node& element : *list) {
                const auto name = element.value_exact<std::string>();
                if (!name) fail(line, usage);
                const auto axis = std::find_if(sweep.axes.begin(), sweep.axes.end(),
                                               [&](const Axis& a) { return a.name == *name; });
                if (axis == sweep.axes.end())
                    fail(line, fmt::format("zip names '{}', which is not an axis (a setting with "
                                           "an array of values)",
                                           *name));
                if (!zipped.insert(*name).second)
                    fail(line, fmt::format("zip names the axis {} twice", *name));
                if (group.empty()) length = axis->values.size();
                if (axis->values.size() != length)
                    fail(line, fmt::format("zip: the axis {} has {} values but {} has {}: axes "
                                           "that advance together need as many values",
                                           *name, axis->values.size(), group[0], length));
                group.push_back(*name);
            }
            if (group.size() < 2) fail(line, "a zip group needs two or more axes");
            sweep.zip.push_back(std::move(group));
        }
    }

    /// The cross product of the dimensions (single axes and zip groups) in the file's order.
    void expand(Sweep& sweep) {
        std::vector<std::vector<size_t>> dimensions;  // axis indices advancing together
        std::vector<bool> placed(sweep.axes.size(), false);
        for (size_t a = 0; a < sweep.axes.size(); ++a) {
            if (placed[a]) continue;
            std::vector<size_t> dimension{a};
            for (const auto& group : sweep.zip)
                if (std::find(group.begin(), group.end(), sweep.axes[a].name) != group.end()) {
                    dimension.clear();
                    for (const std::string& name : group)
                        for (size_t b = 0; b < sweep.axes.size(); ++b)
                            if (sweep.axes[b].name == name) dimension.push_back(b);
                }
            for (size_t b : dimension)
                placed[b] = true;
            dimensions.push_back(std::move(dimension));
        }
        size_t count = 1;
        for (const auto& d : dimensions) {
            count *= sweep.axes[d[0]].values.size();
            if (count > kMaxJobs)
                fail(1,
                     fmt::format("the sweep has more than {} jobs: sweep fewer values", kMaxJobs));
        }
        std::vector<size_t> index(dimensions.size(), 0);
        std::map<std::string, size_t> ids;
        for (size_t n = 0; n < count; ++n) {
            Job job;
            job.values.resize(sweep.axes.size());
            for (size_t d = 0; d < dimensions.size(); ++d)
                for (size_t a : dimensions[d])
                    job.values[a] = sweep.axes[a].values[index[d]];
            make_job(sweep, job);
            if (const auto [it, fresh] = ids.emplace(job.id, n); !fresh)
                fail(1, fmt::format("two jobs have the same settings ({}): every combination "
                                    "must differ",
                                    sweep.describe(job)));
            sweep.jobs.push_back(std::move(job));
            for (size_t d = dimensions.size(); d-- > 0;) {  // odometer, last dimension fastest
                if (++index[d] < sweep.axes[dimensions[d][0]].values.size()) break;
                index[d] = 0;
            }
        }
    }

    int64_t line_of(const std::string& name) const {
        for (const Entry& e : entries_)
            if (e.name == name) return e.position.line;
        return 1;
    }

    void make_job(const Sweep& sweep, Job& job) {
        std::vector<Setting> settings = sweep.fixed;
        for (size_t a = 0; a < sweep.axes.size(); ++a)
            settings.push_back({sweep.axes[a].name, job.values[a]});
        job.id = job_id(settings);
        // The base configuration first, then the keys over it, then the run settings.
        std::vector<std::pair<std::string, Value>> chip_keys;
        for (const Setting& s : settings)
            if (s.name == "config") apply(job.run, s.name, {s.value, line_of(s.name)});
        for (const Setting& s : settings)
            if (s.name != "config") apply(job.run, s.name, {s.value, line_of(s.name)}, &chip_keys);
        // No kernel: the tracer of the structure asked for, here or in the scene file.
        if (job.run.kernel.empty()) {
            std::optional<scene::AccelStructure> structure = job.run.accel.structure;
            try {
                if (!structure) structure = scene::load_accel_settings(job.run.scene).structure;
            } catch (const Error& e) {
                fail(line_of("scene"), e.what());
            }
            job.run.kernel = resolve_kernel_(std::string(
                scene::accel_info(structure.value_or(scene::AccelStructure::bvh2)).default_kernel));
        }
        if (chip_keys.empty()) return;
        // All keys at once over the base, then validated together (l1.line_bytes and
        // l2.line_bytes may only change together). Each key is written on its line of the
        // sweep file, so that an error about one key names the line it comes from.
        std::sort(chip_keys.begin(), chip_keys.end(),
                  [](const auto& a, const auto& b) { return a.second.line < b.second.line; });
        std::string toml;
        int64_t line = 1;
        for (const auto& [name, v] : chip_keys) {
            for (; line < v.line; ++line)
                toml += '\n';
            toml += fmt::format("{} = {}\n", name, v.value.dump());
            ++line;
        }
        const std::string source = file_.string();
        try {
            job.run.chip = timing::parse_config(toml, source, job.run.chip);
        } catch (const Error& e) {
            const std::string what = e.what();
            if (what.starts_with(source + ": "))  // a rule between fields, not one key's value
                fail(chip_keys.back().second.line,
                     fmt::format("the job {} has a chip configuration tpsim refuses: {}; leave "
                                 "the combination out (zip) or change the values",
                                 sweep.describe(job), what.substr(source.size() + 2)));
            throw;
        }
    }

    std::filesystem::path file_;
    std::filesystem::path base_;
    const KernelResolver& resolve_kernel_;
    std::vector<Entry> entries_;
};

}  // namespace

const Job* Sweep::find(std::string_view id) const {
    for (const Job& job : jobs)
        if (job.id == id) return &job;
    return nullptr;
}

std::string Sweep::describe(const Job& job) const {
    std::string text;
    for (size_t a = 0; a < axes.size(); ++a)
        text += fmt::format("{}{}={}", a ? ", " : "", axes[a].name, value_text(job.values[a]));
    return text.empty() ? "the one job" : text;
}

Sweep load_sweep(const std::filesystem::path& file, const KernelResolver& resolve_kernel) {
    return Reader(file, resolve_kernel).read();
}

std::filesystem::path plan_path(const std::filesystem::path& dir) {
    return dir / "sweep.json";
}
std::filesystem::path stats_path(const std::filesystem::path& dir, const std::string& id) {
    return dir / "jobs" / (id + ".json");
}
std::filesystem::path error_path(const std::filesystem::path& dir, const std::string& id) {
    return dir / "jobs" / (id + ".error");
}
std::filesystem::path log_dir(const std::filesystem::path& dir) {
    return dir / "logs";
}

void write_plan(const Sweep& sweep, const std::filesystem::path& dir) {
    std::error_code ec;
    for (const std::filesystem::path& d : {dir, dir / "jobs", log_dir(dir)})
        if (std::filesystem::create_directories(d, ec); ec)
            throw Error(fmt::format("cannot create the results directory '{}': {}", d.string(),
                                    ec.message()));
    Json doc = {{"format", "tpsim-sweep"},
                {"version", kPlanVersion},
                {"file", std::filesystem::absolute(sweep.file).string()}};
    Json axes = Json::array(), fixed = Json::object(), jobs = Json::array();
    for (const Axis& a : sweep.axes)
        axes.push_back({{"name", a.name}, {"values", a.values}});
    for (const Setting& s : sweep.fixed)
        fixed[s.name] = s.value;
    for (const Job& job : sweep.jobs) {
        const JobRun& r = job.run;
        jobs.push_back({{"id", job.id},
                        {"values", job.values},
                        {"run",
                         {{"scene", r.scene.string()},
                          {"kernel", r.kernel.string()},
                          {"accel", accel_json(r.accel)},
                          {"width", r.width},
                          {"height", r.height},
                          {"spp", r.spp},
                          {"seed", r.seed},
                          {"timing", r.timing},
                          {"chip", changed_fields(r.chip)}}}});
    }
    doc["axes"] = std::move(axes);
    doc["fixed"] = std::move(fixed);
    doc["zip"] = sweep.zip;
    doc["jobs"] = std::move(jobs);
    // Renamed into place: a job starting on another node never reads half a plan.
    const std::filesystem::path path = plan_path(dir), temporary = dir / ".sweep.json.tmp";
    {
        std::ofstream out(temporary, std::ios::binary);
        out << doc.dump(1) << '\n';
        if (!out.flush())
            throw Error(fmt::format("cannot write the sweep plan '{}'", temporary.string()));
    }
    std::filesystem::rename(temporary, path, ec);
    if (ec) throw Error(fmt::format("cannot write '{}': {}", path.string(), ec.message()));
}

Sweep read_plan(const std::filesystem::path& dir) {
    const std::filesystem::path path = plan_path(dir);
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec))
        throw Error(fmt::format("'{}' is not a sweep's results directory (it has no sweep.json); "
                                "give the directory tpsim sweep run or slurm wrote",
                                dir.string()));
    const std::string text = read_input_file(path, "sweep plan", uintmax_t(1) << 30);
    const auto bad = [&](const std::string& what) {
        return Error(fmt::format("{}: {}; run tpsim sweep run or slurm again to rewrite it",
                                 path.string(), what));
    };
    Json doc;
    try {
        doc = Json::parse(text);
    } catch (const Json::exception& e) {
        throw bad(fmt::format("not JSON ({})", e.what()));
    }
    if (!doc.is_object() || doc.value("format", "") != "tpsim-sweep")
        throw bad("not a tpsim sweep plan");
    if (doc.value("version", 0) != kPlanVersion)
        throw bad(fmt::format("written by plan version {}; this tpsim reads version {}",
                              doc.value("version", 0), kPlanVersion));
    Sweep sweep;
    try {
        sweep.file = doc.at("file").get<std::string>();
        for (const Json& a : doc.at("axes"))
            sweep.axes.push_back(
                {a.at("name").get<std::string>(), a.at("values").get<std::vector<Json>>()});
        for (const auto& [name, value] : doc.at("fixed").items())
            sweep.fixed.push_back({name, value});
        sweep.zip = doc.at("zip").get<std::vector<std::vector<std::string>>>();
        for (const Json& j : doc.at("jobs")) {
            Job job;
            job.id = j.at("id").get<std::string>();
            job.values = j.at("values").get<std::vector<Json>>();
            const Json& r = j.at("run");
            job.run.scene = r.at("scene").get<std::string>();
            job.run.kernel = r.at("kernel").get<std::string>();
            for (const auto& [name, value] : r.at("accel").items())
                if (!scene::is_accel_setting(name) ||
                    !scene::set_accel_setting(job.run.accel, name, accel_value(value)).empty())
                    throw bad(fmt::format("job {} has a bad accel setting {}", job.id, name));
            job.run.width = r.at("width").get<uint32_t>();
            job.run.height = r.at("height").get<uint32_t>();
            job.run.spp = r.at("spp").get<uint32_t>();
            job.run.seed = r.at("seed").get<uint32_t>();
            job.run.timing = r.at("timing").get<std::string>();
            job.run.chip = timing::parse_config(r.at("chip").get<std::string>(),
                                                fmt::format("{} job {}", path.string(), job.id));
            if (job.values.size() != sweep.axes.size()) throw bad("a job lacks axis values");
            sweep.jobs.push_back(std::move(job));
        }
    } catch (const Json::exception& e) {
        throw bad(fmt::format("malformed ({})", e.what()));
    }
    return sweep;
}

}  // namespace tpsim::sweep
