#include "sim/analysis/html_report.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <optional>
#include <set>
#include <sstream>
#include <utility>

#include <fmt/format.h>

#include "sim/analysis/page_assets.hpp"
#include "sim/core/error.hpp"
#include "sim/render/image_codec.hpp"
#include "sim/stats/thousands.hpp"

namespace tpsim::analysis {
namespace {

/// Where Debian's libjs-chart.js puts the UMD build: chart.umd.js from Chart.js 4 on,
/// chart.min.js before (where chart.js is UMD too, but 2.7 times larger).
constexpr const char* kChartJsCandidates[] = {"/usr/share/javascript/chart.js/chart.umd.js",
                                              "/usr/share/javascript/chart.js/chart.min.js"};

std::string escape(std::string_view text) {
    std::string out;
    for (char ch : text) {
        switch (ch) {
        case '&':
            out += "&amp;";
            break;
        case '<':
            out += "&lt;";
            break;
        case '>':
            out += "&gt;";
            break;
        case '"':
            out += "&quot;";
            break;
        default:
            out += ch;
        }
    }
    return out;
}

/// A number shortened for a summary card: 2.23 M, 121 k, 0.6648.
std::string short_number(double value) {
    const double magnitude = std::abs(value);
    if (magnitude >= 1e9) return fmt::format("{:.3g} G", value / 1e9);
    if (magnitude >= 1e6) return fmt::format("{:.3g} M", value / 1e6);
    if (magnitude >= 1e4) return fmt::format("{:.3g} k", value / 1e3);
    return format_number(value);
}

/// A number for a person reading a table: whole numbers with thousands separators (1,472,000).
std::string readable(double value) {
    const std::string text = format_number(value);
    if (text.find_first_not_of("-0123456789") != std::string::npos) return text;
    return stats::with_thousands(text);
}

/// One chart for the JSON blob; report_page.js draws it with Chart.js.
struct Chart {
    /// "bar" (labels + values), "line" ({x, y} points over cycles, or values over labels: a
    /// sweep's axis) or "scatter" ({x, y, label} points, optionally joined: a dataset's "line")
    std::string type = "bar";
    std::string title = "";
    std::string unit = "";  ///< the value axis title
    bool horizontal = false;
    bool percent = false;
    bool log = false;  ///< a logarithmic value axis
    /// The value axis starts at 0 (bars of counts); false fits it to the data, so that the few
    /// per cent by which compared designs differ can be seen.
    bool zero = true;
    bool tall = false;
    std::string x_title = "";  ///< scatter: the x axis title
    bool x_log = false;        ///< scatter: a logarithmic x axis
    /// The value axis's [min, max] when set (error bars beyond it are cut); otherwise Chart.js
    /// fits the data and its error bars.
    std::optional<std::pair<double, double>> range = std::nullopt;
    Json labels = Json::array();
    Json datasets = Json::array();

    void add(std::string label, Json data, bool line = false) {
        datasets.push_back(
            {{"label", std::move(label)}, {"data", std::move(data)}, {"line", line}});
    }
    bool has_data() const {
        for (const Json& d : datasets)
            for (const Json& v : d["data"]) {
                const Json& y = v.is_object() ? v["y"] : v;
                if (y.is_number() && y != 0) return true;
            }
        return false;
    }
    Json to_json() const {
        Json spec = {{"type", type},        {"title", title},
                     {"unit", unit},        {"horizontal", horizontal},
                     {"percent", percent},  {"log", log},
                     {"zero", zero},        {"xTitle", x_title},
                     {"xLog", x_log},       {"labels", labels},
                     {"datasets", datasets}};
        if (range) spec["range"] = {range->first, range->second};
        return spec;
    }
};

/// The page being written: HTML body text plus the charts it places.
class Page {
public:
    std::ostringstream body;

    /// Places a chart (nothing when it has no nonzero value: an empty chart says nothing).
    void chart(const Chart& chart) {
        if (!chart.has_data()) return;
        body << fmt::format("<div class=\"chart{}\"><canvas data-chart=\"{}\"></canvas></div>\n",
                            chart.tall ? " tall" : "", charts_.size());
        charts_.push_back(chart.to_json());
    }

    std::string finish(const std::string& title, const std::string& chart_js) const {
        // No '<' in the blob, so no text in it can end (or comment out) its <script> element;
        // in JSON it can only stand inside a string, where \u003c means the same.
        std::string blob;
        for (char ch : Json{{"charts", charts_}}.dump())
            blob += ch == '<' ? std::string("\\u003c") : std::string(1, ch);
        std::ostringstream page;
        page << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
             << "<title>" << escape(title) << "</title>\n<style>\n"
             << kReportPageCss << "</style>\n"
             << "<script>window.tpsimErrors = []; window.addEventListener('error', function (e) "
                "{ window.tpsimErrors.push(String(e.message)); });</script>\n"
             << "</head>\n<body>\n<main>\n"
             << body.str()
             << "<footer><p id=\"chart-status\" data-status=\"pending\">charts not drawn (is "
                "JavaScript off?)</p></footer>\n</main>\n"
             << "<script id=\"tpsim-data\" type=\"application/json\">" << blob << "</script>\n"
             << "<script>\n"
             << chart_js << "\n</script>\n"
             << "<script>\n"
             << kReportPageJs << "</script>\n</body>\n</html>\n";
        return page.str();
    }

private:
    Json charts_ = Json::array();
};

std::string image_tag(const std::filesystem::path& path, const std::string& caption) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec))
        return fmt::format("<p class=\"note\">{}: {} does not exist.</p>\n", escape(caption),
                           escape(path.string()));
    std::string png;
    try {
        png = png_bytes(path);
    } catch (const Error& e) {  // the rest of the page is still worth having
        return fmt::format("<p class=\"note\">{}: {}.</p>\n", escape(caption), escape(e.what()));
    }
    return fmt::format("<figure><img alt=\"{0}\" src=\"data:image/png;base64,{1}\">"
                       "<figcaption>{0} ({2})</figcaption></figure>\n",
                       escape(caption), render::image_codec().base64(png),
                       escape(path.filename().string()));
}

/// "tracer · timing · 32x32 pixels · 1 spp · 8 threads · BVH sweep, max_leaf 8", the parts
/// the run has.
std::string run_line(const StatsFile& run) {
    const auto field = [&](const char* key) { return run.run_text(key); };
    std::vector<std::string> parts;
    for (const char* key : {"kernel_name", "engine"})
        if (!field(key).empty()) parts.push_back(field(key));
    if (!field("width").empty())
        parts.push_back(fmt::format("{}x{} pixels", field("width"), field("height")));
    if (!field("samples_per_pixel").empty()) parts.push_back(field("samples_per_pixel") + " spp");
    if (!field("threads").empty()) parts.push_back(field("threads") + " threads");
    // The structure the kernel traversed (files without `accel` come from BVH-only tpsim).
    const std::string accel = field("accel");
    if (accel == "grid")
        parts.push_back(
            field("grid_resolution") == "0"
                ? fmt::format("uniform grid, {} cells per triangle", field("grid_density"))
                : fmt::format("uniform grid, {} cells on the longest axis",
                              field("grid_resolution")));
    else if (accel == "kdtree")
        parts.push_back(fmt::format("kd-tree, depth limit {}", field("kdtree_max_depth") == "0"
                                                                   ? std::string("8 + 1.3 log2 N")
                                                                   : field("kdtree_max_depth")));
    else if (accel == "bsp")
        parts.push_back(fmt::format("BSP tree (13 plane orientations), depth limit {}",
                                    field("kdtree_max_depth") == "0" ? std::string("8 + 1.3 log2 N")
                                                                     : field("kdtree_max_depth")));
    else if (accel == "octree")
        parts.push_back(fmt::format("octree, depth limit {}", field("octree_max_depth") == "0"
                                                                  ? std::string("the default")
                                                                  : field("octree_max_depth")));
    else if (accel == "none")
        parts.push_back("no acceleration structure");
    else if (accel == "bvh4" || accel == "bvh8")
        parts.push_back(fmt::format("{}-wide BVH from {}, max_leaf {}, nodes {}, {} boxes",
                                    accel.substr(3), field("bvh_builder"), field("max_leaf"),
                                    field("bvh_order"), field("bvh_boxes")));
    else if (!field("bvh_builder").empty())
        parts.push_back(fmt::format(
            "BVH {}, max_leaf {}{}{}", field("bvh_builder"), field("max_leaf"),
            field("bvh_order").empty() ? "" : fmt::format(", nodes {}", field("bvh_order")),
            field("bvh_align_pairs") == "true" ? ", pairs line-aligned" : ""));
    std::string line;
    for (const std::string& part : parts)
        line += (line.empty() ? "" : " &middot; ") + escape(part);
    return line;
}

