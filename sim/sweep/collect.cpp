// Collecting a sweep: every job's axis values and key statistics in one table (CSV, Markdown,
// and the JSON document its HTML page is drawn from).
#include <algorithm>

#include <fmt/format.h>

#include "sim/analysis/compare.hpp"
#include "sim/analysis/stats_file.hpp"
#include "sim/core/error.hpp"
#include "sim/stats/thousands.hpp"
#include "sim/sweep/sweep.hpp"

namespace tpsim::sweep {
namespace {

std::string value_text(const Json& value) {
    return value.is_string() ? value.get<std::string>() : value.dump();
}

/// Exact: the shortest text that reads back as the same double.
std::string exact(const std::optional<double>& value) {
    return value ? fmt::format("{}", *value) : std::string();
}

/// For a person: whole numbers with thousands separators, others to 4 significant digits.
std::string readable(const std::optional<double>& value) {
    if (!value) return "-";
    const std::string text = analysis::format_number(*value);
    if (text.find_first_not_of("-0123456789") != std::string::npos) return text;
    return stats::with_thousands(text);
}

/// "did you mean ..." for a mistyped key: the keys sharing its longest leading path.
std::string suggestion(const std::string& key, const std::vector<std::string>& keys) {
    for (std::string prefix = key; !prefix.empty();) {
        const size_t slash = prefix.rfind('/');
        prefix = slash == std::string::npos ? std::string() : prefix.substr(0, slash + 1);
        std::vector<std::string> near;
        for (const std::string& k : keys)
            if (!prefix.empty() && k.starts_with(prefix) && near.size() < 4) near.push_back(k);
        if (!near.empty())
            return fmt::format("keys under '{}' are e.g. {}", prefix, fmt::join(near, ", "));
        if (!prefix.empty()) prefix.pop_back();
    }
    return fmt::format(
        "keys are e.g. {}",
        fmt::join(keys.begin(), keys.begin() + std::min<size_t>(4, keys.size()), ", "));
}

}  // namespace

std::vector<Column> default_columns() {
    return {{"cycles", "chip/cycles"},
            {"instructions", "instructions/total"},
            {"rays", "rays/total"},
            {"l1_hit_rate", "chip/l1/hit_rate"},
            {"l2_hit_rate", "chip/l2/hit_rate"},
            {"dram_bytes_read", "dram/bytes_read"},
            {"dram_bytes_written", "dram/bytes_written"},
            {"frame_seconds", "chip/frame_seconds"},
            {"energy_joules", "energy/total"},
            {"watts", "energy/average_watts"},
            {"mrays_per_joule", "energy/mrays_per_joule"},
            {"area_mm2", "area/total"}};
}

Table collect(const Sweep& sweep, const std::filesystem::path& dir,
              const std::vector<Column>& columns) {
    Table table;
    for (const Axis& axis : sweep.axes)
        table.axes.push_back(axis.name);
    table.fixed = sweep.fixed;
    table.columns = columns;
    std::vector<bool> found(columns.size(), false);
    std::vector<std::string> keys;  // of the first finished job, to suggest from
    for (const Job& job : sweep.jobs) {
        Table::Row row{job.id, "missing", job.values, {}, std::nullopt};
        row.stats.resize(columns.size());
        if (finished(dir, job)) {
            const analysis::StatsFile run = analysis::load_stats_file(stats_path(dir, job.id));
            row.status = "ok";
            for (size_t c = 0; c < columns.size(); ++c) {
                row.stats[c] = run.stat(columns[c].stat);
                found[c] = found[c] || row.stats[c].has_value();
                if (table.columns[c].unit.empty())
                    table.columns[c].unit = run.unit(columns[c].stat);
            }
            if (keys.empty())
                for (const auto& stat : run.stats)
                    keys.push_back(stat.first);
            double host = 0;
            bool any = false;
            for (const char* key :
                 {"host/load_seconds", "host/bvh_seconds", "host/wide_bvh_seconds",
                  "host/grid_seconds", "host/kdtree_seconds", "host/bsp_seconds",
                  "host/octree_seconds", "host/run_seconds"})
                if (const auto seconds = run.stat(key)) {
                    host += *seconds;
                    any = true;
                }
            if (any) row.host_seconds = host;
        } else if (std::error_code ec; std::filesystem::exists(error_path(dir, job.id), ec)) {
            row.status = "failed";
        }
        table.rows.push_back(std::move(row));
    }
    for (size_t c = 0; c < columns.size(); ++c)
        if (columns[c].given && !found[c] && !keys.empty())
            throw Error(fmt::format("--column {}={}: no finished job has the statistic '{}'; {} "
                                    "(docs/statistics.md lists every key)",
                                    columns[c].name, columns[c].stat, columns[c].stat,
                                    suggestion(columns[c].stat, keys)));
    return table;
}

std::string table_csv(const Table& table, bool host_time) {
    std::string out = "id";
    for (const std::string& axis : table.axes)
        out += fmt::format(",{}", analysis::csv_field(axis));
    out += ",status";
    for (const Column& column : table.columns)
        out += fmt::format(",{}", analysis::csv_field(column.name));
    out += host_time ? ",host_seconds\n" : "\n";
    for (const Table::Row& row : table.rows) {
        out += row.id;
        for (const Json& value : row.values)
            out += fmt::format(",{}", analysis::csv_field(value_text(value)));
        out += "," + row.status;
        for (const auto& stat : row.stats)
            out += fmt::format(",{}", exact(stat));
        if (host_time) out += fmt::format(",{}", exact(row.host_seconds));
        out += "\n";
    }
    return out;
}

std::string table_markdown(const Table& table, bool host_time) {
    std::string head = "| id |", rule = "|---|";
    for (const std::string& axis : table.axes) {
        head += " " + axis + " |";
        rule += "---|";
    }
    head += " status |";
    rule += "---|";
    for (const Column& column : table.columns) {
        head += " " + column.name + " |";
        rule += "---:|";
    }
    if (host_time) {
        head += " host s |";
        rule += "---:|";
    }
    std::string out = head + "\n" + rule + "\n";
    for (const Table::Row& row : table.rows) {
        out += "| " + row.id + " |";
        for (const Json& value : row.values)
            out += fmt::format(" {} |", value_text(value));
        out += " " + row.status + " |";
        for (const auto& stat : row.stats)
            out += fmt::format(" {} |", readable(stat));
        if (host_time)
            out += row.host_seconds ? fmt::format(" {:.2f} |", *row.host_seconds)
                                    : std::string(" - |");
        out += "\n";
    }
    return out;
}

ChartChoice default_charts(const Table& table) {
    ChartChoice choice{{"cycles", "dram_bytes_read"}, "", ""};
    for (const std::string& axis : table.axes)
        if (axis != "scene") {
            choice.x = axis;
            break;
        }
    if (choice.x.empty() && !table.axes.empty()) choice.x = table.axes[0];
    return choice;
}

Json table_document(const Table& table, const ChartChoice& charts, const std::string& title) {
    if (!charts.x.empty() &&
        std::find(table.axes.begin(), table.axes.end(), charts.x) == table.axes.end())
        throw Error(fmt::format("--x {}: the sweep has no such axis; its axes are {}", charts.x,
                                fmt::join(table.axes, ", ")));
    if (!charts.by.empty() &&
        (charts.by == charts.x ||
         std::find(table.axes.begin(), table.axes.end(), charts.by) == table.axes.end()))
        throw Error(fmt::format("--by {}: give an axis other than --x {}; the sweep's axes are {}",
                                charts.by, charts.x, fmt::join(table.axes, ", ")));
    for (const std::string& metric : charts.metrics)
        if (metric != "host_seconds" &&
            std::none_of(table.columns.begin(), table.columns.end(),
                         [&](const Column& c) { return c.name == metric; }))
            throw Error(fmt::format("--metric {}: the table has no such column; give one of its "
                                    "columns or add a statistic with --column NAME=KEY",
                                    metric));
    Json doc = {{"format", "tpsim-sweep-table"}, {"title", title}, {"axes", table.axes}};
    Json fixed = Json::object(), columns = Json::array(), rows = Json::array();
    for (const Setting& s : table.fixed)
        fixed[s.name] = s.value;
    for (const Column& c : table.columns)
        columns.push_back({{"name", c.name}, {"stat", c.stat}, {"unit", c.unit}});
    for (const Table::Row& row : table.rows) {
        Json stats = Json::array();
        for (const auto& s : row.stats)
            stats.push_back(s ? Json(*s) : Json());
        rows.push_back({{"id", row.id},
                        {"status", row.status},
                        {"values", row.values},
                        {"stats", std::move(stats)},
                        {"host_seconds", row.host_seconds ? Json(*row.host_seconds) : Json()}});
    }
    doc["fixed"] = std::move(fixed);
    doc["columns"] = std::move(columns);
    doc["rows"] = std::move(rows);
    doc["charts"] = {{"metrics", charts.metrics}, {"x", charts.x}, {"by", charts.by}};
    return doc;
}

}  // namespace tpsim::sweep
