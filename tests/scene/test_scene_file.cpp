#include <algorithm>

#include <catch2/catch.hpp>

#include "sim/scene/load_scene.hpp"
#include "tests/scene/scene_test_util.hpp"

using namespace tpsim::scene;
using tpsim::scene::testing::write_file;

namespace {

const char* kTriangleObj = "mtllib tri.mtl\nusemtl paint\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\n";
const char* kTriangleMtl = "newmtl paint\nKd 0.1 0.2 0.3\n";

/// A scene file next to a one-triangle OBJ; `body` follows a minimal valid header.
std::filesystem::path scene_with(const std::string& name, const std::string& body) {
    write_file("tri.obj", kTriangleObj);
    write_file("tri.mtl", kTriangleMtl);
    return write_file(name, body);
}

std::string error_of(const std::filesystem::path& path) {
    try {
        load_scene(path);
    } catch (const SceneError& e) {
        return e.what();
    }
    return "(no error)";
}

bool has_material(const Scene& scene, const std::string& name) {
    return std::any_of(scene.materials.begin(), scene.materials.end(),
                       [&](const Material& m) { return m.name == name; });
}

}  // namespace

TEST_CASE("A complete scene file is read into the Scene", "[scenefile]") {
    const auto path = scene_with("full.toml", R"(
name = "full"
ambient = [0.2, 0.3, 0.4]
background = [0.5, 0.6, 0.7]
[image]
width = 320
height = 200
samples_per_pixel = 4
[shading]
shadows = false
light_falloff = false
[camera]
eye = [0, 0, 10]
look_at = [0, 0, 0]
up = [0, 1, 0]
fov = 60
[[lights]]
position = [1, 2, 3]
color = [1, 0.5, 0.25]
intensity = 4
[materials]
paint = [0.9, 0.8, 0.7]
blue = [0, 0, 1]
[[meshes]]
path = "tri.obj"
scale = 2
translate = [10, 0, 0]
[[meshes]]
path = "tri.obj"
rotate = [0, 90, 0]
material = "blue"
[[generators]]
type = "sphere"
center = [0, 0, 0]
radius = 1
segments = 8
rings = 4
)");
    const Scene s = load_scene(path);
    CHECK(s.name == "full");
    CHECK(s.width == 320);
    CHECK(s.height == 200);
    CHECK(s.samples_per_pixel == 4);
    CHECK_FALSE(s.shadows);
    CHECK_FALSE(s.light_falloff);
    CHECK(s.ambient == glm::vec3(0.2f, 0.3f, 0.4f));
    CHECK(s.background == glm::vec3(0.5f, 0.6f, 0.7f));
    // Camera-relative: the eye is the frame's origin; the scene fits in [-1, 1] (reach 12: x of
    // the first mesh), so the unit is 16.
    CHECK(s.frame.origin == glm::dvec3(0, 0, 10));
    CHECK(s.frame.unit == 16);
    CHECK(s.camera.eye == glm::vec3(0, 0, 0));
    CHECK(s.camera.look_at == glm::vec3(0, 0, -1));
    CHECK(s.camera.vertical_fov_degrees == 60);
    REQUIRE(s.lights.size() == 1);
    CHECK(s.frame.to_world(s.lights[0].position) == glm::dvec3(1, 2, 3));
    CHECK(s.lights[0].color == glm::vec3(4, 2, 1));  // colour times intensity (no falloff)

    // 1 + 1 triangles from the OBJ, 2 * 8 * (4 - 1) from the sphere.
    REQUIRE(s.triangles.size() == 2 + 48);
    // First mesh: scaled by 2, then moved +10 in x. The scene's "paint" overrides the file's.
    const Triangle& first = s.triangles[0];
    CHECK(s.frame.to_world(first.v0) == glm::dvec3(12, 0, 0));
    CHECK(s.frame.to_world(first.v1) == glm::dvec3(10, 2, 0));
    CHECK(s.materials[first.material].name == "paint");
    CHECK(s.materials[first.material].diffuse == glm::vec3(0.9f, 0.8f, 0.7f));
    // Second mesh: 90 degrees about +y takes +x to -z, exactly; its material is forced to "blue".
    const Triangle& second = s.triangles[1];
    CHECK(s.frame.to_world(second.v0) == glm::dvec3(0, 0, -1));
    CHECK(s.materials[second.material].name == "blue");
    // Sphere without a material gets the default; only used materials are kept.
    CHECK(s.materials[s.triangles.back().material].name == "default");
    CHECK(s.materials.size() == 3);
    REQUIRE(s.sources.size() == 3);
    CHECK(s.sources[2].triangles == 48);
}