std::string share_cell(double share) {
    return fmt::format(
        "<td class=\"num\"><span class=\"track\"><span class=\"bar\" "
        "style=\"width:{:.1f}%\"></span></span><span class=\"share\">{:.1f} %</span></td>",
        100 * std::clamp(share, 0.0, 1.0), 100 * share);
}

void cards(Page& page, const StatsFile& run) {
    struct Card {
        const char* key;
        const char* label;
        double scale;
        const char* suffix;
    };
    const Card list[] = {{"chip/cycles", "cycles", 1, ""},
                         {"chip/frame_seconds", "frame time", 1e3, " ms"},
                         {"chip/rays_per_second", "rays per second", 1, ""},
                         {"instructions/total", "instructions", 1, ""},
                         {"chip/issue_rate", "instructions per TP-cycle", 1, ""},
                         {"chip/l1/hit_rate", "L1 hit rate", 100, " %"},
                         {"chip/l2/hit_rate", "L2 hit rate", 100, " %"},
                         {"chip/dram/bandwidth_gbps", "DRAM bandwidth", 1, " GB/s"},
                         {"rays/total", "rays", 1, ""},
                         {"traversal/nodes_per_ray", "nodes per ray", 1, ""},
                         {"traversal/triangles_per_ray", "triangles per ray", 1, ""},
                         {"energy/total", "energy per frame", 1e3, " mJ"},
                         {"energy/average_watts", "average power", 1, " W"},
                         {"energy/mrays_per_joule", "M rays per joule", 1, ""},
                         {"area/total", "chip area", 1, " mm&sup2;"}};
    page.body << "<section class=\"cards\">\n";
    for (const Card& card : list)
        if (const auto value = run.stat(card.key)) {
            // An estimate is marked and carries its interval, relative to it; a sampled run's
            // exact figures (instructions, rays) are not.
            const double half = run.interval(card.key);
            std::string interval;
            if (std::isnan(half))
                interval = " <span class=\"interval\">&plusmn;&nbsp;?</span>";
            else if (half != 0 && *value != 0)
                interval =
                    fmt::format(" <span class=\"interval\">&plusmn;&nbsp;{:.2g}&nbsp;%</span>",
                                100 * half / std::abs(*value));
            page.body << fmt::format("<div class=\"card\"><div class=\"value\">{}{}{}</div>"
                                     "<div class=\"label\">{}</div></div>\n",
                                     half != 0 ? "~" : "", short_number(*value * card.scale),
                                     card.suffix + interval, card.label);
        }
    page.body << "</section>\n";
}

/// What a sampled run's figures are: estimates, how they were made, and the key ones with
/// their intervals.
void sampling(Page& page, const StatsFile& run) {
    if (!run.sampling) return;
    const Json& s = *run.sampling;
    const auto number = [&](const char* key) { return s.value(key, 0.0); };
    if (!run.estimated()) {
        page.body << "<p class=\"note\">Sampled simulation: the run ended within its first "
                     "unit, so every figure was measured cycle by cycle.</p>\n";
        return;
    }
    page.body << fmt::format(
        "<h2>Estimates (sampled simulation)</h2>\n<p class=\"note\"><b>The cycle-level figures "
        "of this report are estimates</b> with {:.0f} % confidence intervals: {} units of {} "
        "cycles (after {} cycles of warm-up each) at a rate of {}, seed {}; the rest of the run "
        "executed under functional warming (docs/error-vs-time.md).</p>\n",
        100 * number("confidence"), readable(number("units")), readable(number("unit_cycles")),
        readable(number("warmup_cycles")), number("rate"), readable(number("seed")));
    if (s.value("too_few_units", false))
        page.body << fmt::format(
            "<p class=\"note worse\">Too few units for these intervals to be trusted: with "
            "fewer than {}, the intervals come out too narrow (docs/error-vs-time.md). Raise "
            "--sample-rate.</p>\n",
            readable(number("trusted_units")));
    page.body << "<table><tr><th>statistic</th><th class=\"num\">estimate</th>"
                 "<th class=\"num\">&plusmn; 95 %</th><th class=\"num\">relative</th></tr>\n";
    for (const char* key :
         {"chip/cycles", "chip/issue_rate", "chip/l1/hit_rate", "chip/l2/hit_rate",
          "dram/bytes_read", "dram/bytes_written", "chip/stalls/operand", "chip/stalls/fu_busy",
          "chip/stalls/fetch_conflict", "chip/stalls/memory_port", "chip/stalls/branch"})
        if (const auto value = run.stat(key)) {
            const double half = run.interval(key);
            page.body << fmt::format(
                "<tr><td>{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td>"
                "<td class=\"num\">{}</td></tr>\n",
                key, readable(*value),
                std::isnan(half) ? "? (too rare: fewer than 5 units saw one)" : readable(half),
                *value != 0 && !std::isnan(half)
                    ? fmt::format("{:.2f} %", 100 * half / std::abs(*value))
                    : "");
        }
    page.body << "</table>\n";
}

/// Region names and the levels each has, from "region/<r>/<level>/<leaf>" keys (table order
/// first, then any other region the keys name).
std::vector<std::pair<std::string, std::vector<std::string>>> region_levels(const StatsFile& run) {
    std::vector<std::pair<std::string, std::vector<std::string>>> regions;
    for (const std::string& r : run.regions)
        regions.push_back({r, {}});
    for (const auto& [name, value] : run.stats) {
        if (!name.starts_with("region/")) continue;
        const size_t a = name.find('/', 7), b = name.find('/', a + 1);
        if (a == std::string::npos || b == std::string::npos ||
            name.find('/', b + 1) != std::string::npos)
            continue;
        const std::string region = name.substr(7, a - 7), level = name.substr(a + 1, b - a - 1);
        auto found = std::find_if(regions.begin(), regions.end(),
                                  [&](const auto& r) { return r.first == region; });
        if (found == regions.end()) found = regions.insert(regions.end(), {region, {}});
        if (std::find(found->second.begin(), found->second.end(), level) == found->second.end())
            found->second.push_back(level);
    }
    return regions;
}

void cycles_charts(Page& page, const StatsFile& run) {
    Chart stalls{.title = "Where TP-cycles go (share of active TP-cycles)",
                 .horizontal = true,
                 .percent = true};
    const double active = run.stat("chip/active_tp_cycles").value_or(0);
    Json shares = Json::array();
    if (active > 0) {
        stalls.labels.push_back("issued");
        shares.push_back(100 * run.stat("chip/instructions").value_or(0) / active);
        for (const auto& [name, value] : run.stats) {
            const std::string_view rest =
                std::string_view(name).substr(name.starts_with("chip/stalls/") ? 12 : name.size());
            if (rest.empty() || rest.find('/') != std::string_view::npos) continue;
            stalls.labels.push_back(std::string(rest));
            shares.push_back(100 * value / active);
        }
    }
    stalls.add("TP-cycles", shares);
    Chart fu{.title = "Functional-unit utilisation", .horizontal = true, .percent = true};
    Json utilisation = Json::array();
    for (const auto& [name, value] : run.stats)
        if (name.starts_with("chip/fu/") && name.ends_with("/utilisation")) {
            fu.labels.push_back(name.substr(8, name.size() - 8 - 12));
            utilisation.push_back(100 * value);
        }
    fu.add("busy", utilisation);
    if (!stalls.has_data() && !fu.has_data()) return;
    page.body << "<h2>Where the cycles go</h2>\n<div class=\"charts\">\n";
    page.chart(stalls);
    page.chart(fu);
    page.body << "</div>\n";
}

