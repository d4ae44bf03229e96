// Emissive materials: the scene format (TOML `emission`, .mtl `Ke`), the SceneExtras sections
// of the memory image, present only for kernels that read them.
#include <algorithm>

#include <catch2/catch.hpp>

#include "pathtrace_util.hpp"
#include "sim/image/memory_image.hpp"
#include "sim/scene/load_scene.hpp"

using namespace tpsim;
using namespace tpsim::pathtrace_test;
namespace layout = trax::layout;

namespace {

const scene::Material& material_named(const scene::Scene& s, const std::string& name) {
    const auto it = std::find_if(s.materials.begin(), s.materials.end(),
                                 [&](const scene::Material& m) { return m.name == name; });
    REQUIRE(it != s.materials.end());
    return *it;
}

bool has_section(const image::MemoryImage& image, const std::string& name) {
    return std::any_of(image.sections.begin(), image.sections.end(),
                       [&](const image::SectionSize& s) { return s.name == name; });
}

const std::string kTwoLamps = R"(
ambient = [0, 0, 0]
[materials]
lamp = { diffuse = [0.5, 0.25, 0], emission = [4, 2, 1] }
dim = { emission = [1, 1, 1] }
plain = [0.1, 0.2, 0.3]
[[generators]]
type = "sphere"
center = [-3, 0, 0]
radius = 1
segments = 8
rings = 4
material = "lamp"
[[generators]]
type = "sphere"
center = [0, 0, 0]
radius = 1
segments = 8
rings = 4
material = "dim"
[[generators]]
type = "sphere"
center = [3, 0, 0]
radius = 1
segments = 8
rings = 4
material = "plain"
)";

}  // namespace

TEST_CASE("emitters: a TOML material's emission and diffuse", "[emitters]") {
    const scene::Scene s = scene::load_scene(write_scene("lamps.toml", kTwoLamps));
    CHECK(material_named(s, "lamp").emission == glm::vec3(4, 2, 1));
    CHECK(material_named(s, "lamp").diffuse == glm::vec3(0.5f, 0.25f, 0));
    CHECK(material_named(s, "dim").diffuse == glm::vec3(0.8f));  // the default albedo
    CHECK(material_named(s, "plain").emission == glm::vec3(0));
    CHECK(material_named(s, "plain").diffuse == glm::vec3(0.1f, 0.2f, 0.3f));
}

