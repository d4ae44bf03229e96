// The path tracer of assignment 5: the starter renders only the light seen directly; the
// reference solution (when course/solutions/ is there) is bit-identical on the simulator and
// the native twin and converges as 1/sqrt(samples).
#include <algorithm>
#include <cmath>

#include <catch2/catch.hpp>

#include "pathtrace_util.hpp"

using namespace tpsim;
using namespace tpsim::pathtrace_test;

namespace {

render::RenderResult render_with(const char* kernel, render::Engine engine, uint32_t size,
                                 uint32_t spp, uint32_t seed = 0,
                                 const std::filesystem::path& scene = cornell()) {
    render::RenderOptions o = options_for(scene, kernel, engine);
    o.image_width = o.image_height = size;
    o.samples_per_pixel = spp;
    o.seed = seed;
    return render::render(o);
}

/// RMS difference over the pixels where `mask` is 0. Pixels that see the light quad (or its
/// edge) are left out: there, 18 x the covered share of the pixel, estimated from a few
/// samples, is noise that swamps the light transport's.
double rms_difference(const std::vector<float>& a, const std::vector<float>& b,
                      const std::vector<bool>& mask) {
    double sum = 0;
    size_t n = 0;
    for (size_t i = 0; i < a.size(); ++i) {
        if (mask[i / 3]) continue;
        sum += (double(a[i]) - b[i]) * (double(a[i]) - b[i]);
        ++n;
    }
    return std::sqrt(sum / double(n));
}

const std::string kNoEmitters = R"(
background = [0.2, 0.3, 0.4]
[[generators]]
type = "sphere"
center = [0, 0, 0]
radius = 1
)";

}  // namespace

TEST_CASE("path tracing: the starter shows only the emitters the camera sees", "[pathtrace]") {
    const render::RenderResult r =
        render_with("path_tracing_starter.elf", render::Engine::functional, 32, 2);
    const glm::vec3 light(18.f, 16.2f, 13.5f);  // scenes/cornell.mtl Ke
    size_t on_light = 0, black = 0;
    for (size_t p = 0; p < r.rgb.size() / 3; ++p) {
        const glm::vec3 c(r.rgb[3 * p], r.rgb[3 * p + 1], r.rgb[3 * p + 2]);
        on_light += c == light;
        black += c == glm::vec3(0);
        // Partly covered pixels average the light and black: a fraction of it.
        if (c != glm::vec3(0)) CHECK(c.y / c.x == Approx(0.9f).epsilon(1e-5));
    }
    CHECK(on_light >= 4);  // the light quad covers a few pixels of 32x32
    CHECK(black > r.rgb.size() / 3 * 9 / 10);
}

TEST_CASE("path tracing: a generated sphere emits from its outside", "[pathtrace]") {
    const render::RenderResult r =
        render_with("path_tracing_starter.elf", render::Engine::native, 16, 1, 0,
                    write_scene("lamp.toml", "[materials]\nlamp = { emission = [4, 3, 2] }\n"
                                             "[[generators]]\ntype = \"sphere\"\n"
                                             "center = [0, 0, 0]\nradius = 1\n"
                                             "material = \"lamp\"\n"));
    size_t lit = 0;
    for (size_t p = 0; p < r.rgb.size() / 3; ++p)
        lit += glm::vec3(r.rgb[3 * p], r.rgb[3 * p + 1], r.rgb[3 * p + 2]) == glm::vec3(4, 3, 2);
    CHECK(lit > r.rgb.size() / 3 / 8);  // the default camera frames the sphere: ~20 %
}

#ifdef TPSIM_HAVE_SOLUTIONS

