#include "sim/render/profile.hpp"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <map>
#include <numeric>
#include <ostream>
#include <tuple>

#include <fmt/format.h>
#include <fmt/ostream.h>

#include "sim/core/error.hpp"

namespace tpsim::render {

ProfileCosts& ProfileCosts::operator+=(const ProfileCosts& other) {
    executions += other.executions;
    cycles += other.cycles;
    for (size_t cause = 0; cause < stalls.size(); ++cause)
        stalls[cause] += other.stalls[cause];
    l1_misses += other.l1_misses;
    dram_bytes += other.dram_bytes;
    return *this;
}

ProfileCosts costs_of(const timing::PcCounters& word) {
    ProfileCosts costs;
    costs.executions = word.executions;
    costs.stalls = word.stalls;
    costs.cycles = std::accumulate(word.stalls.begin(), word.stalls.end(), word.executions);
    costs.l1_misses = word.l1_misses;
    costs.dram_bytes = word.dram_bytes;
    return costs;
}

namespace {

bool has_costs(const ProfileCosts& c) {
    return c != ProfileCosts{};
}

/// The stall causes a profile shows: fetch_miss only with a finite I-cache (whose run always
/// has some, its cold misses), so that without one the profile is what it always was.
size_t shown_causes(const Profile& profile) {
    constexpr size_t kFetchMiss = size_t(timing::Stall::FetchMiss);
    static_assert(kFetchMiss + 1 == timing::kStallCauses, "fetch_miss is the last cause");
    return profile.total.stalls[kFetchMiss] != 0 ? timing::kStallCauses : kFetchMiss;
}

}  // namespace

Profile profile_of(const timing::PcProfile& words, const core::Program& program) {
    Profile profile;
    // Ordered maps: the roll-up must not depend on host hashing.
    std::map<uint32_t, FunctionProfile> functions;  // by symbol address; kUnknown at 0
    std::map<std::tuple<std::string, uint32_t, std::string>, LineProfile> lines;
    std::vector<uint32_t> pcs;  // of each entry of words.words
    for (const timing::TextRange& range : words.text)
        for (uint32_t word = 0; word < range.words; ++word)
            pcs.push_back(range.base + 4 * word);
    for (size_t index = 0; index < words.words.size(); ++index) {
        const ProfileCosts costs = costs_of(words.words[index]);
        if (!has_costs(costs)) continue;
        const uint32_t pc = pcs[index];
        profile.total += costs;

        const core::Symbol* symbol = program.function_at(pc);
        FunctionProfile& function = functions[symbol ? symbol->address : 0];
        if (function.function.empty()) {
            function.function = symbol ? core::demangle(symbol->name) : std::string(kUnknown);
            function.address = symbol ? symbol->address : 0;
        }
        function.costs += costs;

        LineProfile entry{std::string(kUnknown), "", 0, std::string(kUnknown), {}};
        if (const auto source = program.source_at(pc)) {
            const std::string in = program.source_function_at(pc);
            entry = {
                source->file, source->path, source->line, in.empty() ? entry.function : in, {}};
        }
        auto key = std::tuple(entry.path, entry.line, entry.function);
        lines.try_emplace(std::move(key), std::move(entry)).first->second.costs += costs;
    }

    for (auto& [address, function] : functions)
        profile.functions.push_back(std::move(function));
    std::stable_sort(profile.functions.begin(), profile.functions.end(),
                     [](const FunctionProfile& a, const FunctionProfile& b) {
                         return a.costs.cycles > b.costs.cycles;
                     });
    // The map already orders by path, line and function: a stable sort keeps that for ties.
    for (auto& [key, line] : lines)
        profile.lines.push_back(std::move(line));
    std::stable_sort(
        profile.lines.begin(), profile.lines.end(),
        [](const LineProfile& a, const LineProfile& b) { return a.costs.cycles > b.costs.cycles; });
    return profile;
}

namespace {

void put_costs(nlohmann::ordered_json& entry, const ProfileCosts& c, size_t causes) {
    entry["executions"] = c.executions;
    entry["cycles"] = c.cycles;
    nlohmann::ordered_json stalls = nlohmann::ordered_json::object();
    for (size_t cause = 0; cause < causes; ++cause)
        stalls[std::string(kStallNames[cause])] = c.stalls[cause];
    entry["stalls"] = std::move(stalls);
    entry["l1_misses"] = c.l1_misses;
    entry["dram_bytes"] = c.dram_bytes;
}

}  // namespace

nlohmann::ordered_json profile_json(const Profile& profile) {
    const size_t causes = shown_causes(profile);
    nlohmann::ordered_json functions = nlohmann::ordered_json::array();
    for (const FunctionProfile& f : profile.functions) {
        nlohmann::ordered_json entry{{"function", f.function}};
        put_costs(entry, f.costs, causes);
        functions.push_back(std::move(entry));
    }
    nlohmann::ordered_json lines = nlohmann::ordered_json::array();
    for (const LineProfile& l : profile.lines) {
        nlohmann::ordered_json entry{{"file", l.file}, {"line", l.line}, {"function", l.function}};
        put_costs(entry, l.costs, causes);
        lines.push_back(std::move(entry));
    }
    nlohmann::ordered_json json;
    json["total_cycles"] = profile.total.cycles;
    json["functions"] = std::move(functions);
    json["lines"] = std::move(lines);
    return json;
}

std::string short_function_name(std::string_view name) {
    // Walk the top level (outside <> and ()): the last "(" there opens the parameter list, the
    // last space before it ends the return type. "(anonymous namespace)" is not top level.
    int depth = 0;
    size_t start = 0, parameters = name.size();
    for (size_t i = 0; i < name.size(); ++i) {
        const char c = name[i];
        if (c == '(' && depth == 0 && i > 0) parameters = i;
        if (c == '<' || c == '(') ++depth;
        if ((c == '>' || c == ')') && depth > 0) --depth;
        if (c == ' ' && depth == 0 && parameters == name.size()) start = i + 1;
    }
    if (start >= parameters) start = 0;
    // Template arguments without their namespaces: "shade<BvhTraversal>".
    std::string shown;
    depth = 0;
    for (size_t i = start; i < parameters; ++i) {
        const char c = name[i];
        depth += c == '<' ? 1 : c == '>' ? -1 : 0;
        if (depth > 0 && c == ':' && i + 1 < parameters && name[i + 1] == ':') {
            if (shown.ends_with("(anonymous namespace)"))
                shown.resize(shown.size() - std::string_view("(anonymous namespace)").size());
            while (!shown.empty() &&
                   (std::isalnum((unsigned char)shown.back()) || shown.back() == '_'))
                shown.pop_back();
            ++i;
            continue;
        }
        shown += c;
    }
    return shown;
}

namespace {

double share(uint64_t part, uint64_t whole) {
    return whole == 0 ? 0.0 : 100.0 * double(part) / double(whole);
}

/// A count in at most 6 columns: exact below 10000, else three significant digits and a unit.
std::string compact(uint64_t value) {
    if (value < 10000) return fmt::format("{}", value);
    constexpr std::string_view kUnits = "kMGTPE";
    double scaled = double(value);
    size_t unit = 0;
    for (scaled /= 1000; scaled >= 999.5 && unit + 1 < kUnits.size(); ++unit)
        scaled /= 1000;
    const int decimals = scaled < 9.995 ? 2 : scaled < 99.95 ? 1 : 0;
    return fmt::format("{:.{}f}{}", scaled, decimals, kUnits[unit]);
}

/// Bytes in at most 7 columns ("512B", "12.3KiB", "1.21GiB").
std::string compact_bytes(uint64_t bytes) {
    if (bytes < 1024) return fmt::format("{}B", bytes);
    constexpr std::array<std::string_view, 6> kUnits = {"KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
    double scaled = double(bytes) / 1024;
    size_t unit = 0;
    for (; scaled >= 1023.5 && unit + 1 < kUnits.size(); ++unit)
        scaled /= 1024;
    const int decimals = scaled < 9.995 ? 2 : scaled < 99.95 ? 1 : 0;
    return fmt::format("{:.{}f}{}", scaled, decimals, kUnits[unit]);
}

/// Cut to `width` columns, marking the cut.
std::string fit(std::string text, size_t width) {
    if (text.size() > width) text = text.substr(0, width - 3) + "...";
    return text;
}

constexpr size_t kTopFunctions = 10, kTopLines = 15, kNameWidth = 38;

// With the fetch_miss column the names are 4 columns narrower: rows stay within 100 columns.
void print_table_row(std::ostream& out, const ProfileCosts& c, uint64_t total,
                     const std::string& name, size_t causes) {
    fmt::print(out, "{:5.1f}% {:>6} {:>6}", share(c.cycles, total), compact(c.cycles),
               compact(c.executions));
    for (size_t cause = 0; cause < causes; ++cause)
        if (const uint64_t stall = c.stalls[cause]; stall == 0)
            fmt::print(out, " {:>3}", "-");
        else
            fmt::print(out, " {:>2.0f}%", share(stall, c.cycles));
    fmt::print(out, " {:>6} {:>7}  {}\n", compact(c.l1_misses), compact_bytes(c.dram_bytes),
               fit(name, causes == timing::kStallCauses ? kNameWidth - 4 : kNameWidth));
}

/// The short name's last two scopes ("BvhTraversal::trace<false>"): beside a file:line the
/// outer namespaces say nothing new.
std::string innermost_scopes(std::string_view function) {
    const std::string name = short_function_name(function);
    int depth = 0;
    size_t scopes = 0;
    for (size_t i = name.size(); i-- > 1;) {
        depth += name[i] == '>' ? 1 : name[i] == '<' ? -1 : 0;
        if (depth == 0 && name[i] == ':' && name[i - 1] == ':' && ++scopes == 2)
            return name.substr(i + 1);
    }
    return name;
}

void print_table_head(std::ostream& out, const std::string& what, size_t causes) {
    fmt::print(out, " share cycles  execs fet brn  fu mem opd syn{} L1miss    DRAM  {}\n",
               causes == timing::kStallCauses ? " fmi" : "", what);
}

}  // namespace

void print_profile(const Profile& p, std::ostream& out) {
    const uint64_t total = p.total.cycles;
    const size_t causes = shown_causes(p);
    fmt::print(out,
               "profile  {} TP-cycles charged (issues + stalls), {} executions, {} L1 misses,\n"
               "         {} DRAM; stalls in % of the entry's cycles: fet fetch conflict,\n"
               "         brn branch, fu FU busy, mem memory port, opd operand, syn sync{}\n",
               total, p.total.executions, p.total.l1_misses, compact_bytes(p.total.dram_bytes),
               causes == timing::kStallCauses ? ",\n         fmi I-cache fetch miss" : "");
    print_table_head(out,
                     fmt::format("function (top {} of {})",
                                 std::min(kTopFunctions, p.functions.size()), p.functions.size()),
                     causes);
    for (size_t i = 0; i < std::min(kTopFunctions, p.functions.size()); ++i)
        print_table_row(out, p.functions[i].costs, total,
                        short_function_name(p.functions[i].function), causes);
    print_table_head(
        out,
        fmt::format("line (top {} of {})", std::min(kTopLines, p.lines.size()), p.lines.size()),
        causes);
    for (size_t i = 0; i < std::min(kTopLines, p.lines.size()); ++i) {
        const LineProfile& l = p.lines[i];
        print_table_row(out, l.costs, total,
                        l.path.empty()
                            ? std::string(kUnknown)
                            : fmt::format("{}:{} {}", l.file, l.line, innermost_scopes(l.function)),
                        causes);
    }
}

namespace {

/// One source line's costs in the listing (all functions it appears in together).
struct ListedLine {
    ProfileCosts costs;
    size_t rank = 0;  ///< 1 = hottest line of the profile; 0 = not among the ranked ones
};

struct ListedFile {
    std::string path;
    ProfileCosts costs;
    std::map<uint32_t, ListedLine> lines;
};

constexpr size_t kRankedLines = 10;
/// Lines shown around each line with costs; longer cost-free stretches are cut to one marker
/// line unless the cut would hide fewer than kShortestCut lines.
constexpr size_t kContext = 3, kShortestCut = 3;

std::vector<ListedFile> listed_files(const Profile& profile) {
    std::map<std::string, ListedFile> by_path;
    for (const LineProfile& l : profile.lines) {
        if (l.path.empty()) continue;  // kUnknown: no source to show
        ListedFile& file = by_path[l.path];
        file.path = l.path;
        file.costs += l.costs;
        file.lines[l.line].costs += l.costs;
    }
    std::vector<ListedLine*> ranking;
    for (auto& [path, file] : by_path)
        for (auto& [number, line] : file.lines)
            ranking.push_back(&line);
    // Ties stay in path and line order.
    std::stable_sort(ranking.begin(), ranking.end(), [](const ListedLine* a, const ListedLine* b) {
        return a->costs.cycles > b->costs.cycles;
    });
    for (size_t i = 0; i < std::min(kRankedLines, ranking.size()); ++i)
        ranking[i]->rank = i + 1;

    std::vector<ListedFile> files;
    for (auto& [path, file] : by_path)
        files.push_back(std::move(file));
    std::stable_sort(files.begin(), files.end(), [](const ListedFile& a, const ListedFile& b) {
        return a.costs.cycles > b.costs.cycles;
    });
    return files;
}

std::string margin(const ListedLine* line, uint64_t total) {
    if (!line) return fmt::format("{:26} |", "");
    const std::string rank = line->rank ? fmt::format("#{}", line->rank) : "";
    return fmt::format("{:6.2f} {:>6} {:>7} {:>4} |", share(line->costs.cycles, total),
                       compact(line->costs.l1_misses), compact_bytes(line->costs.dram_bytes), rank);
}

void write_file_section(std::ostream& out, const ListedFile& file, uint64_t total) {
    fmt::print(out, "\n==== {}: {:.2f} % of the cycles, {} L1 misses, {} DRAM ====\n", file.path,
               share(file.costs.cycles, total), file.costs.l1_misses,
               compact_bytes(file.costs.dram_bytes));
    fmt::print(out, "cycles L1miss    DRAM rank | {:>5}  source\n", "line");
    std::vector<std::string> source;
    std::ifstream in(file.path);
    for (std::string text; in && std::getline(in, text);)
        source.push_back(std::move(text));
    if (source.empty()) {
        fmt::print(out, "(source not found: cannot read {}; the costs of its lines follow)\n",
                   file.path);
        for (const auto& [number, line] : file.lines)
            fmt::print(out, "{} {:5}\n", margin(&line, total), number);
        return;
    }
    const auto listed = [&](size_t number) {
        auto it = file.lines.find(uint32_t(number));
        return it == file.lines.end() ? nullptr : &it->second;
    };
    // Distance from each line to the nearest line with costs decides what is cut.
    const size_t count = source.size();
    std::vector<size_t> distance(count + 2, count + 2);
    for (size_t n = 1, last = 0; n <= count; ++n) {
        if (listed(n)) last = n;
        if (last) distance[n] = n - last;
    }
    for (size_t n = count, next = 0; n >= 1; --n) {
        if (listed(n)) next = n;
        if (next) distance[n] = std::min(distance[n], next - n);
    }
    for (size_t n = 1; n <= count;) {
        size_t end = n;
        while (end <= count && distance[end] > kContext)
            ++end;
        if (end - n >= kShortestCut) {
            fmt::print(out, "{} {:>5}  ... lines {}-{} without costs ...\n", margin(nullptr, 0), "",
                       n, end - 1);
            n = end;
            continue;
        }
        fmt::print(out, "{} {:5}  {}\n", margin(listed(n), total), n, source[n - 1]);
        ++n;
    }
    for (auto it = file.lines.upper_bound(uint32_t(count)); it != file.lines.end(); ++it)
        fmt::print(out, "{} {:5}  (beyond the end of the file: it changed since the build)\n",
                   margin(&it->second, total), it->first);
}

}  // namespace

void write_annotated_listing(const std::filesystem::path& path, const Profile& profile,
                             const std::string& kernel) {
    std::ofstream out(path);
    if (!out)
        throw Error(fmt::format("cannot write the annotated listing '{}': the directory does not "
                                "exist or is not writable; give a writable path",
                                path.string()));
    const uint64_t total = profile.total.cycles;
    fmt::print(out, "tpsim annotated source of {}\n", kernel);
    fmt::print(out, "{} TP-cycles charged (issues + stalls) = 100 %, {} L1 misses, {} DRAM\n",
               total, profile.total.l1_misses, compact_bytes(profile.total.dram_bytes));
    for (const LineProfile& l : profile.lines)
        if (l.path.empty())
            fmt::print(out, "{}: {:.2f} % of the cycles at addresses without a source line\n",
                       kUnknown, share(l.costs.cycles, total));
    const std::vector<ListedFile> files = listed_files(profile);
    fmt::print(out, "\nfiles by cycles:\n");
    for (const ListedFile& f : files)
        fmt::print(out, "{:7.2f} %  {}\n", share(f.costs.cycles, total), f.path);
    fmt::print(out,
               "\nmargin: the line's % of the cycles, its L1 misses and DRAM bytes, and its "
               "rank\namong the {} hottest lines\n",
               kRankedLines);
    for (const ListedFile& f : files)
        write_file_section(out, f, total);
    if (!out.flush())
        throw Error(fmt::format("cannot write the annotated listing '{}': write failed (disk "
                                "full?)",
                                path.string()));
}

}  // namespace tpsim::render