/// The energy and area estimate (docs/energy.md): energy by part as a chart, area by part as a
/// chart and a table with each part's share.
void energy_and_area(Page& page, const StatsFile& run) {
    const auto total = run.stat("energy/total");
    const auto area_total = run.stat("area/total");
    if (!total || !area_total) return;
    const std::set<std::string, std::less<>> totals = {
        "energy/total",   "energy/average_watts", "energy/mrays_per_joule",
        "energy/per_ray", "energy/per_pixel",     "area/total"};
    Chart energy{.title = "Energy by part (share of the frame's energy)",
                 .horizontal = true,
                 .percent = true,
                 .tall = true};
    Chart area{.title = "Area by part (share of the chip)", .horizontal = true, .percent = true};
    Json energy_shares = Json::array(), area_shares = Json::array();
    std::vector<std::pair<std::string, double>> areas;
    for (const auto& [name, value] : run.stats) {
        if (totals.contains(name)) continue;
        if (name.starts_with("energy/") && *total > 0) {
            energy.labels.push_back(name.substr(7));
            energy_shares.push_back(100 * value / *total);
        } else if (name.starts_with("area/") && *area_total > 0) {
            area.labels.push_back(name.substr(5));
            area_shares.push_back(100 * value / *area_total);
            areas.emplace_back(name.substr(5), value);
        }
    }
    energy.add("energy", energy_shares);
    area.add("area", area_shares);
    page.body << fmt::format(
        "<h2>Energy and area</h2>\n<p class=\"note\">A 65 nm estimate from "
        "the run's event counts and the configuration's [energy] and [area] "
        "costs (docs/energy.md): {} mJ per frame{}, {} W average, {} mm&sup2;."
        "</p>\n<div class=\"charts\">\n",
        readable(*total * 1e3),
        run.stat("energy/per_ray")
            ? fmt::format(", {} nJ per ray", readable(*run.stat("energy/per_ray") * 1e9))
            : "",
        readable(run.stat("energy/average_watts").value_or(0)), readable(*area_total));
    page.chart(energy);
    page.chart(area);
    page.body << "</div>\n<table><tr><th>part</th><th class=\"num\">area (mm&sup2;)</th>"
                 "<th class=\"num\">share</th></tr>\n";
    for (const auto& [part, mm2] : areas)
        page.body << fmt::format("<tr><td class=\"code\">{}</td><td class=\"num\">{}</td>{}</tr>\n",
                                 escape(part), readable(mm2),
                                 share_cell(*area_total > 0 ? mm2 / *area_total : 0));
    page.body << fmt::format("<tr><td>total</td><td class=\"num\">{}</td><td></td></tr>\n"
                             "</table>\n",
                             readable(*area_total));
}

void traffic(Page& page, const StatsFile& run) {
    const auto regions = region_levels(run);
    if (regions.empty()) return;
    const auto stat = [&](const std::string& region, const std::string& level, const char* leaf) {
        return run.stat("region/" + region + "/" + level + "/" + leaf);
    };
    const auto moves_bytes = [&](const std::string& region, const std::string& level) {
        return stat(region, level, "moved_bytes").value_or(0) != 0;
    };
    // The chart: the levels that move bytes (l1, l2, dram), on a log scale, as the regions'
    // traffic spans orders of magnitude.
    std::vector<std::string> levels;
    for (const auto& [region, own_levels] : regions)
        for (const std::string& level : own_levels)
            if (moves_bytes(region, level) &&
                std::find(levels.begin(), levels.end(), level) == levels.end())
                levels.push_back(level);
    Chart chart{.title = "Bytes moved by region and level (log scale)",
                .unit = "B",
                .log = true,
                .tall = true};
    std::vector<Json> data(levels.size(), Json::array());
    for (const auto& [region, own_levels] : regions) {
        if (std::none_of(levels.begin(), levels.end(),
                         [&](const std::string& level) { return moves_bytes(region, level); }))
            continue;
        chart.labels.push_back(region);
        for (size_t l = 0; l < levels.size(); ++l) {
            const double bytes = stat(region, levels[l], "moved_bytes").value_or(0);
            data[l].push_back(bytes > 0 ? Json(bytes) : Json());  // no bar rather than log(0)
        }
    }
    for (size_t l = 0; l < levels.size(); ++l)
        chart.add(levels[l], data[l]);

    // The table: every region x level that saw an access; local-store loads and stores and
    // I-cache fetches go in the reads and writes columns.
    std::ostringstream table;
    table << "<table><tr><th>region</th><th>level</th><th class=\"num\">reads</th>"
             "<th class=\"num\">writes</th><th class=\"num\">misses</th>"
             "<th class=\"num\">hit rate</th><th class=\"num\">payload B</th>"
             "<th class=\"num\">moved B</th></tr>\n";
    for (const auto& [region, own_levels] : regions)
        for (const std::string& level : own_levels) {
            const auto first_of = [&](std::initializer_list<const char*> leaves) {
                for (const char* leaf : leaves)
                    if (const auto v = stat(region, level, leaf)) return v;
                return std::optional<double>();
            };
            const auto reads = first_of({"reads", "loads", "fetches"});
            const auto writes = first_of({"writes", "stores"});
            const auto misses = stat(region, level, "misses"), hits = stat(region, level, "hits");
            const auto payload = stat(region, level, "payload_bytes");
            const auto moved = stat(region, level, "moved_bytes");
            if (reads.value_or(0) == 0 && writes.value_or(0) == 0 && payload.value_or(0) == 0 &&
                moved.value_or(0) == 0)
                continue;
            const auto cell = [](std::optional<double> v) {
                return fmt::format("<td class=\"num\">{}</td>", v ? readable(*v) : "");
            };
            table << "<tr><td>" << escape(region) << "</td><td>" << escape(level) << "</td>"
                  << cell(reads) << cell(writes) << cell(misses) << "<td class=\"num\">"
                  << (reads && hits && *reads > 0 ? fmt::format("{:.1f} %", 100 * *hits / *reads)
                                                  : "")
                  << "</td>" << cell(payload) << cell(moved) << "</tr>\n";
        }
    table << "</table>\n";
    page.body << "<h2>Memory traffic by region</h2>\n";
    page.chart(chart);
    page.body << table.str();
}

void timeline(Page& page, const StatsFile& run) {
    if (!run.timeline || run.timeline->rows.empty()) return;
    const Timeline& t = *run.timeline;
    const auto cycle = t.column("cycle");
    if (!cycle) return;
    const auto points = [&](size_t column, double scale) {
        Json data = Json::array();
        for (const auto& row : t.rows)
            data.push_back(
                {{"x", row[*cycle]},
                 {"y", std::isfinite(row[column]) ? Json(scale * row[column]) : Json()}});
        return data;
    };
    // Hit rates share one chart; every other column gets its own.
    Chart hit_rates{.type = "line", .title = "Hit rates", .percent = true};
    std::vector<Chart> charts;
    for (size_t c = 0; c < t.columns.size(); ++c) {
        const std::string& name = t.columns[c];
        if (c == *cycle) continue;
        if (name.ends_with("_hit_rate")) {
            hit_rates.add(name.substr(0, name.size() - 9), points(c, 100));
            continue;
        }
        Chart chart{.type = "line", .title = name};
        if (name == "issue_rate") chart.title = "Issue rate (instructions per TP-cycle)";
        if (name == "dram_bytes_per_cycle") chart.title = "DRAM bandwidth", chart.unit = "B/cycle";
        if (name == "active_threads") chart.title = "Active threads";
        chart.add(name, points(c, 1));
        charts.push_back(chart);
    }
    if (!hit_rates.datasets.empty())
        charts.insert(charts.begin() + std::min<size_t>(1, charts.size()), hit_rates);
    page.body << fmt::format("<h2>Over time</h2>\n<p class=\"note\">One point per {} cycles.</p>\n"
                             "<div class=\"charts\">\n",
                             readable(double(t.interval_cycles)));
    for (const Chart& chart : charts)
        page.chart(chart);
    page.body << "</div>\n";
}

