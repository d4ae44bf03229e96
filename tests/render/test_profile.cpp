// The source-line profile over the real tracer kernel, with synthetic per-word costs: roll-ups
// that add up exactly, inlined code on its own line, the JSON object, the report section and the
// annotated listing.
#include <algorithm>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <tuple>

#include <catch2/catch.hpp>
#include <fmt/format.h>

#include "sim/core/error.hpp"
#include "sim/render/profile.hpp"
#include "tests/scratch.hpp"

using namespace tpsim;
using tpsim::testing::scratch_path;

namespace {

const core::Program& tracer() {
    static const core::Program program =
        core::load_elf(std::string(TPSIM_KERNEL_DIR) + "/tracer.elf");
    return program;
}

const core::Segment& text_of(const core::Program& program) {
    for (const core::Segment& s : program.segments)
        if (s.executable) return s;
    FAIL("no executable segment");
    throw;
}

/// Every word of the text costed, each differently: executions = word index + 1, and stalls,
/// misses and bytes that vary independently of it; fetch-miss stalls (a finite I-cache's) only
/// if `fetch_misses`.
timing::PcProfile synthetic_profile(const core::Program& program, bool fetch_misses = true) {
    const core::Segment& text = text_of(program);
    timing::PcProfile profile;
    profile.text = {{text.vaddr, text.memsz / 4}};
    profile.words.resize(text.memsz / 4);
    for (size_t i = 0; i < profile.words.size(); ++i) {
        timing::PcCounters& w = profile.words[i];
        w.executions = i + 1;
        for (size_t cause = 0; cause < timing::kStallCauses; ++cause)
            w.stalls[cause] = (i * (cause + 3)) % 17;
        if (!fetch_misses) w.stalls[size_t(timing::Stall::FetchMiss)] = 0;
        w.l1_misses = i % 3;
        w.dram_bytes = (i % 5) * 32;
    }
    return profile;
}

/// The profile with one word costed.
timing::PcProfile single_word(const core::Program& program, uint32_t pc, uint64_t executions) {
    const core::Segment& text = text_of(program);
    timing::PcProfile profile;
    profile.text = {{text.vaddr, text.memsz / 4}};
    profile.words.resize(text.memsz / 4);
    timing::PcCounters& w = profile.words[(pc - text.vaddr) / 4];
    w.executions = executions;
    w.stalls[size_t(timing::Stall::Operand)] = 3 * executions;
    w.l1_misses = 7;
    w.dram_bytes = 7 * 64;
    return profile;
}

template <typename Entries> render::ProfileCosts sum(const Entries& entries) {
    render::ProfileCosts total;
    for (const auto& e : entries)
        total += e.costs;
    return total;
}

std::string read_text(const std::filesystem::path& path) {
    std::ifstream in(path);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
}

}  // namespace

TEST_CASE("profile: function and line roll-ups add up to the totals exactly", "[profile]") {
    const timing::PcProfile words = synthetic_profile(tracer());
    const render::Profile p = render::profile_of(words, tracer());

    render::ProfileCosts expected;
    for (const timing::PcCounters& w : words.words)
        expected += render::costs_of(w);
    CHECK(p.total == expected);
    CHECK(p.total.executions == words.words.size() * (words.words.size() + 1) / 2);
    CHECK(sum(p.functions) == p.total);
    CHECK(sum(p.lines) == p.total);
    // Every cycle is an issue or a stall.
    for (const render::FunctionProfile& f : p.functions) {
        uint64_t stalls = 0;
        for (uint64_t s : f.costs.stalls)
            stalls += s;
        CHECK(f.costs.cycles == f.costs.executions + stalls);
    }
    // The tracer's functions are all there, hottest first; lines come from several files.
    CHECK(p.functions.size() >= tracer().functions.size());
    for (size_t i = 1; i < p.functions.size(); ++i)
        CHECK(p.functions[i - 1].costs.cycles >= p.functions[i].costs.cycles);
    for (size_t i = 1; i < p.lines.size(); ++i)
        CHECK(p.lines[i - 1].costs.cycles >= p.lines[i].costs.cycles);
    std::set<std::string> files;
    for (const render::LineProfile& l : p.lines)
        files.insert(l.file);
    CHECK(files.count("rt.hpp") == 1);
    CHECK(files.count("trax.hpp") == 1);
}