TEST_CASE("emitters: bad emission values are reported with file and line", "[emitters]") {
    const auto message = [](const std::string& emission) {
        const auto path =
            write_scene("bad.toml", "[materials]\nlamp = { emission = " + emission +
                                        " }\n[[generators]]\ntype = \"sphere\"\n"
                                        "center = [0, 0, 0]\nradius = 1\nmaterial = \"lamp\"\n");
        try {
            scene::load_scene(path);
        } catch (const scene::SceneError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    CHECK_THAT(message("[-1, 0, 0]"),
               Catch::Contains("bad.toml:2:") &&
                   Catch::Contains("materials.lamp.emission[0] must be in [0, 3.402823e+38]"));
    CHECK_THAT(message("[0, nan, 0]"), Catch::Contains("materials.lamp.emission[1]"));
    CHECK_THAT(message("[0, 0, 1e39]"), Catch::Contains("materials.lamp.emission[2]"));
    CHECK_THAT(message("[1, 1]"), Catch::Contains("must be an array of 3 numbers"));
}

TEST_CASE("emitters: the Cornell box's light quad emits (.mtl Ke)", "[emitters]") {
    const scene::Scene s = scene::load_scene(cornell());
    CHECK(material_named(s, "light").emission == glm::vec3(18.f, 16.2f, 13.5f));
    CHECK(material_named(s, "light").diffuse == glm::vec3(0.78f));
    CHECK(material_named(s, "white").emission == glm::vec3(0));
}

TEST_CASE("emitters: .mtl Ke out of range is an error naming the material", "[emitters]") {
    const auto obj = write_scene("ke.obj", "mtllib ke.mtl\nusemtl hot\nv 0 0 0\nv 1 0 0\n"
                                           "v 0 1 0\nf 1 2 3\n");
    write_scene("ke.mtl", "newmtl hot\nKe 1 -2 0\n");
    CHECK_THROWS_WITH(scene::load_scene(obj),
                      Catch::Contains("material 'hot' emits (1, -2, 0) (.mtl Ke)"));
}

TEST_CASE("emitters: the extras sections hold the seed, emissions and emissive triangles",
          "[emitters]") {
    const scene::Scene s = scene::load_scene(cornell());
    const image::MemoryImage image = image::build_memory_image(s, nullptr, 4, {}, 1234u);
    const uint32_t* w = image.words.data();
    const auto word = [&](int addr, int offset) { return int32_t(w[addr + offset]); };
    const auto real = [&](int addr, int offset) {
        return __builtin_bit_cast(float, w[addr + offset]);
    };
    const int extras = layout::kExtrasAddr;
    CHECK(w[extras + layout::kExtrasSeed] == 1234u);
    const int emission = word(extras, layout::kExtrasEmission);
    CHECK(word(extras, layout::kExtrasEmission + 1) == int32_t(s.materials.size()));
    for (size_t m = 0; m < s.materials.size(); ++m)
        for (int c = 0; c < 3; ++c)
            CHECK(real(emission + int(m) * layout::kEmissionWords, c) ==
                  s.materials[m].emission[c]);

    // The light quad: two triangles, half the power each, 130 mm x 105 mm in image units.
    const int emitters = word(extras, layout::kExtrasEmitters);
    REQUIRE(word(extras, layout::kExtrasEmitters + 1) == 2);
    const double unit = s.frame.unit;
    float area = 0, cdf = 0;
    for (int i = 0; i < 2; ++i) {
        const int e = emitters + i * layout::kEmitterWords;
        const int tri = image.header.triangles.addr +
                        word(e, layout::kEmitterTriangle) * layout::kTriangleWords;
        CHECK(s.materials[size_t(word(tri, layout::kTriangleMaterial))].name == "light");
        CHECK(real(e, layout::kEmitterProbability) == Approx(0.5));
        CHECK(real(e, layout::kEmitterCdf) > cdf);
        cdf = real(e, layout::kEmitterCdf);
        area += real(e, layout::kEmitterArea);
    }
    CHECK(cdf == 1.0f);
    CHECK(double(area) * unit * unit == Approx(130.0 * 105.0).epsilon(1e-4));
    // Every section stays in the read-only scene part, before the framebuffer.
    CHECK(emitters + 2 * layout::kEmitterWords <= image.header.framebuffer.addr);
    CHECK(has_section(image, "extras"));
    CHECK(has_section(image, "emitters"));
}

TEST_CASE("emitters: probabilities follow each emitter's power", "[emitters]") {
    const scene::Scene s = scene::load_scene(write_scene("lamps.toml", kTwoLamps));
    const image::MemoryImage image = image::build_memory_image(s, nullptr, 1, {}, 0u);
    const uint32_t* w = image.words.data();
    const int extras = layout::kExtrasAddr;
    const int emitters = int32_t(w[extras + layout::kExtrasEmitters]);
    const int count = int32_t(w[extras + layout::kExtrasEmitters + 1]);
    // Two identical spheres emit: "lamp" with mean radiance 7/3, "dim" with 1; "plain" not.
    double lamp = 0, dim = 0;
    for (int i = 0; i < count; ++i) {
        const uint32_t* e = w + emitters + i * layout::kEmitterWords;
        const int tri = image.header.triangles.addr + int32_t(e[0]) * layout::kTriangleWords;
        const std::string& name =
            s.materials[size_t(int32_t(w[tri + layout::kTriangleMaterial]))].name;
        REQUIRE(name != "plain");
        (name == "lamp" ? lamp : dim) += __builtin_bit_cast(float, e[layout::kEmitterProbability]);
    }
    CHECK(lamp + dim == Approx(1.0));
    CHECK(lamp / dim == Approx(7.0 / 3.0).epsilon(1e-4));
}

TEST_CASE("emitters: an image without extras is laid out as before they existed", "[emitters]") {
    // The Cornell box emits, yet without extras its image equals that of the same scene with
    // the emission removed, and it lists only the sections it always had.
    scene::Scene s = scene::load_scene(cornell());
    const image::MemoryImage with_light = image::build_memory_image(s, nullptr, 8);
    for (scene::Material& m : s.materials)
        m.emission = glm::vec3(0);
    const image::MemoryImage dark = image::build_memory_image(s, nullptr, 8);
    CHECK(with_light.words == dark.words);
    CHECK_FALSE(has_section(with_light, "extras"));
    CHECK_FALSE(has_section(with_light, "emission"));
    CHECK_FALSE(has_section(with_light, "emitters"));
    CHECK(with_light.header.camera.addr == layout::align_section(layout::kHeaderWords));
    // With extras but nothing emitting: the record and the emission table, no emitters.
    const image::MemoryImage extras = image::build_memory_image(s, nullptr, 8, {}, 0u);
    CHECK(extras.words[layout::kExtrasAddr + layout::kExtrasEmitters + 1] == 0u);
    CHECK(extras.header.camera.addr > layout::kExtrasAddr);
}

TEST_CASE("emitters: only kernels that read them get the extras", "[emitters]") {
    const auto sections_of = [](const char* kernel) {
        render::RenderOptions o = options_for(cornell(), kernel, render::Engine::native);
        o.image_width = o.image_height = 8;
        return render::render(o).image;
    };
    const image::MemoryImage tracer = sections_of("tracer.elf");
    CHECK_FALSE(has_section(tracer, "extras"));
    CHECK(tracer.header.camera.addr == layout::kExtrasAddr);  // where the extras would be
    CHECK(has_section(sections_of("rand_probe.elf"), "extras"));
    CHECK(has_section(sections_of("path_tracing_starter.elf"), "emitters"));
}
