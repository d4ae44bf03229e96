// The scene compiler's numbers: the camera-relative, unit-size frame, validation relative to the
// scene's size, refusals of what float cannot hold, and mesh up axes (docs/scenes.md).
#include <cmath>
#include <string>

#include <catch2/catch.hpp>
#include <fmt/format.h>

#include "sim/scene/load_scene.hpp"
#include "tests/scene/scene_test_util.hpp"

using namespace tpsim::scene;
using tpsim::scene::testing::write_file;

namespace {

/// An asymmetric tetrahedron (no axis maps it onto itself), authored y-up.
const char* kTetraObj = "v 0 0 0\nv 2 0 0\nv 0 3 0\nv 0 0 5\nf 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n";

std::string error_of(const std::string& name, const std::string& body) {
    write_file("tetra.obj", kTetraObj);
    try {
        load_scene(write_file(name, body));
    } catch (const SceneError& e) {
        return e.what();
    }
    return "(no error)";
}

float max_abs(const glm::vec3& v) {
    return std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)});
}

}  // namespace

TEST_CASE("The scene is compiled camera-relative and scaled into [-1, 1]", "[scenespace]") {
    write_file("tetra.obj", kTetraObj);
    for (const double scale : {1e-25, 1e-3, 1.0, 3e7, 1e19}) {
        INFO("scale " << scale);
        // An explicit camera and light scaled with the mesh; the light's intensity by scale^2.
        const Scene s = load_scene(write_file(
            "frame.toml",
            fmt::format("[camera]\neye = [{0:.17g}, {0:.17g}, {1:.17g}]\nlook_at = [0, 0, 0]\n"
                        "[[lights]]\nposition = [0, {1:.17g}, 0]\nintensity = {2:.17g}\n"
                        "[[meshes]]\npath = \"tetra.obj\"\nscale = {3:.17g}\n",
                        4 * scale, 10 * scale, 100 * scale * scale, scale)));
        CHECK(s.frame.origin == glm::dvec3(4 * scale, 4 * scale, 10 * scale));
        CHECK(std::exp2(std::round(std::log2(s.frame.unit))) == s.frame.unit);  // a power of two
        CHECK(s.camera.eye == glm::vec3(0.f));
        float reach = 0.f;
        for (const Triangle& t : s.triangles)
            for (const glm::vec3& v : {t.v0, t.v1, t.v2}) {
                reach = std::max(reach, max_abs(v - s.camera.eye));
                // Back in the world, every vertex is where the file put it.
                const glm::dvec3 world = s.frame.to_world(v) / scale;
                CHECK(glm::length(world - glm::round(world)) < 1e-5);
            }
        CHECK(reach >= 0.5f);
        CHECK(reach < 1.f);
        // Irradiance is unchanged: colour / distance^2 is 100 / 10^2 in the world and the frame.
        const glm::vec3 to_light = s.lights[0].position - s.triangles[0].v0;
        CHECK(double(s.lights[0].color.x / glm::dot(to_light, to_light)) ==
              Approx(1.0).epsilon(1e-5));
    }
}

TEST_CASE("A mesh file whose float coordinates are coarser than the render gets a warning",
          "[scenespace][warnings]") {
    // The tetrahedron stored 1e6 from its file's origin: float there rounds to 0.06.
    const Scene far =
        load_scene(write_file("far_tetra.obj", "v 1e6 0 0\nv 1000002 0 0\nv 1e6 3 0\nv 1e6 0 5\n"
                                               "f 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n"));
    REQUIRE(far.warnings.size() == 1);
    CHECK_THAT(far.warnings[0], Catch::Contains("far_tetra.obj: its coordinates lie up to 1e+06 "
                                                "from the mesh file's own origin") &&
                                    Catch::Contains("export the mesh centred on its origin"));
    // Stored at its origin and moved there with translate, it is exact and nothing is said.
    write_file("tetra.obj", kTetraObj);
    CHECK(load_scene(write_file("moved_tetra.toml",
                                "[[meshes]]\npath = \"tetra.obj\"\ntranslate = [1e6, 0, 0]\n"))
              .warnings.empty());
}