TEST_CASE("profile: ties are ordered by address and by file and line", "[profile]") {
    // All words cost the same: the order is the tie-break alone.
    timing::PcProfile words = synthetic_profile(tracer());
    for (timing::PcCounters& w : words.words)
        w = timing::PcCounters{1, {}, 0, 0};
    const render::Profile p = render::profile_of(words, tracer());
    for (size_t i = 1; i < p.functions.size(); ++i) {
        const auto &a = p.functions[i - 1], &b = p.functions[i];
        if (a.costs.cycles == b.costs.cycles) CHECK(a.address < b.address);
    }
    for (size_t i = 1; i < p.lines.size(); ++i) {
        const auto &a = p.lines[i - 1], &b = p.lines[i];
        if (a.costs.cycles == b.costs.cycles)
            CHECK(std::tie(a.path, a.line, a.function) < std::tie(b.path, b.line, b.function));
    }
    CHECK(render::profile_json(render::profile_of(words, tracer())) == render::profile_json(p));
}

TEST_CASE("profile: inlined code is charged to the helper's own line", "[profile]") {
    const core::Program& program = tracer();
    const core::Segment& text = text_of(program);
    // A word of a kernel-API helper (trax.hpp) inlined into one of the tracer's functions.
    uint32_t pc = 0;
    for (uint32_t at = text.vaddr; at < text.end() && pc == 0; at += 4) {
        const auto source = program.source_at(at);
        if (source && source->file == "trax.hpp" && !program.inlined_call_sites(at).empty() &&
            program.function_at(at))
            pc = at;
    }
    REQUIRE(pc != 0);
    const auto source = program.source_at(pc);
    const std::string caller = core::demangle(program.function_at(pc)->name);
    INFO("pc " << std::hex << pc << " " << source->file << ":" << std::dec << source->line << " in "
               << caller);

    const render::Profile p = render::profile_of(single_word(program, pc, 100), program);
    REQUIRE(p.lines.size() == 1);
    const render::LineProfile& line = p.lines[0];
    CHECK(line.file == "trax.hpp");
    CHECK(line.line == source->line);
    CHECK(line.path == source->path);
    CHECK(line.costs.cycles == 400);
    CHECK(line.costs.l1_misses == 7);
    // The line names the helper it is in; the function roll-up charges the caller's symbol.
    CHECK(line.function == program.source_function_at(pc));
    CHECK(line.function != caller);
    REQUIRE(p.functions.size() == 1);
    CHECK(p.functions[0].function == caller);
    CHECK(p.functions[0].costs == line.costs);
}

TEST_CASE("profile: the loader keeps full source paths", "[profile]") {
    const core::Program& program = tracer();
    const auto source = program.source_at(program.entry);
    REQUIRE(source);
    CHECK(std::filesystem::path(source->path).is_absolute());
    CHECK(std::filesystem::path(source->path).filename() == source->file);
    // The kernels were built from this tree, so their sources are here.
    for (const core::Program::SourceFile& f : program.line_files)
        if (f.file == "rt.hpp")
            CHECK(std::filesystem::equivalent(f.path,
                                              std::string(TPSIM_SOURCE_DIR) + "/kernel/rt.hpp"));
}

TEST_CASE("profile: words without a function or a line go to one (unknown) entry", "[profile]") {
    const core::Program& program = tracer();
    timing::PcProfile words = single_word(program, program.entry, 5);
    // Past the end of the text: no symbol, no line.
    words.text.front().words += 8;
    words.words.resize(words.words.size() + 8);
    words.words.back().executions = 11;
    words.words[words.words.size() - 2].executions = 13;
    const render::Profile p = render::profile_of(words, program);
    REQUIRE(p.functions.size() == 2);
    CHECK(p.functions[0].function == render::kUnknown);
    CHECK(p.functions[0].costs.executions == 24);
    REQUIRE(p.lines.size() == 2);
    CHECK(p.lines[0].file == render::kUnknown);
    CHECK(p.lines[0].line == 0);
    CHECK(p.lines[0].costs.executions == 24);
    CHECK(sum(p.lines) == p.total);
}

