// bench_bvh [--threads N] [scene-or-mesh ...]: loads each scene, builds its BVH with both
// builders and prints build time (wall clock and the process's CPU time, all threads), node
// count, depth and SAH cost. Defaults to the bunny and the stress scene, and to oneTBB's default
// thread count (the host's cores).
#include <ctime>
#include <exception>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <oneapi/tbb/global_control.h>

#include "sim/scene/bvh.hpp"
#include "sim/scene/load_scene.hpp"

namespace {

double cpu_seconds() {
    timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

}  // namespace

int main(int argc, char** argv) {
    using namespace tpsim::scene;
    std::vector<std::filesystem::path> paths;
    std::optional<tbb::global_control> threads;
    for (int i = 1; i < argc; ++i) {
        if (std::string(argv[i]) == "--threads" && i + 1 < argc) {
            threads.emplace(tbb::global_control::max_allowed_parallelism, std::stoul(argv[++i]));
        } else {
            paths.push_back(argv[i]);
        }
    }
    if (paths.empty()) paths = {TPSIM_SCENES_DIR "/bunny.toml", TPSIM_SCENES_DIR "/stress.toml"};
    try {
        fmt::print("{:<14} {:>9} {:<7} {:>9} {:>9} {:>9} {:>6} {:>8} {:>9} {:>8}\n", "scene",
                   "triangles", "builder", "build_ms", "cpu_ms", "nodes", "depth", "sah", "leaves",
                   "limited");
        for (const auto& path : paths) {
            const Scene scene = load_scene(path);
            for (BvhBuilder builder : {BvhBuilder::sweep, BvhBuilder::binned}) {
                const double cpu_start = cpu_seconds();
                const Bvh bvh = build_bvh(scene.triangles, BvhConfig{.builder = builder});
                const double cpu = cpu_seconds() - cpu_start;
                const BvhStats& s = bvh.stats;
                fmt::print(
                    "{:<14} {:>9} {:<7} {:>9.1f} {:>9.1f} {:>9} {:>6} {:>8.3f} {:>9} {:>8}\n",
                    scene.name, scene.triangles.size(), to_string(builder), s.build_seconds * 1e3,
                    cpu * 1e3, s.nodes, s.max_depth, s.sah_cost, s.leaves, s.depth_limited_nodes);
            }
        }
    } catch (const std::exception& e) {
        fmt::print(stderr, "bench_bvh: {}\n", e.what());
        return 1;
    }
    return 0;
}
