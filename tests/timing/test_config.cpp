#include "sim/timing/config.hpp"

#include <catch2/catch.hpp>

#include <algorithm>

#include "sim/core/input_file.hpp"
#include "sim/core/toml_nesting.hpp"

using namespace tpsim::timing;
using Catch::Contains;

namespace {
const std::string kConfigs = TPSIM_CONFIG_DIR;
}

TEST_CASE("the trax preset spells out exactly the built-in defaults", "[config]") {
    CHECK(load_config(kConfigs + "/trax.toml") == ChipConfig{});
    CHECK_NOTHROW(validate(ChipConfig{}));
}

TEST_CASE("the tiny preset is 1 TM x 4 TPs and keeps unlisted defaults", "[config]") {
    const ChipConfig tiny = load_config(kConfigs + "/tiny.toml");
    CHECK(tiny.chip.num_tms == 1);
    CHECK(tiny.chip.tps_per_tm == 4);
    CHECK(tiny.l1.size_bytes == 1024);
    CHECK_FALSE(tiny.fu.fp_divsqrt.pipelined);
    CHECK(tiny.dram.tRCD == ChipConfig{}.dram.tRCD);
    CHECK(tiny.num_l2() == 1);
}

TEST_CASE("errors name the source line, the key and the allowed range", "[config]") {
    CHECK_THROWS_WITH(parse_config("[l1]\nsize_bytes = 32768\nways = 0\n", "x.toml"),
                      Contains("x.toml:3") && Contains("l1.ways = 0") && Contains("allowed 1..64"));
    CHECK_THROWS_WITH(parse_config("[l1]\nsise_bytes = 1\n", "x.toml"),
                      Contains("x.toml:2") && Contains("unknown key 'l1.sise_bytes'"));
    CHECK_THROWS_WITH(parse_config("[fu.fp_add]\npipelined = 3\n", "x.toml"),
                      Contains("fu.fp_add.pipelined must be true or false"));
    CHECK_THROWS_WITH(parse_config("[dram]\ntCL = \"fast\"\n", "x.toml"),
                      Contains("dram.tCL must be an integer in 1..1000"));
    CHECK_THROWS_WITH(parse_config("[chip\n", "x.toml"), Contains("x.toml:1"));
    CHECK_THROWS_WITH(load_config("/nonexistent/chip.toml"), Contains("/nonexistent/chip.toml"));
}

TEST_CASE("cross-field rules are checked", "[config]") {
    CHECK_THROWS_WITH(parse_config("[l1]\nsize_bytes = 3000\n", "x.toml"),
                      Contains("l1.size_bytes = 3000 must be a power-of-two multiple"));
    CHECK_THROWS_WITH(parse_config("[l2]\nline_bytes = 128\n", "x.toml"),
                      Contains("must equal l1.line_bytes"));
    CHECK_THROWS_WITH(parse_config("[l1]\nline_bytes = 48\n", "x.toml"), Contains("power of two"));
    CHECK_THROWS_WITH(parse_config("[dram]\ntRAS = 5\n", "x.toml"), Contains("dram.tRAS"));
    // A finite I-cache's geometry is checked as the data caches'; with size_bytes = 0 (never
    // misses) its other fields take no part.
    CHECK_THROWS_WITH(parse_config("[icache]\nsize_bytes = 3000\n", "x.toml"),
                      Contains("icache.size_bytes = 3000 must be a power-of-two multiple"));
    CHECK_THROWS_WITH(parse_config("[icache]\nsize_bytes = 4096\nline_bytes = 128\n", "x.toml"),
                      Contains("icache.line_bytes = 128 must equal l1.line_bytes = 64"));
    CHECK_NOTHROW(parse_config("[icache]\nsize_bytes = 0\nline_bytes = 128\n", "x.toml"));
    CHECK_NOTHROW(parse_config("[icache]\nsize_bytes = 1024\nways = 16\n", "x.toml"));
}