void profile_table(Page& page, const std::vector<ProfileEntry>& entries, double total, bool lines) {
    constexpr size_t kShown = 20;
    page.body << fmt::format("<h3>Top {} by cycles{}</h3>\n<table{}><tr>{}<th>function</th>"
                             "<th class=\"num\">share</th><th class=\"num\">cycles</th>"
                             "<th class=\"num\">executions</th><th class=\"num\">stall "
                             "cycles</th><th class=\"num\">L1 misses</th><th class=\"num\">DRAM "
                             "B</th></tr>\n",
                             lines ? "source lines" : "functions",
                             entries.size() > kShown ? fmt::format(" (of {})", entries.size()) : "",
                             lines ? " class=\"lines\"" : "", lines ? "<th>line</th>" : "");
    for (size_t i = 0; i < std::min(kShown, entries.size()); ++i) {
        const ProfileEntry& e = entries[i];
        double stalls = 0;
        for (const auto& [cause, cycles] : e.stalls)
            stalls += cycles;
        page.body << "<tr>";
        if (lines)
            page.body << fmt::format("<td class=\"code line\">{}:{}</td>", escape(e.file), e.line);
        // Demangled names run long: one line each, cut with an ellipsis, in full on hover.
        page.body << fmt::format("<td class=\"code name\" title=\"{0}\">{0}</td>{1}<td "
                                 "class=\"num\">{2}</td><td "
                                 "class=\"num\">{3}</td><td class=\"num\">{4}</td><td "
                                 "class=\"num\">{5}</td><td class=\"num\">{6}</td></tr>\n",
                                 escape(e.function), share_cell(total > 0 ? e.cycles / total : 0),
                                 readable(e.cycles), readable(e.executions), readable(stalls),
                                 readable(e.l1_misses), readable(e.dram_bytes));
    }
    page.body << "</table>\n";
}

void profile(Page& page, const StatsFile& run) {
    if (!run.profile) return;
    page.body << fmt::format("<h2>Profile</h2>\n<p class=\"note\">Shares of {} TP-cycles charged "
                             "(issues and stalls).</p>\n",
                             readable(run.profile->total_cycles));
    profile_table(page, run.profile->functions, run.profile->total_cycles, false);
    profile_table(page, run.profile->lines, run.profile->total_cycles, true);
}

void configuration(Page& page, const StatsFile& run) {
    if (run.config.empty()) return;
    page.body << fmt::format("<details><summary>Resolved chip configuration ({} keys)</summary>\n"
                             "<table><tr><th>key</th><th>value</th></tr>\n",
                             run.config.size());
    for (const auto& [key, value] : run.config)
        page.body << fmt::format(
            "<tr><td class=\"code\">{}</td><td class=\"code\">{}</td></tr>\n", escape(key),
            escape(value.is_string() ? value.get<std::string>() : value.dump()));
    page.body << "</table>\n</details>\n";
}

/// Each run's host time, named by its file when there are several.
void host_line(Page& page, const std::vector<const StatsFile*>& runs) {
    std::string line;
    for (const StatsFile* run : runs)
        if (const auto seconds = run->stat("host/run_seconds"))
            line += runs.size() == 1 ? fmt::format("{:.3f} s", *seconds)
                                     : fmt::format("{}{}: {:.3f} s", line.empty() ? "" : ", ",
                                                   escape(run->path.filename().string()), *seconds);
    if (!line.empty())
        page.body << "<p class=\"note\">Host wall time of the kernel run (the simulator's speed, "
                     "not a result): "
                  << line << "</p>\n";
}

/// A key without the '/'-separated segments every row of the section shares at its start and
/// end: "chip/fu/fp_add/utilisation" is "fp_add" among the FU utilisation rows.
std::string distinct_part(const Section& section, const std::string& key) {
    const auto shared_by_all = [&](auto&& shares) {
        return std::all_of(section.rows.begin(), section.rows.end(),
                           [&](const Row& row) { return shares(row.key); });
    };
    size_t start = 0;
    for (size_t slash; (slash = key.find('/', start)) != std::string::npos; start = slash + 1) {
        const std::string prefix = key.substr(0, slash + 1);
        if (!shared_by_all([&](const std::string& k) { return k.starts_with(prefix); })) break;
    }
    size_t end = key.size();
    for (size_t slash;
         end > start && (slash = key.rfind('/', end - 1)) != std::string::npos && slash >= start;
         end = slash) {
        const std::string suffix = key.substr(slash);
        if (!shared_by_all([&](const std::string& k) { return k.ends_with(suffix); })) break;
    }
    return end > start ? key.substr(start, end - start) : key;
}

/// A grouped bar chart of rows from the comparison: one group per row, one bar per run; or,
/// `relative`, one bar per run after A: its change against A in per cent (a bar from 0, so a
/// 2 % difference shows as 2 % of the axis rather than as a sliver on a bar of 100 %).
Chart grouped(const Comparison& c, const Section& section, std::string title, bool relative,
              double scale = 1) {
    Chart chart{.title = std::move(title), .percent = relative || scale == 100};
    if (relative) chart.unit = "change against A";
    for (const Row& row : section.rows)
        chart.labels.push_back(distinct_part(section, row.key));
    for (size_t r = relative ? 1 : 0; r < c.runs.size(); ++r) {
        Json data = Json::array();
        for (const Row& row : section.rows) {
            const auto v = relative ? row.ratio(r) : row.values[r];
            const double shown = relative && v ? 100 * (*v - 1) : v ? scale * *v : 0;
            data.push_back(std::isfinite(shown) ? Json(shown) : Json(0));
        }
        chart.add(run_letter(r), data);
    }
    return chart;
}

const Section* find_section(const Comparison& c, std::string_view title) {
    for (const Section& s : c.sections)
        if (s.title == title) return &s;
    return nullptr;
}

std::string ratio_cell(const Row& row, size_t r) {
    const auto ratio = row.ratio(r);
    if (!ratio) return "<td class=\"num\">-</td>";
    const char* cls = "";
    if (row.differs_notably(r))
        cls = row.better == Better::neutral                    ? " changed"
              : (*ratio > 1) == (row.better == Better::higher) ? " better"
                                                               : " worse";
    return fmt::format("<td class=\"num{}\">{:.3f}x{}</td>", cls, *ratio,
                       row.within_intervals(r) ? "~" : "");
}

}  // namespace

std::string load_chart_js() {
    for (const char* candidate : kChartJsCandidates) {
        std::ifstream in(candidate, std::ios::binary);
        if (!in) continue;
        std::ostringstream text;
        text << in.rdbuf();
        // Only a UMD build defines the global Chart in a plain <script> (an ES module would not),
        // and one with "</script" in it would end its element early.
        if (text.str().find("define.amd") == std::string::npos ||
            text.str().find("</script") != std::string::npos)
            continue;
        return text.str();
    }
    throw Error(fmt::format("cannot find Chart.js's UMD build (looked for {} and {}); install "
                            "the Debian package libjs-chart.js (scripts/setup does)",
                            kChartJsCandidates[0], kChartJsCandidates[1]));
}

std::string report_page(const StatsFile& run, const std::string& chart_js,
                        const std::string& source) {
    Page page;
    const std::string scene = run.run_text("scene");
    page.body << fmt::format(
        "<h1>tpsim report: {}</h1>\n<p class=\"sub\">{}</p>\n"
        "<p class=\"sub\">{}</p>\n",
        escape(scene.empty() ? run.path.filename().string() : scene), run_line(run),
        escape(source.empty() ? "statistics file " + run.path.string() : source));
    cards(page, run);
    sampling(page, run);
    const auto image = run.run_file("image");
    const auto heatmap = run.run_file("heatmap");
    if (image || heatmap) {
        page.body << "<h2>Image</h2>\n<div class=\"images\">\n";
        if (image) page.body << image_tag(*image, "image");
        if (heatmap) page.body << image_tag(*heatmap, "heat map");
        page.body << "</div>\n";
    }
    cycles_charts(page, run);
    traffic(page, run);
    energy_and_area(page, run);
    timeline(page, run);
    profile(page, run);
    if (!run.stat("chip/cycles"))
        page.body << "<p class=\"note\">This run used the " << escape(run.run_text("engine"))
                  << " engine: no cycles, stalls, memory traffic, timeline or profile (render "
                     "with --timing cycle for those).</p>\n";
    configuration(page, run);
    host_line(page, {&run});
    return page.finish("tpsim report: " + (scene.empty() ? run.path.string() : scene), chart_js);
}