TEST_CASE("profile: the JSON object has the statistics file's shape", "[profile]") {
    for (const bool fetch_misses : {true, false}) {
        INFO("fetch misses " << fetch_misses);
        const render::Profile p =
            render::profile_of(synthetic_profile(tracer(), fetch_misses), tracer());
        const nlohmann::ordered_json json = render::profile_json(p);
        std::vector<std::string> keys;
        for (const auto& [key, value] : json.items())
            keys.push_back(key);
        CHECK(keys == std::vector<std::string>{"total_cycles", "functions", "lines"});
        CHECK(json["total_cycles"] == p.total.cycles);
        REQUIRE(json["functions"].size() == p.functions.size());
        REQUIRE(json["lines"].size() == p.lines.size());

        const auto& top = json["functions"][0];
        std::vector<std::string> entry_keys;
        for (const auto& [key, value] : top.items())
            entry_keys.push_back(key);
        CHECK(entry_keys == std::vector<std::string>{"function", "executions", "cycles", "stalls",
                                                     "l1_misses", "dram_bytes"});
        CHECK(top["function"] == p.functions[0].function);
        CHECK(top["cycles"] == p.functions[0].costs.cycles);
        size_t cause = 0;
        for (const auto& [name, value] : top["stalls"].items()) {
            CHECK(name == render::kStallNames[cause]);
            CHECK(value == p.functions[0].costs.stalls[cause]);
            ++cause;
        }
        // fetch_miss (the last cause) only with fetch-miss stalls, i.e. with a finite I-cache.
        CHECK(cause == (fetch_misses ? timing::kStallCauses : size_t(timing::Stall::FetchMiss)));

        const auto& line = json["lines"][0];
        std::vector<std::string> line_keys;
        for (const auto& [key, value] : line.items())
            line_keys.push_back(key);
        CHECK(line_keys == std::vector<std::string>{"file", "line", "function", "executions",
                                                    "cycles", "stalls", "l1_misses", "dram_bytes"});
        CHECK(line["file"] == p.lines[0].file);
        CHECK(line["line"] == p.lines[0].line);
        uint64_t cycles = 0;
        for (const auto& l : json["lines"])
            cycles += l["cycles"].get<uint64_t>();
        CHECK(cycles == json["total_cycles"]);
    }
}

TEST_CASE("profile: the report section names the hottest entries in 100 columns", "[profile]") {
    // With fetch-miss stalls (a finite I-cache) one more stall column, and its name in the head.
    for (const bool fetch_misses : {false, true}) {
        INFO("fetch misses " << fetch_misses);
        const render::Profile p =
            render::profile_of(synthetic_profile(tracer(), fetch_misses), tracer());
        std::ostringstream out;
        render::print_profile(p, out);
        const std::string text = out.str();
        INFO(text);
        std::istringstream lines(text);
        size_t rows = 0;
        for (std::string row; std::getline(lines, row); ++rows)
            CHECK(row.size() <= 100);
        // A head of three lines (four with fetch misses), two table heads, 10 functions (or all)
        // and 15 lines.
        CHECK(rows == (fetch_misses ? 4 : 3) + 2 + std::min<size_t>(10, p.functions.size()) + 15);
        CHECK(text.find(std::to_string(p.total.cycles)) != std::string::npos);
        CHECK((text.find(" fmi ") != std::string::npos) == fetch_misses);
        // Names take 38 columns, 34 beside the fetch-miss column (cut with "...").
        std::string name = render::short_function_name(p.functions[0].function);
        if (fetch_misses && name.size() > 34) name = name.substr(0, 31) + "...";
        CHECK(text.find(name) != std::string::npos);
        // The head names every column: its "function" stands above the rows' names, one stall
        // column per cause between them.
        const size_t head = text.find("function (top");
        const size_t line_start = text.rfind('\n', head) + 1;
        const size_t row_start = text.find('\n', head) + 1;
        CHECK(head - line_start == text.find(name, row_start) - row_start);
        const std::string hottest_line =
            p.lines[0].file + ":" + std::to_string(p.lines[0].line) + " ";
        CHECK(text.find(hottest_line) != std::string::npos);
    }
}

