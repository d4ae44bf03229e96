#include <catch2/catch.hpp>

#include "sim/scene/load_scene.hpp"
#include "sim/scene/mesh_import.hpp"
#include "tests/scene/scene_test_util.hpp"

using namespace tpsim::scene;
using tpsim::scene::testing::write_file;

TEST_CASE("OBJ: quads are triangulated, degenerate faces kept and counted, lines skipped",
          "[import]") {
    const auto path = write_file("quad.obj",
                                 "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\n"
                                 "f 1 2 3 4\n"  // quad -> 2 triangles
                                 "f 1 2 5\n"    // collinear -> degenerate, kept
                                 "l 1 3\n");    // a line: not a triangle
    const ImportedMesh mesh = import_mesh(path);
    CHECK(mesh.triangles.size() == 3);
    CHECK(mesh.summary.triangles == 3);
    CHECK(mesh.summary.degenerate_triangles == 1);
    CHECK(mesh.summary.skipped_primitives == 1);
}

TEST_CASE("PLY and OFF files import", "[import]") {
    const auto ply = write_file(
        "tri.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                   "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                   "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
    const ImportedMesh from_ply = import_mesh(ply);
    REQUIRE(from_ply.triangles.size() == 1);
    CHECK(from_ply.triangles[0].v1 == glm::vec3(1, 0, 0));

    const auto off =
        write_file("square.off", "OFF\n4 1 0\n0 0 0\n2 0 0\n2 2 0\n0 2 0\n4 0 1 2 3\n");
    const ImportedMesh from_off = import_mesh(off);
    CHECK(from_off.triangles.size() == 2);
    const Aabb box = bounds_of(from_off.triangles);
    CHECK(box.lo == glm::vec3(0, 0, 0));
    CHECK(box.hi == glm::vec3(2, 2, 0));
}

TEST_CASE("Missing, empty, malformed and unsupported mesh files give clear errors", "[import]") {
    CHECK_THROWS_WITH(import_mesh("/nonexistent/dir/x.obj"),
                      Catch::Contains("mesh file not found"));
    CHECK_THROWS_WITH(import_mesh(write_file("empty.obj", "")), Catch::Contains("empty.obj"));
    CHECK_THROWS_WITH(import_mesh(write_file(
                          "bad.ply", "ply\nformat ascii 1.0\nelement vertex 3\nend_header\n1 2")),
                      Catch::Contains("bad.ply"));
    CHECK_THROWS_WITH(import_mesh(write_file("bad.off", "OFF\n3 1 0\n0 0 0\n")),
                      Catch::Contains("bad.off"));
    CHECK_THROWS_WITH(import_mesh(write_file("only_points.obj", "v 0 0 0\nv 1 0 0\np 1\np 2\n")),
                      Catch::Contains("no triangles"));
    CHECK_THROWS_WITH(import_mesh(write_file("notes.xyzzy", "hello")),
                      Catch::Contains("not a mesh format"));
    CHECK_THROWS_AS(load_scene(write_file("notes.txt2", "hello")), SceneError);
}

TEST_CASE("A bare mesh gets a camera that sees all of it, a light and a material",
          "[import][framing]") {
    // A long, thin, off-centre box: the hard case for framing.
    const auto path = write_file("stick.obj", "v 100 5 -3\nv 160 5 -3\nv 160 7 -3\nv 100 7 -3\n"
                                              "v 100 5 -1\nv 160 5 -1\nv 160 7 -1\nv 100 7 -1\n"
                                              "f 1 2 3 4\nf 5 6 7 8\nf 1 2 6 5\nf 4 3 7 8\n");
    const Scene scene = load_scene(path);
    REQUIRE(scene.triangles.size() == 8);
    REQUIRE(scene.lights.size() == 1);
    REQUIRE(scene.materials.size() == 1);

    const Camera& c = scene.camera;
    const glm::vec3 forward = glm::normalize(c.look_at - c.eye);
    const glm::vec3 right = glm::normalize(glm::cross(forward, c.up));
    const glm::vec3 up = glm::cross(right, forward);
    const float tan_half = std::tan(glm::radians(c.vertical_fov_degrees) * 0.5f);
    const float aspect = float(scene.width) / float(scene.height);
    for (const Triangle& t : scene.triangles)
        for (const glm::vec3& v : {t.v0, t.v1, t.v2}) {
            const glm::vec3 d = v - c.eye;
            const float depth = glm::dot(d, forward);
            REQUIRE(depth > 0.f);
            CHECK(std::abs(glm::dot(d, right) / depth) <= tan_half * aspect);
            CHECK(std::abs(glm::dot(d, up) / depth) <= tan_half);
        }
    // The light's default intensity makes the irradiance at the mesh centre 1 (I / d^2), in
    // the frame's units as in the world's.
    const glm::dvec3 centre(130, 6, -2);
    const glm::dvec3 to_light = scene.frame.to_world(scene.lights[0].position) - centre;
    const double unit = scene.frame.unit;
    CHECK(scene.lights[0].color.x * unit * unit / glm::dot(to_light, to_light) ==
          Approx(1.0).epsilon(1e-6));
}

TEST_CASE("Every truncation of a valid OBJ, PLY and OFF file loads or fails cleanly",
          "[import][robustness]") {
    const std::pair<std::string, std::string> files[] = {
        {"cut.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\nf 1 3 4\n"},
        {"cut.ply", "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float "
                    "y\nproperty float z\n"
                    "element face 2\nproperty list uchar int vertex_indices\nend_header\n"
                    "0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n"},
        {"cut.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n4 0 1 2 3\n"},
    };
    for (const auto& [name, contents] : files)
        for (size_t length = 0; length <= contents.size(); ++length) {
            INFO(name << " cut to " << length << " bytes");
            const auto path = write_file(name, contents.substr(0, length));
            // Only two outcomes are allowed: triangles, or a runtime_error naming the file.
            std::string outcome;
            try {
                outcome = import_mesh(path).triangles.empty() ? "no triangles and no error" : "ok";
            } catch (const std::runtime_error& e) {
                outcome = e.what();
            }
            INFO(outcome);
            CHECK((outcome == "ok" || outcome.find(name) != std::string::npos));
        }
}