TEST_CASE("File materials are used when the scene does not override them", "[scenefile]") {
    const Scene s = load_scene(scene_with("plain.toml", "[[meshes]]\npath = \"tri.obj\"\n"));
    REQUIRE(s.materials.size() == 1);
    CHECK(s.materials[0].name == "paint");
    CHECK(s.materials[0].diffuse == glm::vec3(0.1f, 0.2f, 0.3f));
    // No [camera], no lights key: framed automatically with one default light.
    CHECK(s.lights.size() == 1);
    CHECK(glm::length(s.camera.eye - s.camera.look_at) > 0.f);
}

TEST_CASE("Out-of-range values name file, line, column, key and the allowed range",
          "[scenefile][errors]") {
    // Line 3 is "fov = 190"; the value starts at column 7.
    const auto path =
        scene_with("bad_fov.toml", "[camera]\neye = [0, 0, 5]\nfov = 190\nlook_at = [0, 0, 0]\n"
                                   "[[meshes]]\npath = \"tri.obj\"\n");
    CHECK(error_of(path) == path.string() + ":3:7: camera.fov must be in (0, 180), got 190");

    CHECK_THAT(error_of(scene_with("w.toml", "[image]\nwidth = 0\n")),
               Catch::Contains(":2:9: image.width must be in [1, 16384], got 0"));
    CHECK_THAT(error_of(scene_with("c.toml", "ambient = [0.1, -1, 0]\n")),
               Catch::Contains("ambient[1] must be in [0, 3.402823e+38], got -1"));
    CHECK_THAT(error_of(scene_with("m.toml", "[materials]\nred = [1.5, 0, 0]\n")),
               Catch::Contains("materials.red[0] must be in [0, 1], got 1.5"));
    CHECK_THAT(error_of(scene_with("s.toml", "[[meshes]]\npath = \"tri.obj\"\nscale = 0\n")),
               Catch::Contains("meshes[0].scale must be in"));
    CHECK_THAT(
        error_of(scene_with("g.toml", "[[generators]]\ntype = \"terrain\"\ncells = [0, 4]\n")),
        Catch::Contains("generators[0].cells[0] must be in [1, 16384], got 0"));
}

TEST_CASE("Unknown keys are errors, at any depth", "[scenefile][errors]") {
    CHECK_THAT(error_of(scene_with("k1.toml", "colour = [1, 1, 1]\n")),
               Catch::Contains(":1:1: unknown key colour (allowed: name, image"));
    CHECK_THAT(error_of(scene_with("k2.toml",
                                   "[camera]\neye = [0, 0, 5]\nlook_at = [0, 0, 0]\nfovv = 40\n")),
               Catch::Contains(":4:1: unknown key camera.fovv"));
    CHECK_THAT(error_of(scene_with("k3.toml",
                                   "[[meshes]]\npath = \"tri.obj\"\ntranslation = [1, 2, 3]\n")),
               Catch::Contains("unknown key meshes[0].translation"));
    CHECK_THAT(error_of(scene_with("k4.toml", "[[lights]]\nposition = [0, 0, 0]\npower = 3\n")),
               Catch::Contains("unknown key lights[0].power"));
}

