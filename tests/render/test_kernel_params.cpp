// Run-time kernel parameters (TRAX_PARAM) on the functional engine, the cycle-level chip and the
// native twin: found in the ELF, set by name, refused with one line when wrong.
#include <bit>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "sim/core/error.hpp"
#include "sim/render/render.hpp"

using namespace tpsim;

namespace {

std::filesystem::path probe() {
    return std::filesystem::path(TPSIM_KERNEL_DIR) / "params_probe.elf";
}

render::RenderResult run(render::Engine engine, std::vector<std::string> params,
                         render::TwinProcess process = render::TwinProcess::child) {
    render::RenderOptions o;
    o.scene = std::filesystem::path(TPSIM_SOURCE_DIR) / "scenes" / "cornell.toml";
    o.kernel = probe();
    o.engine = engine;
    o.twin_process = process;
    o.image_width = o.image_height = 4;
    o.chip.chip.num_tms = 1;
    o.chip.chip.tps_per_tm = 4;
    o.params = std::move(params);
    return render::render(o);
}

uint32_t word(const render::RenderResult& r, uint32_t i) {
    return r.image.words.at(r.image.header.framebuffer.addr + i);
}

std::string error_of(std::vector<std::string> params) {
    try {
        run(render::Engine::functional, std::move(params));
    } catch (const Error& e) {
        return e.what();
    }
    return "(no error)";
}

}  // namespace

TEST_CASE("kernel params: declared with their types and defaults, read from the ELF",
          "[render][params]") {
    const render::Kernel kernel = render::Kernel::load(probe());
    REQUIRE(kernel.params.size() == 3);  // by name; `unused` too, though nothing reads it
    CHECK(kernel.params[0].name == "count");
    CHECK(kernel.params[0].type == render::KernelParam::Type::int32);
    CHECK(kernel.params[0].text() == "3");
    CHECK(kernel.params[1].name == "gain");
    CHECK(kernel.params[1].type == render::KernelParam::Type::float32);
    CHECK(kernel.params[1].symbol() == "trax_param_float_gain");
    CHECK(kernel.params[1].bits == std::bit_cast<uint32_t>(0.5f));
    CHECK(kernel.params[2].name == "unused");
    CHECK(kernel.params[2].text() == "7");
    for (const render::KernelParam& p : kernel.params)
        CHECK_FALSE(p.set);
    // The tracer declares none.
    CHECK(render::Kernel::load(std::filesystem::path(TPSIM_KERNEL_DIR) / "tracer.elf")
              .params.empty());
}

TEST_CASE("kernel params: every engine runs with the defaults, or with the values set",
          "[render][params]") {
    for (const render::Engine engine :
         {render::Engine::functional, render::Engine::timing, render::Engine::native}) {
        INFO("engine " << int(engine));
        const render::RenderResult defaults = run(engine, {});
        CHECK(word(defaults, 0) == std::bit_cast<uint32_t>(0.5f));
        CHECK(word(defaults, 1) == 3);
        CHECK(word(defaults, 2) == std::bit_cast<uint32_t>(1.5f));

        const render::RenderResult set = run(engine, {"gain=2.25", "count=-4", "unused=1"});
        CHECK(word(set, 0) == std::bit_cast<uint32_t>(2.25f));
        CHECK(word(set, 1) == uint32_t(-4));
        CHECK(word(set, 2) == std::bit_cast<uint32_t>(-9.0f));
        REQUIRE(set.params.size() == 3);
        CHECK(render::describe_params(set.params) == "count=-4, gain=2.25, unused=1");
        CHECK(set.params[1].set);
    }
}

TEST_CASE("kernel params: a twin in tpsim's own process does not keep an earlier run's values",
          "[render][params]") {
    const auto in_process = render::TwinProcess::in_process;
    CHECK(word(run(render::Engine::native, {"count=11"}, in_process), 1) == 11);
    CHECK(word(run(render::Engine::native, {}, in_process), 1) == 3);
}

TEST_CASE("kernel params: a float reads back to the same bits, whatever its text",
          "[render][params]") {
    const render::RenderResult r = run(render::Engine::functional, {"gain=1e-3"});
    CHECK(word(r, 0) == std::bit_cast<uint32_t>(1e-3f));
    CHECK(r.params[1].text() == "0.001");
}

TEST_CASE("kernel params: wrong names and values are refused with one line", "[render][params]") {
    CHECK(error_of({"gian=1"}) ==
          "kernel parameter gian=1: params_probe.elf has no parameter 'gian'; its parameters: "
          "count (int, default 3), gain (float, default 0.5), unused (int, default 7)");
    CHECK(error_of({"gain"}) == "kernel parameter 'gain': write NAME=VALUE, e.g. threshold=0.02");
    CHECK(error_of({"=1"}) == "kernel parameter '=1': write NAME=VALUE, e.g. threshold=0.02");
    CHECK(error_of({"gain=1", "gain=2"}) == "kernel parameter 'gain' is given twice; give it once");
    for (const char* bad : {"gain=", "gain=fast", "gain=1.5x", "gain=nan", "gain=inf", "gain=1e39"})
        CHECK(error_of({bad}) == std::string("kernel parameter ") + bad +
                                     ": 'gain' of params_probe.elf is a float: give a finite "
                                     "number, got '" +
                                     std::string(bad).substr(5) + "'; e.g. gain=0.5");
    for (const char* bad : {"count=1.5", "count=2147483648", "count=0x10", "count= 1"})
        CHECK(error_of({bad}) == std::string("kernel parameter ") + bad +
                                     ": 'count' of params_probe.elf is an int: give a whole "
                                     "number in [-2147483648, 2147483647], got '" +
                                     std::string(bad).substr(6) + "'; e.g. count=3");
    render::RenderOptions tracer;
    tracer.scene = std::filesystem::path(TPSIM_SOURCE_DIR) / "scenes" / "cornell.toml";
    tracer.kernel = std::filesystem::path(TPSIM_KERNEL_DIR) / "tracer.elf";
    tracer.params = {"threshold=0.1"};
    CHECK_THROWS_WITH(render::render(tracer),
                      "kernel parameter threshold=0.1: tracer.elf has no parameter 'threshold'; it "
                      "declares none (TRAX_PARAM in kernel/trax.hpp, docs/kernel-api.md)");
}