TEST_CASE("a chip that needs too much host memory is refused with the figure and the field",
          "[config]") {
    ChipConfig big;
    big.chip.num_tms = 64;
    big.l1.size_bytes = 1u << 30;
    // 64 TMs x 2^24 lines x 16 bytes: 16 GiB of L1 tags.
    CHECK(host_bytes(big).front().bytes == uint64_t(16) << 30);
    CHECK_THROWS_WITH(validate(big), Contains("needs about 16.0 GiB of host memory") &&
                                         Contains("reduce l1.size_bytes"));
    big.chip.num_tms = 16;  // 4 GiB of L1 tags: allowed
    CHECK_NOTHROW(validate(big));
    CHECK_THROWS_WITH(apply_override(big, "chip.num_tms=64"), Contains("l1.size_bytes"));
    // The I-caches' tags count too: 2 per TM of 32 TPs, 2^24 lines each, 16 TMs: 8 GiB more.
    big.icache.size_bytes = 1u << 30;
    CHECK_THROWS_WITH(validate(big), Contains("reduce icache.size_bytes"));
}

TEST_CASE("overrides set one field with the same validation", "[config]") {
    ChipConfig c;
    apply_override(c, "l1.size_bytes=16384");
    CHECK(c.l1.size_bytes == 16384);
    apply_override(c, "fu.fp_divsqrt.pipelined = false");
    CHECK_FALSE(c.fu.fp_divsqrt.pipelined);
    apply_override(c, "chip.num_tms=0x10");
    CHECK(c.chip.num_tms == 16);
    const ChipConfig before = c;
    CHECK_THROWS_WITH(apply_override(c, "l1.ways=65"),
                      Contains("override 'l1.ways=65'") && Contains("allowed 1..64"));
    CHECK_THROWS_WITH(apply_override(c, "l1.ways"), Contains("expected key=value"));
    CHECK_THROWS_WITH(apply_override(c, "l1.wayz=2"), Contains("unknown key 'l1.wayz'"));
    CHECK_THROWS_WITH(apply_override(c, "l1.ways=two"), Contains("must be an integer"));
    CHECK_THROWS_WITH(apply_override(c, "l1.ways=-1"), Contains("out of range"));
    CHECK_THROWS_WITH(apply_override(c, "l1.size_bytes=1000"), Contains("power-of-two"));
    CHECK(c == before);  // a rejected override leaves the config untouched
}

TEST_CASE("overrides are validated together, after all of them are applied", "[config]") {
    // tRAS must be >= tRCD: raising both is one valid change, refused if checked one at a time.
    ChipConfig c;
    const std::vector<std::string> both = {"dram.tRCD=36", "dram.tRAS=84"};
    apply_overrides(c, both);
    CHECK(c.dram.tRCD == 36);
    CHECK(c.dram.tRAS == 84);
    // A list that stays invalid is refused whole, naming every override, the config untouched.
    ChipConfig d;
    const std::vector<std::string> bad = {"dram.tRAS=84", "dram.tRCD=90"};
    CHECK_THROWS_WITH(apply_overrides(d, bad),
                      Contains("overrides 'dram.tRAS=84', 'dram.tRCD=90'") &&
                          Contains("dram.tRAS = 84 must be >= dram.tRCD = 90"));
    CHECK(d == ChipConfig{});
}

TEST_CASE("the printed config lists every key and parses back to the same config", "[config]") {
    ChipConfig c;
    apply_override(c, "dram.tCL=20");
    apply_override(c, "fu.atomic.pipelined=false");
    apply_override(c, "l2.write_combining_lines=8");
    apply_override(c, "icache.size_bytes=4096");
    const std::string text = to_toml(c);
    const std::vector<ConfigField> fields = config_fields(c);
    for (const ConfigField& field : fields) {
        const std::string leaf = field.key.substr(field.key.rfind('.') + 1);
        CHECK(text.find(leaf) != std::string::npos);
    }
    CHECK(parse_config(text, "printed") == c);
    CHECK(fields.size() == 4 + 4 + 9 * 3 + 6 + 2 * 6 + 1 + 15 + 3 + 20 + 16);
    // The fields carry the resolved values, bools as 0/1.
    const auto field = [&](std::string_view key) {
        return *std::find_if(fields.begin(), fields.end(),
                             [&](const ConfigField& f) { return f.key == key; });
    };
    CHECK(field("dram.tCL").value == 20);
    CHECK_FALSE(field("dram.tCL").is_bool);
    CHECK(field("fu.atomic.pipelined").is_bool);
    CHECK(field("fu.atomic.pipelined").value == 0);
}