TEST_CASE("Camera validation is relative to the scene, not absolute", "[scenespace][errors]") {
    // 1e-25 apart is a valid camera for a scene of size 1e-25 (it was "must differ").
    CHECK(error_of("tiny_cam.toml",
                   "[camera]\neye = [0, 0, 3e-25]\nlook_at = [0, 0, 0]\n"
                   "[[meshes]]\npath = \"tetra.obj\"\nscale = 1e-25\n") == "(no error)");
    // An up vector of length 1e19 is not parallel to the view (it was).
    CHECK(error_of("big_up.toml", "[camera]\neye = [0, 0, 3e19]\nlook_at = [0, 0, 0]\n"
                                  "up = [0, 1e19, 0]\n[[meshes]]\npath = \"tetra.obj\"\n"
                                  "scale = 1e19\n") == "(no error)");
    // Parallel is still parallel at any size, and equal is still equal.
    CHECK_THAT(error_of("parallel.toml", "[camera]\neye = [0, 0, 3e-25]\nlook_at = [0, 0, 0]\n"
                                         "up = [0, 0, 1e-30]\n[[meshes]]\npath = \"tetra.obj\"\n"),
               Catch::Contains("camera.up must be non-zero and not parallel to look_at - eye"));
    CHECK_THAT(error_of("same.toml", "[camera]\neye = [1e-30, 0, 0]\nlook_at = [1e-30, 0, 0]\n"
                                     "[[meshes]]\npath = \"tetra.obj\"\n"),
               Catch::Contains("camera.eye and camera.look_at must differ"));
}

TEST_CASE("Automatic framing follows the scene's size at any scale", "[scenespace][framing]") {
    write_file("tetra.obj", kTetraObj);
    const auto frame_at = [](double scale) {
        return load_scene(write_file(
            "framed.toml", fmt::format("[[meshes]]\npath = \"tetra.obj\"\nscale = {}\n", scale)));
    };
    const Scene unit = frame_at(1);
    for (const double scale : {0x1p-99, 0x1p-27, 0x1p60}) {
        // A power-of-two scale is exact: the same float scene, only the frame differs. (A
        // radius floor of 1e-6 made a bunny scaled by 1e-8 a 3-pixel dot.)
        const Scene scaled = frame_at(scale);
        INFO("scale " << scale);
        CHECK(scaled.frame.unit == unit.frame.unit * scale);
        CHECK(scaled.camera.look_at == unit.camera.look_at);
        CHECK(scaled.lights[0].position == unit.lights[0].position);
        CHECK(scaled.lights[0].color == unit.lights[0].color);
        REQUIRE(scaled.triangles.size() == unit.triangles.size());
        for (size_t i = 0; i < unit.triangles.size(); ++i) {
            CHECK(scaled.triangles[i].v0 == unit.triangles[i].v0);
            CHECK(scaled.triangles[i].v2 == unit.triangles[i].v2);
        }
    }
}

TEST_CASE("Values float cannot hold are refused with the key and the allowed range",
          "[scenespace][errors]") {
    const std::string mesh = "[[meshes]]\npath = \"tetra.obj\"\n";
    // Each of these rendered black, uniform or inf before.
    CHECK_THAT(error_of("amb.toml", "ambient = [1e39, 0, 0]\n" + mesh),
               Catch::Contains(":1:12: ambient[0] must be in [0, 3.402823e+38], got 1e+39"));
    CHECK_THAT(error_of("fov_tiny.toml", "[camera]\neye = [0, 0, 9]\nlook_at = [0, 0, 0]\n"
                                         "fov = 1e-300\n" +
                                             mesh),
               Catch::Contains(":4:7: camera.fov must be in [0.028, 180) for a 256-pixel-high "
                               "image (narrower, float cannot tell neighbouring pixels' rays "
                               "apart), got 1e-300"));
    CHECK(error_of("fov_ok.toml", "[camera]\neye = [0, 0, 9]\nlook_at = [0, 0, 0]\nfov = 0.028\n" +
                                      mesh) == "(no error)");
    CHECK_THAT(
        error_of("bright.toml", "[[lights]]\nposition = [0, 9, 0]\nintensity = 1e300\n" + mesh),
        Catch::Contains(":3:13: lights[0]: color x intensity = 1e+300 is more than float "
                        "holds for a scene this size with light_falloff"));
    // The limit follows the size: 1e60 is right for a scene of size 1e30.
    CHECK(error_of("bright_big.toml",
                   "[[lights]]\nposition = [0, 9e30, 0]\nintensity = 1e60\n"
                   "[[meshes]]\npath = \"tetra.obj\"\nscale = 1e30\n") == "(no error)");
    CHECK_THAT(error_of("far_light.toml", "[[lights]]\nposition = [0, 1e39, 0]\n" + mesh),
               Catch::Contains(":2:12: lights[0].position is 1e+39 from camera.eye, more than "
                               "1.15e+18 times the scene's extent"));
    CHECK_THAT(
        error_of("color.toml", "[[lights]]\nposition = [0, 9, 0]\ncolor = [1, 1e39, 1]\n" + mesh),
        Catch::Contains("lights[0].color[1] must be in [0, 3.402823e+38], got 1e+39"));
    CHECK_THAT(error_of("radius.toml", "[[generators]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\n"
                                       "radius = 1e39\n"),
               Catch::Contains("generators[0].radius must be in [1e-30, 1e+30], got 1e+39"));
    CHECK_THAT(error_of("scale.toml", mesh + "scale = 1e-31\n"),
               Catch::Contains("meshes[0].scale must be in [1e-30, 1e+30], got 1e-31"));
    // World positions are double: a camera and mesh at 1e39 are a valid (if distant) scene.
    CHECK(error_of("far.toml", "[camera]\neye = [1e39, 0, 9]\nlook_at = [1e39, 0, 0]\n"
                               "[[lights]]\nposition = [1e39, 9, 0]\n" +
                                   mesh + "translate = [1e39, 0, 0]\n") == "(no error)");
}

