// End to end: the simulated machine and the native twin render bit-identical images.
#include <cstring>

#include <catch2/catch.hpp>

#include "sim/render/render.hpp"

using namespace tpsim;

namespace {

render::RenderOptions options_for(const char* scene, const char* kernel, render::Engine engine) {
    render::RenderOptions o;
    o.scene = std::filesystem::path(TPSIM_SOURCE_DIR) / "scenes" / scene;
    o.kernel = std::filesystem::path(TPSIM_KERNEL_DIR) / kernel;
    o.engine = engine;
    return o;
}

/// Index of the first pixel component whose bits differ, or -1.
long first_difference(const std::vector<float>& a, const std::vector<float>& b) {
    for (size_t i = 0; i < a.size(); ++i)
        if (std::memcmp(&a[i], &b[i], sizeof(float)) != 0) return long(i);
    return -1;
}

}  // namespace

TEST_CASE("render: the simulated Cornell box equals the native twin bit for bit", "[render]") {
    auto sim_options = options_for("cornell.toml", "primary_brute.elf", render::Engine::functional);
    auto native_options = options_for("cornell.toml", "primary_brute.elf", render::Engine::native);
    // A small image keeps the test quick; the shading code paths are the same.
    sim_options.chip.chip.num_tms = native_options.chip.chip.num_tms = 2;
    const render::RenderResult simulated = render::render(sim_options);
    const render::RenderResult native = render::render(native_options);

    REQUIRE(simulated.rgb.size() == size_t(simulated.scene.width) * simulated.scene.height * 3);
    REQUIRE(simulated.rgb.size() == native.rgb.size());
    CHECK(simulated.instructions.total > 0);
    const long diff = first_difference(simulated.rgb, native.rgb);
    INFO("first differing component " << diff << " (pixel " << diff / 3 << ")");
    CHECK(diff == -1);
    // Not a blank image: the lit scene has many distinct values.
    size_t lit = 0;
    for (float v : simulated.rgb) lit += v > 0.05f;
    CHECK(lit > simulated.rgb.size() / 2);
}
