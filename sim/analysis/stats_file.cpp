#include "sim/analysis/stats_file.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include <fmt/format.h>

#include "sim/core/error.hpp"

namespace tpsim::analysis {
namespace {

constexpr const char* kHowToGetOne = "give a file written by tpsim render --stats-json";

/// Thrown from the parser callback to stop a too deeply nested document early.
struct TooDeep {};

/// Reads one part of the document, naming where it is in messages: `X.json: "profile".
/// "functions"[3]."cycles" must be a number, got a string`.
class Reader {
public:
    explicit Reader(std::string file) : file_(std::move(file)) {}

    [[noreturn]] void fail(const std::string& where, const std::string& problem) const {
        throw Error(fmt::format("{}: {} {}; the file is damaged or was not written by tpsim", file_,
                                where, problem));
    }

    double number(const Json& value, const std::string& where) const {
        return need(value, value.is_number(), "a number", where).get<double>();
    }
    std::string string(const Json& value, const std::string& where) const {
        return need(value, value.is_string(), "a string", where).get<std::string>();
    }
    const Json& object(const Json& value, const std::string& where) const {
        return need(value, value.is_object(), "an object", where);
    }
    const Json& array(const Json& value, const std::string& where) const {
        return need(value, value.is_array(), "an array", where);
    }

private:
    const Json& need(const Json& value, bool ok, const char* expected,
                     const std::string& where) const {
        if (!ok) {
            const char* article = value.is_object() || value.is_array() ? "an " : "a ";
            fail(where, fmt::format("must be {}, got {}{}", expected,
                                    value.is_null() ? "" : article, value.type_name()));
        }
        return value;
    }
    std::string file_;
};

std::string in_quotes(std::string_view key) {
    return fmt::format("\"{}\"", key);
}

ProfileEntry read_profile_entry(const Reader& r, const Json& entry, const std::string& where,
                                bool is_line) {
    r.object(entry, where);
    ProfileEntry e;
    const auto field = [&](const char* key) -> const Json& {
        if (!entry.contains(key)) r.fail(where, fmt::format("has no \"{}\"", key));
        return entry[key];
    };
    e.function = r.string(field("function"), where + ".\"function\"");
    if (is_line) {
        e.file = r.string(field("file"), where + ".\"file\"");
        e.line = static_cast<int64_t>(r.number(field("line"), where + ".\"line\""));
    }
    e.executions = r.number(field("executions"), where + ".\"executions\"");
    e.cycles = r.number(field("cycles"), where + ".\"cycles\"");
    if (entry.contains("stalls"))
        for (const auto& [cause, value] : r.object(entry["stalls"], where + ".\"stalls\"").items())
            e.stalls.emplace_back(cause,
                                  r.number(value, where + ".\"stalls\"." + in_quotes(cause)));
    if (entry.contains("l1_misses"))
        e.l1_misses = r.number(entry["l1_misses"], where + ".\"l1_misses\"");
    if (entry.contains("dram_bytes"))
        e.dram_bytes = r.number(entry["dram_bytes"], where + ".\"dram_bytes\"");
    return e;
}

Timeline read_timeline(const Reader& r, const Json& value) {
    r.object(value, "\"timeline\"");
    Timeline t;
    if (value.contains("interval_cycles"))
        t.interval_cycles = static_cast<uint64_t>(
            r.number(value["interval_cycles"], "\"timeline\".\"interval_cycles\""));
    if (!value.contains("columns")) r.fail("\"timeline\"", "has no \"columns\"");
    for (const Json& column : r.array(value["columns"], "\"timeline\".\"columns\""))
        t.columns.push_back(r.string(column, "\"timeline\".\"columns\"[]"));
    if (!value.contains("rows")) r.fail("\"timeline\"", "has no \"rows\"");
    const Json& rows = r.array(value["rows"], "\"timeline\".\"rows\"");
    for (size_t i = 0; i < rows.size(); ++i) {
        const std::string where = fmt::format("\"timeline\".\"rows\"[{}]", i);
        const Json& row = r.array(rows[i], where);
        if (row.size() != t.columns.size())
            r.fail(where,
                   fmt::format("has {} values for {} columns", row.size(), t.columns.size()));
        std::vector<double>& values = t.rows.emplace_back();
        for (const Json& v : row)
            values.push_back(v.is_null() ? std::numeric_limits<double>::quiet_NaN()
                                         : r.number(v, where));
    }
    return t;
}

Profile read_profile(const Reader& r, const Json& value) {
    r.object(value, "\"profile\"");
    Profile p;
    if (value.contains("total_cycles"))
        p.total_cycles = r.number(value["total_cycles"], "\"profile\".\"total_cycles\"");
    for (const char* list : {"functions", "lines"}) {
        if (!value.contains(list)) continue;
        const std::string where = "\"profile\"." + in_quotes(list);
        const Json& entries = r.array(value[list], where);
        std::vector<ProfileEntry>& out = list == std::string_view("lines") ? p.lines : p.functions;
        for (size_t i = 0; i < entries.size(); ++i)
            out.push_back(read_profile_entry(r, entries[i], fmt::format("{}[{}]", where, i),
                                             &out == &p.lines));
    }
    return p;
}

/// Version 1 was one flat object of statistics, without "format" or "version".
bool looks_like_version_1(const Json& document) {
    return !document.empty() && document.contains("instructions/total") &&
           std::all_of(document.begin(), document.end(),
                       [](const Json& v) { return v.is_number() || v.is_null(); });
}

}  // namespace

std::optional<size_t> Timeline::column(std::string_view name) const {
    for (size_t i = 0; i < columns.size(); ++i)
        if (columns[i] == name) return i;
    return std::nullopt;
}

std::optional<double> StatsFile::stat(std::string_view name) const {
    const auto found = stat_index.find(name);
    if (found == stat_index.end()) return std::nullopt;
    return stats[found->second].second;
}

double StatsFile::interval(std::string_view name) const {
    const auto found = intervals.find(name);
    return found == intervals.end() ? 0.0 : found->second;
}

std::string StatsFile::unit(std::string_view name) const {
    const auto found = units.find(name);
    return found == units.end() ? std::string() : found->second;
}

std::string StatsFile::run_text(std::string_view key) const {
    const auto found = run.find(key);
    if (found == run.end() || found->is_null()) return "";
    return found->is_string() ? found->get<std::string>() : found->dump();
}

std::optional<std::filesystem::path> StatsFile::run_file(std::string_view key) const {
    const std::string name = run_text(key);
    if (name.empty()) return std::nullopt;
    return path.parent_path() / name;
}

StatsFile parse_stats_file(std::string_view text, const std::filesystem::path& path) {
    const std::string file = path.string();
    Json document;
    try {
        // The callback sees every value with its depth: a hostile file nested millions deep is
        // refused here, before anything walks it recursively.
        const auto bound_depth = [](int depth, nlohmann::json::parse_event_t, Json&) {
            if (depth > kMaxStatsDepth) throw TooDeep{};
            return true;
        };
        document = Json::parse(text.begin(), text.end(), bound_depth);
    } catch (const Json::parse_error& e) {
        throw Error(fmt::format("{} is not a tpsim statistics file: not JSON (syntax error at "
                                "byte {}); {}",
                                file, e.byte, kHowToGetOne));
    } catch (const TooDeep&) {
        throw Error(fmt::format("{} is not a tpsim statistics file: JSON nested more than {} "
                                "levels deep; {}",
                                file, kMaxStatsDepth, kHowToGetOne));
    }
    if (!document.is_object())
        throw Error(fmt::format("{} is not a tpsim statistics file: a JSON {}, not an object; {}",
                                file, document.type_name(), kHowToGetOne));
    if (!document.contains("format") && looks_like_version_1(document))
        throw Error(fmt::format("{} was written by statistics format version 1; this tpsim reads "
                                "version {}: render it again",
                                file, kStatsFormatVersion));
    if (!document.contains("format") || document["format"] != "tpsim-stats")
        throw Error(
            fmt::format("{} is not a tpsim statistics file ({} is not \"tpsim-stats\"); {}", file,
                        document.contains("format") ? "its \"format\" " + document["format"].dump()
                                                    : std::string("it has no \"format\", which"),
                        kHowToGetOne));
    const Json& version = document.contains("version") ? document["version"] : Json();
    if (!version.is_number_integer())
        throw Error(fmt::format("{}: \"version\" must be a whole number, got {}; the file is "
                                "damaged or was not written by tpsim",
                                file, version.dump()));
    if (version.get<int64_t>() != kStatsFormatVersion)
        throw Error(fmt::format("{} was written by statistics format version {}; this tpsim reads "
                                "version {}: render it again",
                                file, version.get<int64_t>(), kStatsFormatVersion));

    const Reader r(file);
    StatsFile f;
    f.path = path;
    if (!document.contains("run")) r.fail("the file", "has no \"run\"");
    f.run = r.object(document["run"], "\"run\"");
    if (!document.contains("stats")) r.fail("the file", "has no \"stats\"");
    for (const auto& [name, value] : r.object(document["stats"], "\"stats\"").items()) {
        const double number = value.is_null() ? std::numeric_limits<double>::quiet_NaN()
                                              : r.number(value, "\"stats\"." + in_quotes(name));
        f.stat_index.emplace(name, f.stats.size());
        f.stats.emplace_back(name, number);
    }
    if (document.contains("config"))
        for (const auto& [key, value] : r.object(document["config"], "\"config\"").items()) {
            if (value.is_structured())
                r.fail("\"config\"." + in_quotes(key), "must be a number, string or boolean");
            f.config.emplace_back(key, value);
        }
    if (document.contains("units"))
        for (const auto& [name, unit] : r.object(document["units"], "\"units\"").items())
            f.units.emplace(name, r.string(unit, "\"units\"." + in_quotes(name)));
    if (document.contains("regions"))
        for (const Json& region : r.array(document["regions"], "\"regions\""))
            f.regions.push_back(r.string(region, "\"regions\"[]"));
    if (document.contains("timeline")) f.timeline = read_timeline(r, document["timeline"]);
    if (document.contains("profile")) f.profile = read_profile(r, document["profile"]);
    if (document.contains("sampling")) f.sampling = r.object(document["sampling"], "\"sampling\"");
    if (document.contains("intervals"))
        for (const auto& [name, half] : r.object(document["intervals"], "\"intervals\"").items())
            f.intervals.emplace(name, half.is_null()  // unknown
                                          ? std::nan("")
                                          : r.number(half, "\"intervals\"." + in_quotes(name)));
    return f;
}

StatsFile load_stats_file(const std::filesystem::path& path) {
    const std::string file = path.string();
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec))
        throw Error(fmt::format("cannot read {}: it is a directory; {}", file, kHowToGetOne));
    const uintmax_t size = std::filesystem::file_size(path, ec);
    if (ec) throw Error(fmt::format("cannot read {}: {}; {}", file, ec.message(), kHowToGetOne));
    if (size > kMaxStatsFileBytes)
        throw Error(fmt::format("{} is not a tpsim statistics file: {} MiB, more than the {} MiB "
                                "this tpsim reads; {}",
                                file, (size + (1 << 20) - 1) >> 20, kMaxStatsFileBytes >> 20,
                                kHowToGetOne));
    std::ifstream in(path, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    if (!in) throw Error(fmt::format("cannot read {}; {}", file, kHowToGetOne));
    return parse_stats_file(text.str(), path);
}

}  // namespace tpsim::analysis