std::string comparison_page(const std::vector<StatsFile>& runs, const Comparison& c,
                            const std::string& chart_js) {
    Page page;
    page.body << "<h1>tpsim comparison</h1>\n<table><tr><th>run</th><th>statistics file</th>"
                 "<th>scene</th><th>setup</th></tr>\n";
    for (size_t r = 0; r < runs.size(); ++r)
        page.body << fmt::format("<tr><td>{}</td><td class=\"code\">{}</td><td>{}</td><td>{}</td>"
                                 "</tr>\n",
                                 run_letter(r), escape(c.runs[r]),
                                 escape(runs[r].run_text("scene")), run_line(runs[r]));
    page.body << "</table>\n";
    for (size_t r = 0; r < runs.size(); ++r)
        if (!c.estimates[r].empty())
            page.body << "<p class=\"warning\">Run " << run_letter(r) << " is "
                      << escape(c.estimates[r])
                      << ". A ratio marked ~ is within the intervals: the "
                      << "estimates cannot tell the two values apart.</p>\n";
    page.body << "<h2>What differs</h2>\n";
    if (c.differences.empty())
        page.body << "<p class=\"note\">Nothing in the run fields or the configuration.</p>\n";
    else {
        page.body << "<table><tr><th>field</th>";
        for (size_t r = 0; r < runs.size(); ++r)
            page.body << "<th>" << run_letter(r) << "</th>";
        page.body << "</tr>\n";
        for (const SetupDifference& d : c.differences) {
            page.body << "<tr><td class=\"code\">" << escape(d.field) << "</td>";
            for (const std::string& v : d.values)
                page.body << "<td class=\"code\">" << escape(v) << "</td>";
            page.body << "</tr>\n";
        }
        page.body << "</table>\n";
    }
    bool any_image = false;
    for (const StatsFile& run : runs)
        any_image |= run.run_file("image").has_value();
    if (any_image) {
        page.body << "<h2>Images</h2>\n<div class=\"images\">\n";
        for (size_t r = 0; r < runs.size(); ++r)
            if (const auto image = runs[r].run_file("image"))
                page.body << image_tag(*image, run_letter(r));
        page.body << "</div>\n";
        for (size_t i = 0; i < c.images.size(); ++i) {
            if (!c.images[i]) continue;
            const ImageDifference& d = *c.images[i];
            page.body << "<p>" << run_letter(i + 1) << " against A: ";
            if (!d.compared())
                page.body << escape(d.note);
            else if (d.differing_pixels == 0)
                page.body << "identical";
            else
                page.body << fmt::format("RMSE {:.6f}, PSNR {:.2f} dB, {} of {} pixels differ "
                                         "({:.2f} %)",
                                         d.rmse, d.psnr, d.differing_pixels, d.pixels,
                                         100 * d.differing_share());
            page.body << "</p>\n";
        }
    }
    page.body << "<h2>Side by side</h2>\n<div class=\"charts\">\n";
    if (const Section* s = find_section(c, "summary"))
        page.chart(grouped(c, *s, "Summary: change against A", true));
    if (const Section* s = find_section(c, "stall causes"))
        page.chart(grouped(c, *s, "Stall causes (TP-cycles)", false));
    if (const Section* s = find_section(c, "FU utilisation"))
        page.chart(grouped(c, *s, "Functional-unit utilisation", false, 100));
    if (const Section* s = find_section(c, "per ray"))
        page.chart(grouped(c, *s, "Per ray: change against A", true));
    if (const Section* s = find_section(c, "energy by part"))
        page.chart(grouped(c, *s, "Energy by part (J)", false));
    if (const Section* s = find_section(c, "area by part"))
        page.chart(grouped(c, *s, "Area by part (mm²)", false));
    if (const Section* s = find_section(c, "traffic by region and level")) {
        Section dram{"dram", {}};
        for (const Row& row : s->rows)
            if (row.key.ends_with("/dram/moved_bytes")) dram.rows.push_back(row);
        Chart chart = grouped(c, dram, "DRAM bytes moved by region (log scale)", false);
        chart.log = true;
        for (Json& dataset : chart.datasets)  // no bar rather than log(0)
            for (Json& bytes : dataset["data"])
                if (bytes == 0) bytes = Json();
        page.chart(chart);
    }
    page.body << "</div>\n";
    for (const Section& section : c.sections) {
        if (section.rows.empty()) continue;
        page.body << "<h3>" << escape(section.title) << "</h3>\n<table><tr><th>statistic</th>"
                  << "<th>unit</th>";
        for (size_t r = 0; r < runs.size(); ++r)
            page.body << "<th class=\"num\">" << run_letter(r) << "</th>"
                      << (r ? "<th class=\"num\">" + run_letter(r) + "/A</th>" : "");
        page.body << "</tr>\n";
        for (const Row& stored : section.rows) {
            const Row row = for_display(stored);
            page.body << "<tr><td class=\"code\">" << escape(row.key) << "</td><td>"
                      << escape(row.unit) << "</td>";
            for (size_t r = 0; r < runs.size(); ++r) {
                page.body << "<td class=\"num\">"
                          << (row.values[r] ? readable(*row.values[r]) : "-");
                if (row.values[r] && row.estimated(r))
                    page.body << " <span class=\"interval\">±"
                              << (std::isnan(row.interval(r)) ? "?" : readable(row.interval(r)))
                              << "</span>";
                page.body << "</td>";
                if (r) page.body << ratio_cell(row, r);
            }
            page.body << "</tr>\n";
        }
        page.body << "</table>\n";
    }
    std::vector<const StatsFile*> all;
    for (const StatsFile& run : runs)
        all.push_back(&run);
    host_line(page, all);
    return page.finish("tpsim comparison", chart_js);
}