TEST_CASE("Type errors, missing keys and bad references are reported", "[scenefile][errors]") {
    CHECK_THAT(error_of(scene_with("t1.toml", "[image]\nwidth = \"wide\"\n")),
               Catch::Contains("image.width must be an integer, got a string"));
    CHECK_THAT(error_of(scene_with("t2.toml", "[camera]\neye = [0, 0]\nlook_at = [0, 0, 0]\n")),
               Catch::Contains("camera.eye must be an array of 3 numbers"));
    CHECK_THAT(error_of(scene_with(
                   "t3.toml", "[camera]\nlook_at = [0, 0, 0]\n[[meshes]]\npath = \"tri.obj\"\n")),
               Catch::Contains("camera.eye is required"));
    CHECK_THAT(error_of(scene_with("t4.toml", "[[meshes]]\nscale = 2\n")),
               Catch::Contains("meshes[0].path is required"));
    CHECK_THAT(
        error_of(scene_with("t5.toml", "[[meshes]]\npath = \"tri.obj\"\nmaterial = \"gold\"\n")),
        Catch::Contains("meshes[0].material 'gold' is not defined in [materials]"));
    CHECK_THAT(error_of(scene_with("t6.toml", "[[generators]]\ntype = \"torus\"\n")),
               Catch::Contains(
                   "generators[0].type must be one of sphere, terrain, sphere_grid, got 'torus'"));
    CHECK_THAT(error_of(scene_with("t7.toml", "[camera]\neye = [1, 1, 1]\nlook_at = [1, 1, 1]\n"
                                              "[[meshes]]\npath = \"tri.obj\"\n")),
               Catch::Contains("camera.eye and camera.look_at must differ"));
    CHECK_THAT(error_of(scene_with("t8.toml", "[shading]\nshadows = 1\n")),
               Catch::Contains("shading.shadows must be true or false"));
    CHECK_THAT(error_of(scene_with("t9.toml", "meshes = 3\n")),
               Catch::Contains("meshes must be an array of tables"));
}

TEST_CASE("Syntax errors, missing files and empty scenes are reported", "[scenefile][errors]") {
    CHECK_THAT(error_of(scene_with("syntax.toml", "[image]\nwidth = = 3\n")),
               Catch::Contains("syntax.toml:2:"));
    CHECK_THAT(error_of(scene_with("syntax.toml", "[image]\nwidth = = 3\n")),
               Catch::Contains("TOML syntax"));
    CHECK_THAT(error_of(write_file("nothing_here.toml", "").parent_path() / "absent.toml"),
               Catch::Contains("scene file not found"));
    CHECK_THAT(error_of(scene_with("empty.toml", "name = \"x\"\n")),
               Catch::Contains("the scene has no geometry"));
    // A missing mesh is reported at the path value inside the scene file (line 2, column 8).
    CHECK_THAT(error_of(scene_with("nomesh.toml", "[[meshes]]\npath = \"missing.obj\"\n")),
               Catch::Contains("nomesh.toml:2:8: meshes[0].path:") &&
                   Catch::Contains("mesh file not found"));
    CHECK_THAT(error_of(scene_with("huge.toml",
                                   "[[generators]]\ntype = \"terrain\"\ncells = [16384, 16384]\n")),
               Catch::Contains("triangles"));
}