TEST_CASE("path tracing: the solution is bit-identical on the simulator and the twin",
          "[pathtrace]") {
    const render::RenderResult simulated =
        render_with("path_tracing_solution.elf", render::Engine::functional, 24, 2, 3);
    const render::RenderResult twin =
        render_with("path_tracing_solution.elf", render::Engine::native, 24, 2, 3);
    REQUIRE(simulated.rgb.size() == 24 * 24 * 3);
    CHECK(first_difference(simulated.rgb, twin.rgb) == -1);
    CHECK(simulated.traversal.primary_rays == twin.traversal.primary_rays);
    CHECK(simulated.traversal.shadow_rays == twin.traversal.shadow_rays);
    // Paths bounce: more closest-hit rays than camera rays, and shadow rays to the light.
    CHECK(simulated.traversal.primary_rays > 2 * 24 * 24 * 2);
    CHECK(simulated.traversal.shadow_rays > 24 * 24);
}

TEST_CASE("path tracing: the Cornell box converges as 1/sqrt(samples)", "[pathtrace]") {
    const auto image = [](uint32_t spp, uint32_t seed) {
        return render_with("path_tracing_solution.elf", render::Engine::native, 32, spp, seed).rgb;
    };
    // Where the starter (emission seen directly) is not black, and the pixels next to those.
    const std::vector<float> light =
        render_with("path_tracing_starter.elf", render::Engine::native, 32, 64).rgb;
    std::vector<bool> sees_light(32 * 32);
    for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 32; ++x)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const int nx = std::clamp(x + dx, 0, 31), ny = std::clamp(y + dy, 0, 31);
                    sees_light[size_t(y * 32 + x)] =
                        sees_light[size_t(y * 32 + x)] || light[size_t(ny * 32 + nx) * 3] > 0;
                }
    REQUIRE(std::count(sees_light.begin(), sees_light.end(), true) < 32 * 32 / 10);

    const std::vector<float> reference = image(512, 1);  // another seed: independent samples
    const double e4 = rms_difference(image(4, 0), reference, sees_light);
    const double e16 = rms_difference(image(16, 0), reference, sees_light);
    const double e64 = rms_difference(image(64, 0), reference, sees_light);
    INFO("RMS error at 4, 16, 64 spp: " << e4 << ", " << e16 << ", " << e64);
    // 4x the samples halves the error (a little less: the reference has noise of its own).
    CHECK(e4 / e16 == Approx(2.0).margin(0.4));
    CHECK(e16 / e64 == Approx(2.0).margin(0.4));
    // Lit by the emitter alone: the floor and walls are bright, the light brightest.
    double mean = 0;
    float brightest = 0;
    for (float v : reference) {
        mean += v;
        brightest = std::max(brightest, v);
    }
    mean /= double(reference.size());
    CHECK(mean > 0.1);
    CHECK(brightest >= 18.0f);  // the light seen directly: its emission and what it reflects
}

TEST_CASE("path tracing: the run seed changes the noise, not the image's expectation",
          "[pathtrace]") {
    const auto a = render_with("path_tracing_solution.elf", render::Engine::native, 16, 8, 0).rgb;
    const auto b = render_with("path_tracing_solution.elf", render::Engine::native, 16, 8, 9).rgb;
    CHECK(first_difference(a, b) != -1);
    CHECK(first_difference(
              a, render_with("path_tracing_solution.elf", render::Engine::native, 16, 8, 0).rgb) ==
          -1);
    double mean_a = 0, mean_b = 0;
    for (size_t i = 0; i < a.size(); ++i) {
        mean_a += a[i];
        mean_b += b[i];
    }
    CHECK(mean_a == Approx(mean_b).epsilon(0.1));
}

TEST_CASE("path tracing: a scene without emitters is black where it is not background",
          "[pathtrace]") {
    const render::RenderResult r =
        render_with("path_tracing_solution.elf", render::Engine::functional, 16, 1, 0,
                    write_scene("dark.toml", kNoEmitters));
    size_t background = 0, black = 0;
    for (size_t p = 0; p < r.rgb.size() / 3; ++p) {
        const glm::vec3 c(r.rgb[3 * p], r.rgb[3 * p + 1], r.rgb[3 * p + 2]);
        background += c == glm::vec3(0.2f, 0.3f, 0.4f);
        black += c == glm::vec3(0);
    }
    CHECK(background > 0);
    CHECK(black > 0);
    CHECK(background + black == r.rgb.size() / 3);
}

#endif