std::string converge_page(const Json& doc, const std::filesystem::path& base,
                          const std::string& chart_js) {
    Page page;
    const auto text = [](const Json& j, const char* key) {
        const auto found = j.find(key);
        return found == j.end() || found->is_null() ? std::string()
               : found->is_string()                 ? found->get<std::string>()
                                                    : found->dump();
    };
    const auto number = [](const Json& j, const char* key) {
        const auto found = j.find(key);
        return found != j.end() && found->is_number() ? std::optional(found->get<double>())
                                                      : std::nullopt;
    };
    const auto kernel_line = [&](const char* kernel, const char* params) {
        std::string line = std::filesystem::path(text(doc, kernel)).stem().string();
        std::string list;
        if (const auto found = doc.find(params); found != doc.end() && found->is_object())
            for (const auto& [name, value] : found->items())
                list += (list.empty() ? "" : ", ") + name + "=" + value.dump();
        return line + (list.empty() ? "" : " (" + list + ")");
    };
    const Json& reference = doc["reference"];
    const std::string scene = text(doc, "scene");
    page.body << fmt::format(
        "<h1>tpsim converge: {}</h1>\n<p class=\"sub\">{}x{} pixels &middot; kernel {} "
        "&middot; seed {}{}</p>\n<p class=\"sub\">Each image against a {} spp reference from "
        "the native twin (seed {}): RMSE and PSNR over the 8-bit sRGB images, peak 1. Frame "
        "cycles from the cycle-level chip model.</p>\n",
        escape(scene), text(doc, "width"), text(doc, "height"),
        escape(kernel_line("kernel", "params")), text(doc, "seed"),
        doc.contains("adaptive_kernel")
            ? " &middot; adaptive kernel " +
                  escape(kernel_line("adaptive_kernel", "adaptive_params"))
            : "",
        text(reference, "samples_per_pixel"), text(reference, "seed"));

    Chart chart{.type = "scatter",
                .title = "Image error against frame cycles",
                .unit = "PSNR (dB)",
                .tall = true,
                .x_title = "frame cycles (log scale)",
                .x_log = true};
    Json uniform = Json::array(), adaptive = Json::array();
    for (const Json& run : doc["runs"]) {
        const auto cycles = number(run, "cycles"), psnr = number(run, "psnr");
        if (!cycles || !psnr) continue;  // identical to the reference: no finite PSNR
        (text(run, "kind") == "adaptive" ? adaptive : uniform)
            .push_back({{"x", *cycles}, {"y", *psnr}, {"label", text(run, "label")}});
    }
    chart.add("uniform samples per pixel", uniform, true);
    if (!adaptive.empty()) chart.add("adaptive (threshold)", adaptive, true);
    page.chart(chart);

    page.body << "<table><tr><th>run</th><th class=\"num\">samples/px</th><th class=\"num\">"
                 "frame cycles</th><th class=\"num\">rays</th><th class=\"num\">RMSE</th>"
                 "<th class=\"num\">PSNR</th><th class=\"num\">uniform PSNR at the same "
                 "cycles</th><th class=\"num\">host s</th></tr>\n";
    for (const Json& run : doc["runs"]) {
        const bool is_adaptive = text(run, "kind") == "adaptive";
        const auto cell = [](const std::string& value) {
            return "<td class=\"num\">" + value + "</td>";
        };
        const auto db = [](std::optional<double> v) {
            return v ? fmt::format("{:.2f} dB", *v) : std::string("-");
        };
        page.body << "<tr><td>" << escape(text(run, "label")) << "</td>"
                  << cell(is_adaptive
                              ? fmt::format("{:.2f} of {}",
                                            number(run, "camera_rays_per_pixel").value_or(0),
                                            text(run, "samples_per_pixel"))
                              : text(run, "samples_per_pixel"))
                  << cell(readable(number(run, "cycles").value_or(0)))
                  << cell(readable(number(run, "rays").value_or(0)))
                  << cell(fmt::format("{:.6f}", number(run, "rmse").value_or(0)))
                  << cell(number(run, "psnr") ? db(number(run, "psnr")) : "identical")
                  << cell(is_adaptive ? db(number(run, "uniform_psnr_at_same_cycles")) : "")
                  << cell(fmt::format("{:.1f}", number(run, "host_seconds").value_or(0)))
                  << "</tr>\n";
    }
    page.body << "</table>\n<h2>Images</h2>\n<div class=\"images\">\n"
              << image_tag(base / text(reference, "image"), text(reference, "label"));
    for (const Json& run : doc["runs"])
        page.body << image_tag(base / text(run, "image"), text(run, "label"));
    page.body << "</div>\n";
    return page.finish("tpsim converge: " + scene, chart_js);
}

namespace {

/// The value range of an error chart ({x, y, yMin, yMax} points): the points and their error
/// bars, but no more than three times the largest error or one and a half times the median
/// bar each way, so that a few runs with huge intervals do not flatten the rest against 0.
std::optional<std::pair<double, double>> error_range(const Chart& chart) {
    double largest = 0, lo = 0, hi = 0;
    std::vector<double> halves;
    for (const Json& dataset : chart.datasets)
        for (const Json& p : dataset["data"]) {
            largest = std::max(largest, std::abs(p["y"].get<double>()));
            lo = std::min(lo, p["yMin"].get<double>());
            hi = std::max(hi, p["yMax"].get<double>());
            halves.push_back((p["yMax"].get<double>() - p["yMin"].get<double>()) / 2);
        }
    if (halves.empty()) return std::nullopt;
    std::nth_element(halves.begin(), halves.begin() + halves.size() / 2, halves.end());
    const double limit = std::max(3 * largest, 1.5 * halves[halves.size() / 2]);
    if (limit == 0) return std::nullopt;
    return std::pair(std::max(lo, -limit), std::min(hi, limit));
}

}  // namespace