TEST_CASE("TOML nesting is bounded before toml++ parses the text", "[config][nesting]") {
    const auto deep = [](const std::string& open, const std::string& close, int levels,
                         const std::string& middle) {
        std::string text;
        for (int i = 0; i < levels; ++i)
            text += open;
        text += middle;
        for (int i = 0; i < levels; ++i)
            text += close;
        return text + "\n";
    };
    // Each way of nesting, at the limit and one past it.
    const int limit = tpsim::kMaxTomlNesting;
    std::string dotted_ok;  // limit - 1 dots: a key `limit` parts long
    for (int i = 1; i < limit; ++i)
        dotted_ok += "a.";
    const std::string dotted_deep = dotted_ok + "a.";
    CHECK_NOTHROW(tpsim::check_toml_nesting(dotted_ok + "a = 1\n", "ok.toml"));
    CHECK_THROWS_WITH(tpsim::check_toml_nesting("\n\n" + dotted_deep + "a = 1\n", "deep.toml"),
                      Catch::StartsWith("deep.toml:3: TOML nested more than 64 levels deep"));
    // x is level 1, each array one more.
    CHECK_NOTHROW(tpsim::check_toml_nesting("x = " + deep("[", "]", limit - 1, "1"), "ok"));
    CHECK_THROWS(tpsim::check_toml_nesting("x = " + deep("[", "]", limit, "1"), "deep"));
    CHECK_NOTHROW(tpsim::check_toml_nesting("x = " + deep("{a = ", "}", limit - 1, "1"), "ok"));
    CHECK_THROWS(tpsim::check_toml_nesting("x = " + deep("{a = ", "}", limit, "1"), "deep"));
    CHECK_NOTHROW(tpsim::check_toml_nesting("[" + dotted_ok + "a]\n", "ok"));
    CHECK_THROWS(tpsim::check_toml_nesting("[[" + dotted_deep + "a]]\n", "deep"));
    // A header's depth carries over to the keys below it.
    CHECK_THROWS(tpsim::check_toml_nesting("[" + dotted_ok + "a]\nb.c = 1\n", "deep"));
    // 100,000 levels, the stack overflow of old, is one error.
    CHECK_THROWS(tpsim::check_toml_nesting(deep("a.", "", 100000, "a = 1"), "deep"));
    CHECK_THROWS_AS(parse_config(deep("a.", "", 100000, "a = 1"), "cfg.toml"), tpsim::Error);
}

TEST_CASE("the nesting scan skips strings and comments and accepts deep-looking valid TOML",
          "[config][nesting]") {
    std::string brackets(200, '[');
    const std::string text = "a = \"" + brackets + "\" # " + brackets + "\n" +  //
                             "b = '" + brackets + "'\n" +                       //
                             "c = \"\"\"\n" + brackets + "\n\\\"\"\" \n" +      //
                             "d = '''" + brackets + "\n'''\n" +                 //
                             "e = [{x = 1}, {y = [1, 2]}, [], {}]\n" +          //
                             "\"quoted.key\".f = 2.5\n" +                       //
                             "[t]\ng = \"\"\"a\"\"\"\"\n" +                     //
                             "[[u.v]]\nh = 1979-05-27T07:32:00Z\n";
    CHECK_NOTHROW(tpsim::check_toml_nesting(text, "tricky.toml"));
    // Every shipped config and scene passes.
    for (const char* file : {"trax.toml", "tiny.toml", "../scenes/cornell.toml",
                             "../scenes/bunny.toml", "../scenes/stress.toml"}) {
        INFO(file);
        const std::string path = kConfigs + "/" + file;
        CHECK_NOTHROW(
            tpsim::check_toml_nesting(tpsim::read_input_file(path, "test input", 1 << 20), path));
    }
}