TEST_CASE("profile: short function names drop return types, parameters and namespaces of "
          "template arguments",
          "[profile]") {
    using render::short_function_name;
    CHECK(short_function_name("trax::rt::Hit trax::rt::BvhTraversal::trace<false>(trax::rt::Vec3, "
                              "float) const") == "trax::rt::BvhTraversal::trace<false>");
    CHECK(short_function_name("void trax::rt::render_image<trax::rt::BvhTraversal>(trax::rt::"
                              "BvhTraversal const&)") == "trax::rt::render_image<BvhTraversal>");
    CHECK(short_function_name("(anonymous namespace)::depth(int)") ==
          "(anonymous namespace)::depth");
    CHECK(short_function_name("void f<(anonymous namespace)::Tag, 3>(int)") == "f<Tag, 3>");
    CHECK(short_function_name("trax_main") == "trax_main");
    CHECK(short_function_name(render::kUnknown) == render::kUnknown);
}

TEST_CASE("profile: the annotated listing shows lines with their shares", "[profile]") {
    const render::Profile p = render::profile_of(synthetic_profile(tracer()), tracer());
    const auto path = scratch_path("tracer.annotate.txt");
    render::write_annotated_listing(path, p, "tracer.elf");
    const std::string listing = read_text(path);

    // The hottest line: its file's section, its number, its source text and share, rank #1.
    const render::LineProfile& hot = p.lines[0];
    REQUIRE(!hot.path.empty());
    CHECK(listing.find("==== " + hot.path + ":") != std::string::npos);
    std::ifstream source(hot.path);
    std::string text;
    for (uint32_t n = 0; n < hot.line; ++n)
        std::getline(source, text);
    uint64_t line_cycles = 0;  // the listing merges the functions a line is in
    for (const render::LineProfile& l : p.lines)
        if (l.path == hot.path && l.line == hot.line) line_cycles += l.costs.cycles;
    const std::string share = fmt::format("{:6.2f}", 100.0 * line_cycles / p.total.cycles);
    std::istringstream rows(listing);
    bool found = false;
    for (std::string row; std::getline(rows, row);)
        if (row.find(fmt::format("| {:5}  {}", hot.line, text)) != std::string::npos) {
            found = true;
            CHECK(row.rfind(share, 0) == 0);
        }
    CHECK(found);
    CHECK(listing.find("#1 |") != std::string::npos);
    CHECK(listing.find("#10 |") != std::string::npos);
    CHECK(listing.find("#11 |") == std::string::npos);
    // Every file with costs has a section, hottest file first.
    std::map<std::string, uint64_t> file_cycles;
    for (const render::LineProfile& l : p.lines)
        if (!l.path.empty()) file_cycles[l.path] += l.costs.cycles;
    std::vector<std::pair<size_t, uint64_t>> sections;  // (position in the listing, cycles)
    for (const auto& [file, cycles] : file_cycles) {
        const size_t at = listing.find("==== " + file + ":");
        REQUIRE(at != std::string::npos);
        sections.push_back({at, cycles});
    }
    std::sort(sections.begin(), sections.end());
    for (size_t i = 1; i < sections.size(); ++i)
        CHECK(sections[i - 1].second >= sections[i].second);
}

TEST_CASE("profile: a missing source file is a note in the listing", "[profile]") {
    render::Profile p;
    render::LineProfile gone{"gone.hpp", "/nonexistent/tpsim/gone.hpp", 42, "f", {}};
    gone.costs.executions = gone.costs.cycles = 10;
    p.lines.push_back(gone);
    p.total = gone.costs;
    const auto path = scratch_path("gone.annotate.txt");
    REQUIRE_NOTHROW(render::write_annotated_listing(path, p, "k.elf"));
    const std::string listing = read_text(path);
    CHECK(listing.find("source not found: cannot read /nonexistent/tpsim/gone.hpp") !=
          std::string::npos);
    CHECK(listing.find("100.00") != std::string::npos);
    CHECK(listing.find("|    42") != std::string::npos);
}

TEST_CASE("profile: a listing to a bad path is an error naming it", "[profile]") {
    const render::Profile p = render::profile_of(synthetic_profile(tracer()), tracer());
    try {
        render::write_annotated_listing("/nonexistent/tpsim/x.txt", p, "tracer.elf");
        FAIL("no error");
    } catch (const Error& e) {
        CHECK(std::string(e.what()).find("/nonexistent/tpsim/x.txt") != std::string::npos);
    }
}