std::string sample_check_page(const Json& doc, const std::string& chart_js) {
    Page page;
    const auto text = [](const Json& j, const char* key) {
        const auto found = j.find(key);
        return found == j.end() || found->is_null() ? std::string()
               : found->is_string()                 ? found->get<std::string>()
                                                    : found->dump();
    };
    const auto number = [](const Json& j, const char* key) {
        const auto found = j.find(key);
        return found != j.end() && found->is_number() ? std::optional(found->get<double>())
                                                      : std::nullopt;
    };
    const auto percent = [](std::optional<double> share, bool sign = false) {
        if (!share) return std::string("-");
        return sign ? fmt::format("{:+.2f} %", 100 * *share)
                    : fmt::format("{:.2f} %", 100 * *share);
    };
    const std::string scene = text(doc, "scene");
    const Json& full = doc["full"];
    const Json& statistics = doc["statistics"];
    const double seeds = number(doc, "seeds").value_or(1);
    page.body << fmt::format(
        "<h1>tpsim sample-check: {}</h1>\n<p class=\"sub\">{}x{} pixels &middot; {} spp "
        "&middot; kernel {} &middot; {}</p>\n<p class=\"sub\">Sampled cycle-level simulation "
        "(render --timing sampled) against the full cycle-level run: units of {} cycles after "
        "{} cycles of warm-up, seeds 1 to {}. Host times are CPU seconds of the kernel run "
        "(medians), speedups the median of the rounds' ratios to the full run; errors and 95 % "
        "intervals are relative to the full run's value (an error bar longer than its chart is "
        "cut at the edge; the tables give it whole).</p>\n",
        escape(scene), text(doc, "width"), text(doc, "height"), text(doc, "samples_per_pixel"),
        escape(std::filesystem::path(text(doc, "kernel")).stem().string()),
        escape(text(doc, "chip")), readable(number(doc, "unit_cycles").value_or(0)),
        readable(number(doc, "warmup_cycles").value_or(0)), seeds);
    page.body << fmt::format(
        "<p>Full cycle-level run: {} cycles, {} instructions, {:.2f} s. The bound, functional "
        "simulation only (--timing none): {:.2f} s, <b>{:.1f}x</b> faster.</p>\n",
        readable(full["values"].value(statistics[0].value("key", ""), 0.0)),
        readable(number(doc, "instructions").value_or(0)),
        number(full, "median_cpu_seconds").value_or(0),
        number(doc["functional"], "median_cpu_seconds").value_or(0),
        number(doc["functional"], "speedup").value_or(0));

    Chart speed{.title = "Speedup over the full cycle-level run (CPU time)", .unit = "x"};
    Json speedups = Json::array();
    for (const Json& rate : doc["rates"]) {
        speed.labels.push_back("rate " + text(rate, "rate"));
        speedups.push_back(number(rate, "speedup").value_or(0));
    }
    speed.labels.push_back("functional (bound)");
    speedups.push_back(number(doc["functional"], "speedup").value_or(0));
    speed.add("speedup", speedups);

    // Error against speedup, one chart per statistic, a dataset per rate; the seeds of a rate
    // are spread a little sideways so that their intervals can be told apart.
    std::vector<Chart> errors;
    for (const Json& statistic : statistics) {
        const std::string key = statistic.value("key", "");
        Chart chart{.type = "scatter",
                    .title = statistic.value("label", key) +
                             ": error of the estimate, with its 95 % interval",
                    .unit = "error (%)",
                    .x_title = "speedup over the full run"};
        for (const Json& rate : doc["rates"]) {
            const double speedup = number(rate, "speedup").value_or(0);
            const Json& runs = rate["runs"];
            Json points = Json::array();
            for (size_t i = 0; i < runs.size(); ++i) {
                const auto found = runs[i].find("statistics");
                if (found == runs[i].end()) continue;  // refused: no estimate
                const Json& check = (*found)[key];
                const auto error = number(check, "error");
                const auto half = number(check, "relative_half_width");
                if (!error || !half) continue;
                const double spread =
                    runs.size() > 1 ? 0.04 * ((double(i) + 0.5) / double(runs.size()) - 0.5) : 0;
                points.push_back({{"x", speedup * (1 + spread)},
                                  {"y", 100 * *error},
                                  {"yMin", 100 * (*error - *half)},
                                  {"yMax", 100 * (*error + *half)},
                                  {"label", "seed " + text(runs[i], "seed")}});
            }
            chart.add("rate " + text(rate, "rate"), points);
        }
        chart.range = error_range(chart);
        errors.push_back(chart);
    }

    page.body << "<div class=\"charts\">\n";
    page.chart(speed);
    for (const Chart& chart : errors)
        page.chart(chart);
    if (seeds > 1) {
        Chart coverage{.title = fmt::format("Coverage of the 95 % intervals over {} seeds", seeds),
                       .percent = true};
        for (const Json& rate : doc["rates"])
            coverage.labels.push_back("rate " + text(rate, "rate"));
        for (const Json& statistic : statistics) {
            Json shares = Json::array();
            for (const Json& rate : doc["rates"]) {
                const Json& c = rate["coverage"][statistic.value("key", "")];
                const double runs = number(c, "runs").value_or(0);
                shares.push_back(runs > 0 ? Json(100 * number(c, "covered").value_or(0) / runs)
                                          : Json());
            }
            coverage.add(statistic.value("label", ""), shares);
        }
        page.chart(coverage);
    }
    page.body << "</div>\n";

    // The tables: seed 1 at each rate, then the coverage over the seeds.
    page.body << "<h2>Seed 1 at each rate</h2>\n<table><tr><th>statistic</th><th "
                 "class=\"num\">rate</th><th class=\"num\">host s</th><th "
                 "class=\"num\">speedup</th><th class=\"num\">estimate</th><th "
                 "class=\"num\">true</th><th class=\"num\">error</th><th class=\"num\">&plusmn; "
                 "95 %</th><th>covered</th></tr>\n";
    for (const Json& statistic : statistics) {
        const std::string key = statistic.value("key", "");
        for (const Json& rate : doc["rates"]) {
            const Json& run = rate["runs"][0];
            const auto found = run.find("statistics");
            page.body << fmt::format("<tr><td>{}</td><td class=\"num\">{}</td><td "
                                     "class=\"num\">{:.2f}</td><td class=\"num\">{:.1f}x</td>",
                                     escape(statistic.value("label", key)), text(rate, "rate"),
                                     number(rate, "median_cpu_seconds").value_or(0),
                                     number(rate, "speedup").value_or(0));
            if (found == run.end()) {
                page.body << "<td colspan=\"5\">not estimated: " << escape(text(run, "refused"))
                          << "</td></tr>\n";
                continue;
            }
            const Json& check = (*found)[key];
            const bool exact = run.value("exact", false);
            const bool unknown = !exact && !number(check, "relative_half_width");
            page.body << fmt::format(
                "<td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td "
                "class=\"num\">{}</td><td{}>{}</td></tr>\n",
                readable(number(check, "estimate").value_or(0)),
                readable(full["values"].value(key, 0.0)), percent(number(check, "error"), true),
                percent(number(check, "relative_half_width")),
                exact || check.value("covered", false) ? "" : " class=\"worse\"",
                exact                           ? "exact"
                : check.value("covered", false) ? "yes"
                : unknown                       ? "unknown"
                                                : "no");
        }
    }
    page.body << "</table>\n";
    if (seeds > 1) {
        page.body << fmt::format(
            "<h2>Coverage over {} seeds</h2>\n<table><tr><th>statistic</th><th "
            "class=\"num\">rate</th><th class=\"num\">covered</th><th class=\"num\">mean "
            "error</th><th class=\"num\">rms error</th><th class=\"num\">median &plusmn; 95 "
            "%</th></tr>\n",
            seeds);
        for (const Json& statistic : statistics) {
            const std::string key = statistic.value("key", "");
            for (const Json& rate : doc["rates"]) {
                const Json& c = rate["coverage"][key];
                const double runs = number(c, "runs").value_or(0);
                if (runs == 0) continue;
                const double covered = number(c, "covered").value_or(0);
                page.body << fmt::format(
                    "<tr><td>{}</td><td class=\"num\">{}</td><td class=\"num\">{:.0f}/{:.0f} "
                    "({:.1f} %)</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td "
                    "class=\"num\">{}</td></tr>\n",
                    escape(statistic.value("label", key)), text(rate, "rate"), covered, runs,
                    100 * covered / runs, percent(number(c, "mean_error"), true),
                    percent(number(c, "rms_error")), percent(number(c, "median_half_width")));
            }
        }
        page.body << "</table>\n";
    }
    return page.finish("tpsim sample-check: " + scene, chart_js);
}

/// The sweep's trade-off between speed and energy: every finished job as a point (frame time,
/// energy per frame), the Pareto front (no other job both faster and cheaper) joined by a line;
/// one chart per scene (when the scene is an axis). Needs the columns of chip/frame_seconds and
/// energy/total (the default columns have both).
void pareto_charts(Page& page, const Json& doc, size_t scene_axis) {
    const Json& columns = doc["columns"];
    const auto column_of = [&](std::string_view stat) {
        for (size_t c = 0; c < columns.size(); ++c)
            if (columns[c].value("stat", "") == stat) return c;
        return columns.size();
    };
    const size_t time = column_of("chip/frame_seconds"), energy = column_of("energy/total");
    if (time == columns.size() || energy == columns.size()) return;
    const std::vector<std::string> axes = doc["axes"].get<std::vector<std::string>>();
    const auto text = [](const Json& value) {
        return value.is_string() ? value.get<std::string>() : value.dump();
    };
    struct Point {
        double ms, mj;
        std::string label;
        size_t tag;  ///< the number the chart draws beside the point, and the table's first column
    };
    std::vector<std::pair<std::string, std::vector<Point>>> scenes;  // in row order
    for (const Json& row : doc["rows"]) {
        const Json& t = row["stats"][time];
        const Json& e = row["stats"][energy];
        if (!t.is_number() || !e.is_number()) continue;
        const std::string scene = scene_axis < axes.size() ? text(row["values"][scene_axis]) : "";
        std::string label;
        for (size_t a = 0; a < axes.size(); ++a)
            if (a != scene_axis)
                label += (label.empty() ? "" : ", ") + axes[a] + "=" + text(row["values"][a]);
        auto found = std::find_if(scenes.begin(), scenes.end(),
                                  [&](const auto& s) { return s.first == scene; });
        if (found == scenes.end()) found = scenes.insert(scenes.end(), {scene, {}});
        const size_t tag = found->second.size() + 1;
        found->second.push_back({t.get<double>() * 1e3, e.get<double>() * 1e3,
                                 label.empty() ? row.value("id", "") : label, tag});
    }
    if (scenes.empty()) return;
    page.body << "<h2>Frame time against energy</h2>\n<p class=\"note\">Each point is a job; the "
                 "line joins the Pareto front, the jobs no other job beats on both frame time "
                 "and energy per frame (docs/energy.md).</p>\n<div class=\"charts\">\n";
    for (auto& [scene, points] : scenes) {
        Chart chart{.type = "scatter",
                    .title =
                        "Pareto: frame time vs energy" + (scene.empty() ? "" : " (" + scene + ")"),
                    .unit = "energy per frame (mJ)",
                    .x_title = "frame time (ms)"};
        Json all = Json::array(), front = Json::array();
        for (const Point& p : points)
            all.push_back({{"x", p.ms}, {"y", p.mj}, {"label", p.label}, {"tag", p.tag}});
        std::stable_sort(points.begin(), points.end(), [](const Point& a, const Point& b) {
            return a.ms < b.ms || (a.ms == b.ms && a.mj < b.mj);
        });
        double cheapest = std::numeric_limits<double>::infinity();
        for (const Point& p : points)
            if (p.mj < cheapest) {  // faster ones all cost more: this one is on the front
                cheapest = p.mj;
                front.push_back({{"x", p.ms}, {"y", p.mj}, {"label", p.label}});
            }
        chart.add("jobs", all);
        chart.add("Pareto front", front, true);
        page.chart(chart);
    }
    page.body << "</div>\n";
    // What each numbered point is, so that a screenshot says it without tooltips.
    for (auto& [scene, points] : scenes) {
        std::sort(points.begin(), points.end(),
                  [](const Point& a, const Point& b) { return a.tag < b.tag; });
        page.body << "<table><tr><th class=\"num\">point</th><th>"
                  << (scene.empty() ? "job" : "job (" + escape(scene) + ")")
                  << "</th><th class=\"num\">frame ms</th><th class=\"num\">energy mJ</th></tr>\n";
        for (const Point& p : points)
            page.body << fmt::format("<tr><td class=\"num\">{}</td><td>{}</td><td "
                                     "class=\"num\">{}</td><td class=\"num\">{}</td></tr>\n",
                                     p.tag, escape(p.label), format_number(p.ms),
                                     format_number(p.mj));
        page.body << "</table>\n";
    }
}