TEST_CASE("A mesh's up axis is turned to +y, exactly", "[scenespace][up]") {
    write_file("tetra.obj", kTetraObj);
    // The same tetrahedron authored z-up: (x, y, z) -> (x, -z, y), and x-up, -y-up.
    write_file("tetra_z.obj", "v 0 0 0\nv 2 0 0\nv 0 0 3\nv 0 -5 0\n"
                              "f 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n");
    write_file("tetra_x.obj", "v 0 0 0\nv 0 -2 0\nv 3 0 0\nv 0 0 5\n"
                              "f 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n");
    write_file("tetra_negy.obj", "v 0 0 0\nv 2 0 0\nv 0 -3 0\nv 0 0 -5\n"
                                 "f 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n");
    const auto scene_of = [](const std::string& file, const std::string& up) {
        return load_scene(
            write_file("up.toml", fmt::format("[[meshes]]\npath = \"{}\"\n{}", file,
                                              up.empty() ? "" : "up = \"" + up + "\"\n")));
    };
    const Scene reference = scene_of("tetra.obj", "");
    for (const auto& [file, up] :
         {std::pair{"tetra_z.obj", "z"}, {"tetra_x.obj", "+x"}, {"tetra_negy.obj", "-y"}}) {
        INFO(file << " up = " << up);
        const Scene turned = scene_of(file, up);
        REQUIRE(turned.triangles.size() == reference.triangles.size());
        for (size_t i = 0; i < reference.triangles.size(); ++i) {
            CHECK(turned.triangles[i].v0 == reference.triangles[i].v0);
            CHECK(turned.triangles[i].v1 == reference.triangles[i].v1);
            CHECK(turned.triangles[i].v2 == reference.triangles[i].v2);
        }
    }
    // A z-up mesh read as y-up is lying down: different geometry.
    CHECK(scene_of("tetra_z.obj", "").triangles[0].v2 != reference.triangles[0].v2);
    // The bare-mesh path takes the axis as an argument.
    const Scene bare = load_scene(write_file("tetra_z.obj", "v 0 0 0\nv 2 0 0\nv 0 0 3\nv 0 -5 0\n"
                                                            "f 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n"),
                                  UpAxis::pos_z);
    const Scene bare_reference = load_scene(write_file("tetra.obj", kTetraObj));
    CHECK(bare.triangles[3].v1 == bare_reference.triangles[3].v1);
    CHECK_THAT(error_of("bad_up.toml", "[[meshes]]\npath = \"tetra.obj\"\nup = \"w\"\n"),
               Catch::Contains(":3:6: meshes[0].up must be one of x, y, z, -x, -y, -z, got 'w'"));
    CHECK(parse_up_axis("-z") == UpAxis::neg_z);
    CHECK(parse_up_axis("+y") == UpAxis::pos_y);
    CHECK_FALSE(parse_up_axis("zz"));
}
