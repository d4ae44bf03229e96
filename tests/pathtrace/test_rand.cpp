// trax_rand() / trax_srand(): the same numbers on the simulator and the native twin, in [0, 1),
// uniform, per thread, seedable; the run seed reaches the default seeding.
#include <catch2/catch.hpp>

#include "kernel/trax.hpp"
#include "pathtrace_util.hpp"

using namespace tpsim;
using namespace tpsim::pathtrace_test;

namespace {

/// rand_probe's framebuffer (see kernels/rand_probe.cpp): mode = samples per pixel.
std::vector<float> probe(render::Engine engine, uint32_t mode, uint32_t seed = 0,
                         uint32_t tms = 1) {
    render::RenderOptions o = options_for(cornell(), "rand_probe.elf", engine);
    o.image_width = o.image_height = 64;
    o.samples_per_pixel = mode;
    o.seed = seed;
    o.chip.chip.num_tms = tms;
    return render::render(o).rgb;
}

/// The three numbers of pixel `pixel`.
std::vector<float> at(const std::vector<float>& rgb, size_t pixel) {
    return {rgb[3 * pixel], rgb[3 * pixel + 1], rgb[3 * pixel + 2]};
}

}  // namespace

TEST_CASE("rand: the simulator and the native twin draw the same numbers", "[rand]") {
    for (uint32_t mode : {1u, 2u, 3u}) {
        INFO("mode " << mode);
        const std::vector<float> simulated = probe(render::Engine::functional, mode, 7);
        const std::vector<float> twin = probe(render::Engine::native, mode, 7);
        REQUIRE(simulated.size() == 64 * 64 * 3);
        CHECK(first_difference(simulated, twin) == -1);
    }
}

TEST_CASE("rand: numbers lie in 0 <= x < 1, in 24-bit steps, uniformly spread", "[rand]") {
    const std::vector<float> values = probe(render::Engine::native, 1);
    double sum = 0, sum2 = 0;
    std::vector<int> buckets(16);
    for (float v : values) {
        REQUIRE(v >= 0.0f);
        REQUIRE(v < 1.0f);
        REQUIRE(v * 16777216.0f == float(int(v * 16777216.0f)));  // a multiple of 2^-24
        sum += v;
        sum2 += double(v) * v;
        ++buckets[size_t(v * 16)];
    }
    const double n = double(values.size());
    // 12,288 numbers: the mean's standard deviation is 0.29 / sqrt(n) = 0.0026.
    CHECK(sum / n == Approx(0.5).margin(0.01));
    CHECK(sum2 / n - (sum / n) * (sum / n) == Approx(1.0 / 12).margin(0.005));
    for (int b : buckets)  // 768 expected per bucket, standard deviation 27
        CHECK(std::abs(b - int(n / 16)) < 150);
}

TEST_CASE("rand: one state per thread, seeded by thread id and run seed", "[rand]") {
    const std::vector<float> seed0 = probe(render::Engine::functional, 1, 0);
    // Thread 0 fills pixels 0, 32, ...; thread 1 pixels 1, 33, ...: different sequences.
    CHECK(at(seed0, 0) != at(seed0, 1));
    // A thread's sequence goes on from pixel to pixel rather than restarting.
    CHECK(at(seed0, 0) != at(seed0, 32));
    // The run seed changes every thread's numbers; the same seed gives the same ones.
    const std::vector<float> seed1 = probe(render::Engine::functional, 1, 1);
    CHECK(at(seed0, 0) != at(seed1, 0));
    CHECK(at(seed0, 5) != at(seed1, 5));
    CHECK(first_difference(seed1, probe(render::Engine::functional, 1, 1)) == -1);
}

TEST_CASE("rand: trax_srand() restarts a thread's sequence", "[rand]") {
    // Every thread called trax_srand(42): thread t's k-th pixel holds what thread 0's k-th holds.
    const std::vector<float> same = probe(render::Engine::functional, 2);
    for (size_t k = 0; k < 4; ++k)
        for (size_t t = 1; t < 32; ++t)
            CHECK(at(same, 32 * k + t) == at(same, 32 * k));
    CHECK(at(same, 0) != at(same, 32));
    // Seeded per pixel, the image does not depend on how many threads drew it...
    const std::vector<float> one_tm = probe(render::Engine::functional, 3, 0, 1);
    CHECK(first_difference(one_tm, probe(render::Engine::functional, 3, 0, 2)) == -1);
    // ... while the default per-thread seeding does.
    CHECK(first_difference(probe(render::Engine::functional, 1, 0, 1),
                           probe(render::Engine::functional, 1, 0, 2)) != -1);
}

TEST_CASE("rand: the generator is Marsaglia's xorshift32", "[rand]") {
    // The twin's trax_rand() over a hand-made context; the test above shows the guest agrees.
    trax::native::ThreadContext thread;
    trax::native::current = &thread;
    // Marsaglia (2003), "Xorshift RNGs": from 2463534242 the (13, 17, 5) generator gives
    // 723471715 first.
    thread.rand_state = 2463534242u;
    CHECK(trax_rand() == float(723471715u >> 8) * 0x1p-24f);
    CHECK(thread.rand_state == 723471715u);
    // trax_srand() never leaves the state at xorshift's fixed point 0.
    for (uint32_t seed : {0u, 1u, 42u, 0xffffffffu}) {
        trax_srand(seed);
        CHECK(thread.rand_state != 0u);
        CHECK(thread.rand_state == (trax_hash(seed) != 0 ? trax_hash(seed) : 0x9e3779b9u));
    }
    trax::native::current = nullptr;
}