std::string sweep_page(const Json& doc, const std::string& chart_js) {
    Page page;
    const auto text = [](const Json& value) {
        return value.is_string() ? value.get<std::string>() : value.dump();
    };
    const std::vector<std::string> axes = doc["axes"].get<std::vector<std::string>>();
    const Json& rows = doc["rows"];
    const Json& columns = doc["columns"];
    std::string fixed;
    for (const auto& [name, value] : doc["fixed"].items())
        fixed += (fixed.empty() ? "" : " &middot; ") + escape(name + " = " + text(value));
    size_t ok = 0;
    for (const Json& row : rows)
        ok += row["status"] == "ok";
    page.body << fmt::format("<h1>tpsim sweep: {}</h1>\n<p class=\"sub\">{} jobs, {} finished "
                             "&middot; axes: {}</p>\n",
                             escape(doc.value("title", "")), rows.size(), ok,
                             escape(fmt::format("{}", fmt::join(axes, ", "))));
    if (!fixed.empty())
        page.body << "<p class=\"sub\">the same in every job: " << fixed << "</p>\n";

    // A metric against the x axis, one dataset per value of the `by` axis; one chart per
    // combination of the remaining axes. Without `by`: one chart per scene (when the scene is
    // an axis), one dataset per combination of the other axes.
    const auto axis_index = [&](const std::string& name) {
        return size_t(std::find(axes.begin(), axes.end(), name) - axes.begin());
    };
    const size_t x_axis = axis_index(doc["charts"].value("x", ""));
    const size_t by_axis = axis_index(doc["charts"].value("by", ""));
    const size_t scene_axis = axis_index("scene");
    const auto in_panel = [&](size_t a) {
        if (a == x_axis || a == by_axis) return false;
        return by_axis < axes.size() || a == scene_axis;
    };
    const auto join = [&](const Json& row, auto&& take) {
        std::string label;
        for (size_t a = 0; a < axes.size(); ++a)
            if (take(a))
                label += (label.empty() ? "" : ", ") + axes[a] + "=" + text(row["values"][a]);
        return label;
    };
    std::vector<std::string> panels, x_labels;
    bool numeric_x = true;
    for (const Json& row : rows) {
        if (x_axis >= axes.size()) break;
        const std::string panel = join(row, in_panel);
        if (std::find(panels.begin(), panels.end(), panel) == panels.end()) panels.push_back(panel);
        const Json& value = row["values"][x_axis];
        numeric_x = numeric_x && value.is_number();
        if (std::find(x_labels.begin(), x_labels.end(), text(value)) == x_labels.end())
            x_labels.push_back(text(value));
    }
    if (x_axis < axes.size()) page.body << "<h2>Charts</h2>\n<div class=\"charts\">\n";
    for (const Json& metric_json : doc["charts"]["metrics"]) {
        if (x_axis >= axes.size()) break;
        const std::string metric = metric_json.get<std::string>();
        size_t column = columns.size();
        for (size_t c = 0; c < columns.size(); ++c)
            if (columns[c]["name"] == metric) column = c;
        for (const std::string& panel : panels) {
            // The x values as categories, evenly spaced (sizes are usually powers of two):
            // lines over a numeric axis, grouped bars over a text one.
            Chart chart{.type = numeric_x ? "line" : "bar",
                        .title = metric + (panel.empty() ? "" : " (" + panel + ")"),
                        .unit = metric,
                        .zero = false,
                        .x_title = axes[x_axis]};
            chart.labels = x_labels;
            std::vector<std::string> series;
            std::vector<Json> data;
            for (const Json& row : rows) {
                if (join(row, in_panel) != panel) continue;
                std::string label =
                    join(row, [&](size_t a) { return a != x_axis && !in_panel(a); });
                if (label.empty()) label = metric;
                auto found = std::find(series.begin(), series.end(), label);
                if (found == series.end()) {
                    series.push_back(label);
                    data.push_back(Json(std::vector<Json>(x_labels.size())));
                    found = series.end() - 1;
                }
                const size_t x = size_t(
                    std::find(x_labels.begin(), x_labels.end(), text(row["values"][x_axis])) -
                    x_labels.begin());
                data[size_t(found - series.begin())][x] =
                    column < columns.size() ? row["stats"][column] : row["host_seconds"];
            }
            for (size_t k = 0; k < series.size(); ++k)
                chart.add(series[k], data[k]);
            chart.tall = series.size() > 4;  // room for the legend
            page.chart(chart);
        }
    }
    if (x_axis < axes.size()) page.body << "</div>\n";
    pareto_charts(page, doc, scene_axis);

    page.body << "<h2>Every job</h2>\n<table><tr><th>id</th>";
    for (const std::string& axis : axes)
        page.body << "<th>" << escape(axis) << "</th>";
    page.body << "<th>status</th>";
    // Seconds and joules with one SI prefix per column, as the charts and compare show them;
    // the header names the prefixed unit (the column's name says the SI one).
    std::vector<Row> shown;
    for (size_t c = 0; c < columns.size(); ++c) {
        Row column{
            columns[c].value("name", ""), columns[c].value("unit", ""), Better::neutral, {}, {}};
        for (const Json& row : rows) {
            const Json& value = row["stats"][c];
            column.values.push_back(value.is_number() ? std::optional(value.get<double>())
                                                      : std::nullopt);
        }
        shown.push_back(for_display(column));
        page.body << "<th class=\"num\" title=\"" << escape(columns[c].value("stat", "")) << "\">"
                  << escape(shown[c].key)
                  << (shown[c].unit == column.unit ? "" : " (" + escape(shown[c].unit) + ")")
                  << "</th>";
    }
    page.body << "<th class=\"num\">host s</th></tr>\n";
    for (size_t r = 0; r < rows.size(); ++r) {
        const Json& row = rows[r];
        page.body << "<tr><td class=\"code id\">" << escape(row.value("id", "")) << "</td>";
        // A path (a scene, a mesh) by its file name, in full on hover.
        for (const Json& value : row["values"]) {
            const std::string full = text(value);
            const std::string name = std::filesystem::path(full).filename().string();
            if (value.is_string() && full.find('/') != std::string::npos && !name.empty())
                page.body << "<td title=\"" << escape(full) << "\">" << escape(name) << "</td>";
            else
                page.body << "<td>" << escape(full) << "</td>";
        }
        page.body << "<td>" << escape(row.value("status", "")) << "</td>";
        for (const Row& column : shown) {
            const auto& value = column.values[r];
            page.body << "<td class=\"num\">" << (value ? readable(*value) : "-") << "</td>";
        }
        const Json& host = row["host_seconds"];
        page.body << "<td class=\"num\">"
                  << (host.is_number() ? fmt::format("{:.2f}", host.get<double>()) : "-")
                  << "</td></tr>\n";
    }
    page.body << "</table>\n<p class=\"note\">host s: the host's wall time for the scene load, "
                 "BVH build and run (not a result: it depends on the machine and its load).</p>\n";
    return page.finish("tpsim sweep: " + doc.value("title", ""), chart_js);
}

}  // namespace tpsim::analysis