TEST_CASE("The shipped scenes load", "[scenefile][shipped]") {
    const std::filesystem::path dir = TPSIM_SCENES_DIR;
    const Scene cornell = load_scene(dir / "cornell.toml");
    // 5 room quads (the front wall is open) + light quad + 2 blocks of 5 quads = 16 quads.
    CHECK(cornell.triangles.size() == 32);
    CHECK(cornell.width == 256);
    CHECK(cornell.frame.origin == glm::dvec3(278, 273, -800));
    CHECK(cornell.camera.vertical_fov_degrees == Approx(39.3077));
    CHECK(has_material(cornell, "red"));
    CHECK(has_material(cornell, "green"));
    CHECK(has_material(cornell, "white"));
    REQUIRE(cornell.lights.size() == 1);
    CHECK(cornell.frame.to_world(cornell.lights[0].position).y < 548.3);  // below the light quad
    CHECK(cornell.sources[0].degenerate_triangles == 0);
    CHECK(cornell.warnings.empty());

    const Scene stress = load_scene(dir / "stress.toml");
    CHECK(stress.triangles.size() >= 1'000'000);
    CHECK(stress.warnings.empty());
    const Scene again = load_scene(dir / "stress.toml");
    CHECK(std::equal(stress.triangles.begin(), stress.triangles.end(), again.triangles.begin(),
                     [](const Triangle& a, const Triangle& b) {
                         return a.v0 == b.v0 && a.v1 == b.v1 && a.v2 == b.v2 &&
                                a.material == b.material;
                     }));

    if (std::filesystem::exists("/usr/share/glmark2/models/bunny.obj")) {
        const Scene bunny = load_scene(dir / "bunny.toml");
        CHECK(bunny.triangles.size() == 69666);
        CHECK(bunny.warnings.empty());
    } else {
        WARN("SKIPPED bunny.toml: install glmark2-data");
    }
}

TEST_CASE("A scene file's [accel] table is read; settings stack, the one above winning",
          "[scenefile]") {
    const auto path = scene_with("accel.toml", R"(
[accel]
structure = "bvh4"
bvh_boxes = "quantized"
grid_density = 2
bvh_align_pairs = true
[[meshes]]
path = "tri.obj"
)");
    const AccelSettings file = load_accel_settings(path);
    CHECK(file.structure == AccelStructure::bvh4);
    CHECK(file.bvh_boxes == BvhBoxes::quantized);
    CHECK(file.grid_density == 2.0);
    CHECK(file.bvh_align_pairs == true);
    CHECK_FALSE(file.max_leaf);
    CHECK_NOTHROW(load_scene(path));  // the loader accepts the table it checks

    AccelSettings command;
    command.structure = AccelStructure::bvh8;
    command.max_leaf = 2;
    const AccelSettings merged = file.under(command);
    CHECK(merged.structure == AccelStructure::bvh8);
    CHECK(merged.max_leaf == 2u);
    CHECK(merged.bvh_boxes == BvhBoxes::quantized);
    const AccelConfigs configs = accel_configs(merged);
    CHECK(configs.bvh.max_leaf_size == 2);
    CHECK(configs.bvh.boxes == BvhBoxes::quantized);
    CHECK(configs.grid.density == 2.0);
    CHECK(configs.kdtree.max_depth == KdTreeConfig{}.max_depth);

    // What is set, by name, sets the same again (a sweep plan stores settings so).
    AccelSettings again;
    for (const auto& [name, value] : accel_setting_values(merged))
        CHECK(set_accel_setting(again, name, value).empty());
    CHECK(again == merged);
    CHECK(load_accel_settings(write_file("tri_only.obj", kTriangleObj)) == AccelSettings{});
}

TEST_CASE("A bad [accel] setting names its key, the file and the line", "[scenefile]") {
    CHECK(error_of(scene_with("accel_depth.toml", "[accel]\noctree_max_depth = 99\n"
                                                  "[[meshes]]\npath = \"tri.obj\"\n"))
              .ends_with("accel_depth.toml:2:20: accel.octree_max_depth must be a whole number "
                         "in [0, 16], got 99"));
    CHECK(error_of(scene_with("accel_order.toml", "[accel]\nbvh_order = 3\n"
                                                  "[[meshes]]\npath = \"tri.obj\"\n"))
              .ends_with("accel_order.toml:2:13: accel.bvh_order must be one of breadth-first, "
                         "depth-first, van-emde-boas, got 3"));
    CHECK(error_of(scene_with("accel_flag.toml", "[accel]\nbvh_align_pairs = \"yes\"\n"
                                                 "[[meshes]]\npath = \"tri.obj\"\n"))
              .ends_with("accel.bvh_align_pairs must be true or false, got \"yes\""));
}
