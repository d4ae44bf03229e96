#include "sim/analysis/compare.hpp"

#include <algorithm>
#include <cmath>
#include <fnmatch.h>
#include <limits>
#include <ostream>
#include <set>

#include <fmt/format.h>

namespace tpsim::analysis {
namespace {

constexpr const char* kAbsent = "(absent)";

/// Splits "region/bvh_nodes/l1/reads" into its '/'-separated segments.
std::vector<std::string> segments(std::string_view name) {
    std::vector<std::string> parts;
    size_t start = 0;
    for (size_t slash; (slash = name.find('/', start)) != std::string_view::npos; start = slash + 1)
        parts.emplace_back(name.substr(start, slash - start));
    parts.emplace_back(name.substr(start));
    return parts;
}

/// Appends `item` unless it is there already (keeps first-seen order, which is file order).
void add_unique(std::vector<std::string>& list, const std::string& item) {
    if (std::find(list.begin(), list.end(), item) == list.end()) list.push_back(item);
}

Row stat_row(const std::vector<StatsFile>& runs, const std::string& key, Better better) {
    Row row{key, "", better, {}, {}};
    for (const StatsFile& run : runs) {
        row.values.push_back(run.stat(key));
        row.intervals.push_back(run.interval(key));
        if (row.unit.empty()) row.unit = run.unit(key);
    }
    return row;
}

/// A figure computed from the statistics `inputs` of each run (absent where a part is absent
/// or divides by 0): exact when they all are, otherwise an estimate of unknown interval.
template <class Derive>
Row derived_row(const std::vector<StatsFile>& runs, std::string key, std::string unit,
                Better better, std::initializer_list<std::string> inputs, Derive derive) {
    Row row{std::move(key), std::move(unit), better, {}, {}};
    for (const StatsFile& run : runs) {
        row.values.push_back(derive(run));
        const bool exact = std::all_of(inputs.begin(), inputs.end(), [&](const std::string& in) {
            return run.interval(in) == 0;
        });
        row.intervals.push_back(exact ? 0.0 : std::numeric_limits<double>::quiet_NaN());
    }
    return row;
}

std::optional<double> quotient(std::optional<double> numerator, std::optional<double> denominator) {
    if (!numerator || !denominator || *denominator == 0) return std::nullopt;
    return *numerator / *denominator;
}

bool has_any(const Row& row) {
    return std::any_of(row.values.begin(), row.values.end(), [](auto v) { return v.has_value(); });
}

bool has_nonzero(const Row& row) {
    return std::any_of(row.values.begin(), row.values.end(), [](auto v) { return v && *v != 0; });
}

/// Keys `prefix<one segment>suffix` present in any run, in file order of the first run that
/// has each.
std::vector<std::string> keys_like(const std::vector<StatsFile>& runs, std::string_view prefix,
                                   std::string_view suffix) {
    std::vector<std::string> keys;
    for (const StatsFile& run : runs)
        for (const auto& [name, value] : run.stats) {
            if (!name.starts_with(prefix) || !name.ends_with(suffix) ||
                name.size() <= prefix.size() + suffix.size())
                continue;
            const std::string_view middle(name.data() + prefix.size(),
                                          name.size() - prefix.size() - suffix.size());
            if (middle.find('/') == std::string_view::npos) add_unique(keys, name);
        }
    return keys;
}

/// What a sampled run's figures are; empty for measured ones.
std::string estimates_note(const StatsFile& run) {
    if (!run.estimated()) return "";
    const Json& s = *run.sampling;
    std::string note = fmt::format(
        "sampled (--timing sampled): its cycle-level figures are estimates, ± the half-width of "
        "their {:g} % confidence interval, from {} units at rate {:g}",
        100 * s.value("confidence", 0.95), s.value("units", 0), s.value("rate", 0.0));
    if (s.value("too_few_units", false))
        note += fmt::format("; fewer than {} units: the intervals are likely too narrow",
                            s.value("trusted_units", 30));
    return note;
}

Section summary_section(const std::vector<StatsFile>& runs) {
    Section s{"summary", {}};
    const std::pair<const char*, Better> keys[] = {{"chip/cycles", Better::lower},
                                                   {"chip/frame_seconds", Better::lower},
                                                   {"chip/rays_per_second", Better::higher},
                                                   {"instructions/total", Better::lower},
                                                   {"chip/issue_rate", Better::higher},
                                                   {"chip/l1/hit_rate", Better::higher},
                                                   {"chip/l2/hit_rate", Better::higher},
                                                   {"dram/bytes_read", Better::lower},
                                                   {"dram/bytes_written", Better::lower},
                                                   {"chip/dram/bandwidth_gbps", Better::neutral},
                                                   {"rays/total", Better::neutral},
                                                   {"energy/total", Better::lower},
                                                   {"energy/average_watts", Better::lower},
                                                   {"energy/mrays_per_joule", Better::higher},
                                                   {"area/total", Better::lower}};
    for (const auto& [key, better] : keys)
        s.rows.push_back(stat_row(runs, key, better));
    return s;
}

Section keyed_section(const std::vector<StatsFile>& runs, std::string title,
                      std::string_view prefix, std::string_view suffix, Better better) {
    Section s{std::move(title), {}};
    for (const std::string& key : keys_like(runs, prefix, suffix))
        s.rows.push_back(stat_row(runs, key, better));
    return s;
}

/// Every statistic under `prefix` (any depth, file order) but the totals and rates the summary
/// and per-ray sections show: the energy and area estimate's parts (docs/energy.md).
Section parts_section(const std::vector<StatsFile>& runs, std::string title,
                      std::string_view prefix) {
    const std::set<std::string, std::less<>> shown_elsewhere = {
        "energy/total",   "energy/average_watts", "energy/mrays_per_joule",
        "energy/per_ray", "energy/per_pixel",     "area/total"};
    std::vector<std::string> keys;
    for (const StatsFile& run : runs)
        for (const auto& [name, value] : run.stats)
            if (name.starts_with(prefix) && !shown_elsewhere.contains(name)) add_unique(keys, name);
    Section s{std::move(title), {}};
    for (const std::string& key : keys)
        s.rows.push_back(stat_row(runs, key, Better::lower));
    return s;
}

/// Region x level traffic: the regions each run lists, then any others its keys name
/// (local_store, instruction_fetch); for each level the figures present; all-zero rows left out.
Section traffic_section(const std::vector<StatsFile>& runs) {
    std::vector<std::string> regions;
    for (const StatsFile& run : runs)
        for (const std::string& region : run.regions)
            add_unique(regions, region);
    // levels[region] in first-seen order
    std::vector<std::pair<std::string, std::vector<std::string>>> levels;
    for (const std::string& region : regions)
        levels.push_back({region, {}});
    for (const StatsFile& run : runs)
        for (const auto& [name, value] : run.stats) {
            const std::vector<std::string> parts = segments(name);
            if (parts.size() != 4 || parts[0] != "region") continue;
            auto found = std::find_if(levels.begin(), levels.end(),
                                      [&](const auto& l) { return l.first == parts[1]; });
            if (found == levels.end()) found = levels.insert(levels.end(), {parts[1], {}});
            add_unique(found->second, parts[2]);
        }
    Section s{"traffic by region and level", {}};
    const std::pair<const char*, Better> leaves[] = {{"payload_bytes", Better::lower},
                                                     {"moved_bytes", Better::lower},
                                                     {"reads", Better::neutral},
                                                     {"misses", Better::lower}};
    for (const auto& [region, region_levels] : levels)
        for (const std::string& level : region_levels) {
            const std::string prefix = "region/" + region + "/" + level + "/";
            for (const auto& [leaf, better] : leaves) {
                Row row = stat_row(runs, prefix + leaf, better);
                if (has_nonzero(row)) s.rows.push_back(std::move(row));
            }
            Row hit_rate = derived_row(
                runs, prefix + "hit_rate", "ratio", Better::higher,
                {prefix + "hits", prefix + "reads"}, [&](const StatsFile& run) {
                    return quotient(run.stat(prefix + "hits"), run.stat(prefix + "reads"));
                });
            if (has_any(hit_rate)) s.rows.push_back(std::move(hit_rate));
        }
    return s;
}

Section per_ray_section(const std::vector<StatsFile>& runs) {
    Section s{"per ray", {}};
    s.rows.push_back(derived_row(runs, "per_ray/instructions", "instructions", Better::lower,
                                 {"instructions/total", "rays/total"}, [](const StatsFile& run) {
                                     return quotient(run.stat("instructions/total"),
                                                     run.stat("rays/total"));
                                 }));
    s.rows.push_back(derived_row(runs, "per_ray/dram_bytes", "B", Better::lower,
                                 {"dram/bytes_read", "dram/bytes_written", "rays/total"},
                                 [](const StatsFile& run) -> std::optional<double> {
                                     const auto read = run.stat("dram/bytes_read");
                                     const auto written = run.stat("dram/bytes_written");
                                     if (!read || !written) return std::nullopt;
                                     return quotient(*read + *written, run.stat("rays/total"));
                                 }));
    s.rows.push_back(stat_row(runs, "energy/per_ray", Better::lower));
    s.rows.push_back(stat_row(runs, "traversal/nodes_per_ray", Better::lower));
    s.rows.push_back(stat_row(runs, "traversal/triangles_per_ray", Better::lower));
    return s;
}

std::vector<SetupDifference> setup_differences(const std::vector<StatsFile>& runs) {
    std::vector<SetupDifference> differences;
    const auto add_if_different = [&](std::string field, std::vector<std::string> values) {
        if (std::adjacent_find(values.begin(), values.end(), std::not_equal_to<>()) != values.end())
            differences.push_back({std::move(field), std::move(values)});
    };
    const auto run_field = [](const StatsFile& run, std::string_view key) {
        const std::string text = run.run_text(key);
        return text.empty() ? std::string(kAbsent) : text;
    };
    for (const char* field :
         {"scene", "kernel", "engine", "accel", "grid_resolution", "grid_density",
          "kdtree_max_depth", "kdtree_max_references", "octree_max_depth", "bvh_builder",
          "max_leaf", "bvh_order", "bvh_align_pairs", "bvh_boxes"}) {
        std::vector<std::string> values;
        for (const StatsFile& run : runs)
            values.push_back(run_field(run, field));
        add_if_different(field, values);
    }
    std::vector<std::string> sizes;
    for (const StatsFile& run : runs)
        sizes.push_back(run_field(run, "width") + "x" + run_field(run, "height"));
    add_if_different("image size", sizes);
    for (const char* field : {"samples_per_pixel", "threads"}) {
        std::vector<std::string> values;
        for (const StatsFile& run : runs)
            values.push_back(run_field(run, field));
        add_if_different(field, values);
    }
    // Kernel parameters (run.params, from kernels that declare TRAX_PARAMs).
    const auto params_of = [](const StatsFile& run) {
        const auto found = run.run.find("params");
        return found != run.run.end() && found->is_object() ? *found : Json::object();
    };
    std::vector<std::string> params;
    for (const StatsFile& run : runs) {
        const Json own = params_of(run);
        for (const auto& [name, value] : own.items())
            add_unique(params, name);
    }
    for (const std::string& name : params) {
        std::vector<std::string> values;
        for (const StatsFile& run : runs) {
            const Json own = params_of(run);
            values.push_back(own.contains(name) ? own[name].dump() : std::string(kAbsent));
        }
        add_if_different("param " + name, values);
    }
    std::vector<std::string> keys;
    for (const StatsFile& run : runs)
        for (const auto& [key, value] : run.config)
            add_unique(keys, key);
    for (const std::string& key : keys) {
        std::vector<std::string> values;
        for (const StatsFile& run : runs) {
            const auto found = std::find_if(run.config.begin(), run.config.end(),
                                            [&](const auto& entry) { return entry.first == key; });
            values.push_back(found == run.config.end()   ? std::string(kAbsent)
                             : found->second.is_string() ? found->second.get<std::string>()
                                                         : found->second.dump());
        }
        add_if_different("config " + key, values);
    }
    return differences;
}

std::optional<ImageDifference> image_difference(const StatsFile& first, const StatsFile& other) {
    const auto a = first.run_file("image");
    const auto b = other.run_file("image");
    if (!a && !b) return std::nullopt;
    if (!a || !b) {
        ImageDifference d;
        d.note = fmt::format("{} names no image", (!a ? first : other).path.string());
        return d;
    }
    return compare_images(*a, *b);
}

// ---- printing ----

std::string format_ratio(std::optional<double> ratio) {
    return ratio ? fmt::format("{:.3f}x", *ratio) : "-";
}

std::string format_cell(std::optional<double> value) {
    return value ? format_number(*value) : "-";
}

/// A value with its interval when it is an estimate: "1592403 ±1130", "0.9415 ±?" (unknown).
std::string estimate_cell(const Row& row, size_t run) {
    const std::string value = format_cell(row.values[run]);
    if (!row.values[run] || !row.estimated(run)) return value;
    const double half = row.interval(run);
    return value + (std::isnan(half) ? " ±?" : " ±" + format_number(half));
}

/// The ratio, marked "~" when the estimates' intervals cannot tell the two values apart.
std::string ratio_text(const Row& row, size_t run) {
    return format_ratio(row.ratio(run)) + (row.within_intervals(run) ? "~" : "");
}

bool any_estimates(const Comparison& c) {
    return std::any_of(c.estimates.begin(), c.estimates.end(),
                       [](const std::string& note) { return !note.empty(); });
}

constexpr const char* kWithinNote =
    "~ after a ratio: the two values differ by less than their intervals together, so the "
    "estimates cannot tell them apart";

std::string image_line(const ImageDifference& d) {
    if (!d.compared()) return d.note;
    if (d.differing_pixels == 0) return fmt::format("identical ({} pixels)", d.pixels);
    return fmt::format("RMSE {:.6f}, PSNR {:.2f} dB, {} of {} pixels differ ({:.2f} %)", d.rmse,
                       d.psnr, d.differing_pixels, d.pixels, 100 * d.differing_share());
}

/// ANSI colour of a notable ratio: green better, red worse, yellow when neither is better.
const char* colour_of(const Row& row, size_t run) {
    if (!row.differs_notably(run)) return nullptr;
    if (row.better == Better::neutral) return "\033[33m";
    const bool up = *row.ratio(run) > 1;
    return up == (row.better == Better::higher) ? "\033[32m" : "\033[31m";
}

void write_text(const Comparison& c, std::ostream& out, bool colour) {
    const size_t n = c.runs.size();
    for (size_t i = 0; i < n; ++i)
        out << fmt::format("{:<10}{}  {}\n", i == 0 ? "runs" : "", run_letter(i), c.runs[i]);
    for (size_t i = 0, shown = 0; i < n; ++i)
        if (!c.estimates[i].empty())
            out << fmt::format("{:<10}{}  {}\n", shown++ == 0 ? "estimates" : "", run_letter(i),
                               c.estimates[i]);
    // Estimates need room for their intervals and the "~" of their ratios.
    const size_t cell = any_estimates(c) ? 24 : 14, ratio_width = any_estimates(c) ? 9 : 8;
    if (c.differences.empty())
        out << fmt::format("{:<10}none in run fields or configuration\n", "differs");
    for (size_t i = 0; i < c.differences.size(); ++i) {
        const SetupDifference& d = c.differences[i];
        std::string values;
        for (size_t r = 0; r < n; ++r)
            values += (r ? " | " : "") + d.values[r];
        out << fmt::format("{:<10}{:<32} {}\n", i == 0 ? "differs" : "", d.field, values);
    }
    for (size_t i = 0; i < c.images.size(); ++i)
        if (c.images[i])
            out << fmt::format("{:<10}{} vs A: {}\n", "image", run_letter(i + 1),
                               image_line(*c.images[i]));
    if (has_any(c.host)) {
        std::string values;
        for (size_t r = 0; r < n; ++r)
            values += fmt::format("  {} {}", run_letter(r), format_cell(c.host.values[r]));
        out << fmt::format("{:<10}host wall time, not a result: {} ({}){}\n", "host", c.host.key,
                           c.host.unit, values);
    }
    for (const Section& section : c.sections) {
        if (section.rows.empty()) continue;
        size_t key_width = section.title.size();
        for (const Row& row : section.rows)
            key_width = std::max(key_width, row.key.size());
        out << fmt::format("\n{:<{}}  {:<12}", section.title, key_width, "unit");
        for (size_t r = 0; r < n; ++r) {
            out << fmt::format(" {:>{}}", run_letter(r), cell);
            if (r) out << fmt::format(" {:>{}}", run_letter(r) + "/A", ratio_width);
        }
        out << "\n";
        for (const Row& stored : section.rows) {
            const Row row = for_display(stored);
            out << fmt::format("{:<{}}  {:<12}", row.key, key_width, row.unit);
            for (size_t r = 0; r < n; ++r) {
                out << fmt::format(" {:>{}}", estimate_cell(row, r), cell);
                if (r == 0) continue;
                const std::string ratio = fmt::format(" {:>{}}", ratio_text(row, r), ratio_width);
                const char* ansi = colour ? colour_of(row, r) : nullptr;
                out << (ansi ? ansi + ratio + "\033[0m" : ratio);
            }
            out << "\n";
        }
    }
    if (any_estimates(c)) out << "\n" << kWithinNote << "\n";
}

void write_markdown(const Comparison& c, std::ostream& out) {
    const size_t n = c.runs.size();
    out << "| run | file |\n|---|---|\n";
    for (size_t i = 0; i < n; ++i)
        out << fmt::format("| {} | `{}` |\n", run_letter(i), c.runs[i]);
    out << "\n";
    for (size_t i = 0; i < n; ++i)
        if (!c.estimates[i].empty())
            out << fmt::format("Run {} is {}.\n\n", run_letter(i), c.estimates[i]);
    if (!c.differences.empty()) {
        out << "| differs |";
        for (size_t r = 0; r < n; ++r)
            out << " " << run_letter(r) << " |";
        out << "\n|---|";
        for (size_t r = 0; r < n; ++r)
            out << "---|";
        out << "\n";
        for (const SetupDifference& d : c.differences) {
            out << "| " << d.field << " |";
            for (const std::string& v : d.values)
                out << " " << v << " |";
            out << "\n";
        }
        out << "\n";
    }
    for (size_t i = 0; i < c.images.size(); ++i)
        if (c.images[i])
            out << fmt::format("Image {} vs A: {}\n\n", run_letter(i + 1),
                               image_line(*c.images[i]));
    if (has_any(c.host)) {
        out << fmt::format("Host wall time (not a result), `{}`:", c.host.key);
        for (size_t r = 0; r < n; ++r)
            out << fmt::format("{} {} {} {}", r ? "," : "", run_letter(r),
                               format_cell(c.host.values[r]), c.host.unit);
        out << "\n\n";
    }
    for (const Section& section : c.sections) {
        if (section.rows.empty()) continue;
        out << "| " << section.title << " | unit |";
        std::string rule = "|---|---|";
        for (size_t r = 0; r < n; ++r) {
            out << " " << run_letter(r) << " |";
            rule += "---:|";
            if (r) {
                out << " " << run_letter(r) << "/A |";
                rule += "---:|";
            }
        }
        out << "\n" << rule << "\n";
        for (const Row& stored : section.rows) {
            const Row row = for_display(stored);
            out << fmt::format("| `{}` | {} |", row.key, row.unit);
            for (size_t r = 0; r < n; ++r) {
                out << " " << estimate_cell(row, r) << " |";
                if (r) out << " " << ratio_text(row, r) << " |";
            }
            out << "\n";
        }
        out << "\n";
    }
    if (any_estimates(c)) out << kWithinNote << ".\n";
}

/// Exact figures for machines: integers in full, reals in the shortest round-trip form.
std::string csv_number(std::optional<double> value) {
    if (!value || !std::isfinite(*value)) return "";
    return fmt::format("{}", *value);
}

void write_csv(const Comparison& c, std::ostream& out) {
    const size_t n = c.runs.size();
    // A sampled run's column is followed by its intervals' half-widths (empty: unknown).
    const auto sampled = [&](size_t r) { return !c.estimates[r].empty(); };
    out << "section,key,unit";
    for (size_t r = 0; r < n; ++r) {
        out << "," << csv_field(c.runs[r]);
        if (sampled(r)) out << "," << csv_field(c.runs[r] + " ±");
        if (r) out << "," << csv_field(c.runs[r] + " / " + c.runs[0]);
    }
    out << "\n";
    for (const SetupDifference& d : c.differences) {
        out << "setup," << csv_field(d.field) << ",";
        for (size_t r = 0; r < n; ++r)
            out << "," << csv_field(d.values[r]) << (sampled(r) ? "," : "") << (r ? "," : "");
        out << "\n";
    }
    for (const Section& section : c.sections)
        for (const Row& row : section.rows) {
            out << csv_field(section.title) << "," << csv_field(row.key) << ","
                << csv_field(row.unit);
            for (size_t r = 0; r < n; ++r) {
                out << "," << csv_number(row.values[r]);
                if (sampled(r)) out << "," << csv_number(row.interval(r));
                if (r) out << "," << csv_number(row.ratio(r));
            }
            out << "\n";
        }
    for (size_t i = 0; i < c.images.size(); ++i) {
        if (!c.images[i]) continue;
        const ImageDifference& d = *c.images[i];
        const size_t r = i + 1;
        const auto image_row = [&](const char* key, const std::string& value) {
            out << "image," << key << ",";
            for (size_t col = 0; col < n; ++col)
                out << "," << (col == r ? value : "") << (sampled(col) ? "," : "")
                    << (col ? "," : "");
            out << "\n";
        };
        if (!d.compared()) {
            image_row("note", csv_field(d.note));
            continue;
        }
        image_row("rmse", csv_number(d.rmse));
        image_row("psnr_db", csv_number(d.psnr));
        image_row("differing_pixels", csv_number(double(d.differing_pixels)));
        image_row("pixels", csv_number(double(d.pixels)));
    }
}

Json json_number(std::optional<double> value) {
    return value && std::isfinite(*value) ? Json(*value) : Json();
}

void write_json(const Comparison& c, std::ostream& out) {
    Json doc;
    doc["format"] = "tpsim-compare";
    doc["runs"] = c.runs;
    doc["estimates"] = c.estimates;
    doc["differences"] = Json::array();
    for (const SetupDifference& d : c.differences)
        doc["differences"].push_back({{"field", d.field}, {"values", d.values}});
    doc["images"] = Json::array();
    for (size_t i = 0; i < c.images.size(); ++i) {
        if (!c.images[i]) continue;
        const ImageDifference& d = *c.images[i];
        Json image = {{"run", c.runs[i + 1]}, {"against", c.runs[0]}};
        if (!d.compared()) {
            image["note"] = d.note;
        } else {
            image["rmse"] = d.rmse;
            image["psnr_db"] = json_number(d.psnr);  // null when identical (infinite)
            image["differing_pixels"] = d.differing_pixels;
            image["pixels"] = d.pixels;
        }
        doc["images"].push_back(image);
    }
    Json host = {{"key", c.host.key}, {"unit", c.host.unit}, {"values", Json::array()}};
    for (const auto& v : c.host.values)
        host["values"].push_back(json_number(v));
    doc["host"] = host;
    doc["sections"] = Json::array();
    for (const Section& section : c.sections) {
        Json rows = Json::array();
        for (const Row& row : section.rows) {
            Json values = Json::array(), ratios = Json::array(), intervals = Json::array();
            for (size_t r = 0; r < row.values.size(); ++r) {
                values.push_back(json_number(row.values[r]));
                ratios.push_back(json_number(row.ratio(r)));
                intervals.push_back(json_number(row.interval(r)));  // null: unknown
            }
            Json entry = {
                {"key", row.key}, {"unit", row.unit}, {"values", values}, {"ratios", ratios}};
            if (any_estimates(c)) entry["intervals"] = intervals;
            rows.push_back(entry);
        }
        doc["sections"].push_back({{"title", section.title}, {"rows", rows}});
    }
    out << doc.dump(2) << "\n";
}

}  // namespace

std::optional<double> Row::ratio(size_t run) const {
    const auto& first = values.at(0);
    const auto& value = values.at(run);
    if (!first || !value) return std::nullopt;
    if (*first == 0) return *value == 0 ? std::optional<double>(1.0) : std::nullopt;
    return *value / *first;
}

bool Row::within_intervals(size_t run) const {
    const double half = interval(0) + interval(run);
    if (!estimated(0) && !estimated(run)) return false;
    const auto& first = values.at(0);
    const auto& value = values.at(run);
    return first && value && std::isfinite(half) && std::abs(*value - *first) <= half;
}

bool Row::differs_notably(size_t run) const {
    const auto r = ratio(run);
    return r && (*r < 0.95 || *r > 1.05);
}

std::string csv_field(const std::string& text) {
    if (text.find_first_of(",\"\n\r") == std::string::npos) return text;
    std::string quoted = "\"";
    for (char ch : text)
        quoted += ch == '"' ? std::string("\"\"") : std::string(1, ch);
    return quoted + "\"";
}

Row for_display(const Row& row) {
    if (row.unit != "s" && row.unit != "J") return row;
    double largest = 0;
    for (const auto& v : row.values)
        if (v && std::isfinite(*v)) largest = std::max(largest, std::abs(*v));
    if (largest == 0 || largest >= 1) return row;
    const struct {
        double scale;
        const char* prefix;
    } prefixes[] = {{1e3, "m"}, {1e6, "µ"}, {1e9, "n"}};
    const auto& chosen = largest >= 1e-3   ? prefixes[0]
                         : largest >= 1e-6 ? prefixes[1]
                                           : prefixes[2];
    Row shown = row;
    shown.unit = chosen.prefix + row.unit;
    for (auto& v : shown.values)
        if (v) *v *= chosen.scale;
    for (double& half : shown.intervals)
        half *= chosen.scale;
    return shown;
}

std::string run_letter(size_t run) {
    return run < 26 ? std::string(1, char('A' + run)) : fmt::format("R{}", run + 1);
}

std::string format_number(double value) {
    if (std::isnan(value)) return "n/a";
    if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
    if (value == std::floor(value) && std::abs(value) < 1e15) return fmt::format("{:.0f}", value);
    if (std::abs(value) >= 1000) return fmt::format("{:.0f}", value);
    return fmt::format("{:.4g}", value);
}

Comparison compare(const std::vector<StatsFile>& runs, const std::vector<std::string>& keys) {
    Comparison c;
    for (const StatsFile& run : runs)
        c.runs.push_back(run.path.string());
    c.differences = setup_differences(runs);
    c.sections.push_back(summary_section(runs));
    c.sections.push_back(keyed_section(runs, "stall causes", "chip/stalls/", "", Better::lower));
    c.sections.push_back(
        keyed_section(runs, "FU utilisation", "chip/fu/", "/utilisation", Better::neutral));
    c.sections.push_back(traffic_section(runs));
    c.sections.push_back(per_ray_section(runs));
    c.sections.push_back(parts_section(runs, "energy by part", "energy/"));
    c.sections.push_back(parts_section(runs, "area by part", "area/"));
    const auto unwanted = [&](const Row& row) {
        return !has_any(row) ||
               (!keys.empty() && std::none_of(keys.begin(), keys.end(), [&](const std::string& k) {
                   return fnmatch(k.c_str(), row.key.c_str(), 0) == 0;
               }));
    };
    for (Section& section : c.sections)
        std::erase_if(section.rows, unwanted);
    std::erase_if(c.sections, [](const Section& section) { return section.rows.empty(); });
    for (size_t i = 1; i < runs.size(); ++i)
        c.images.push_back(image_difference(runs[0], runs[i]));
    c.host = stat_row(runs, "host/run_seconds", Better::neutral);
    for (const StatsFile& run : runs)
        c.estimates.push_back(estimates_note(run));
    return c;
}

void write_comparison(const Comparison& comparison, Format format, std::ostream& out, bool colour) {
    switch (format) {
    case Format::text:
        write_text(comparison, out, colour);
        break;
    case Format::markdown:
        write_markdown(comparison, out);
        break;
    case Format::csv:
        write_csv(comparison, out);
        break;
    case Format::json:
        write_json(comparison, out);
        break;
    }
}

}  // namespace tpsim::analysis
