// bench_accel [--threads N] [scene-or-mesh ...]: loads each scene and builds each acceleration
// structure: the BVH with both SAH builders (build time as wall clock and the process's CPU
// time, all threads; node count, depth, SAH cost), the BVH's image layout in each node order,
// its collapse into the 4- and 8-wide BVHs and their layout in both box formats, the uniform
// grid by the density rule and the kd-tree. Defaults to the bunny and the stress scene, and to
// oneTBB's default thread count (the host's cores).
#include <chrono>
#include <ctime>
#include <exception>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <oneapi/tbb/global_control.h>

#include "sim/image/memory_image.hpp"
#include "sim/scene/bvh.hpp"
#include "sim/scene/grid.hpp"
#include "sim/scene/kdtree.hpp"
#include "sim/scene/load_scene.hpp"
#include "sim/scene/octree.hpp"
#include "sim/scene/wide_bvh.hpp"

namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

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
        fmt::print("\n{:<14} {:<34} {:>9} {:>9} {:>12} {:>10}\n", "scene", "structure", "build_ms",
                   "cpu_ms", "size", "refs/tri");
        for (const auto& path : paths) {
            const Scene scene = load_scene(path);
            const Bvh bvh = build_bvh(scene.triangles);
            for (BvhOrder order : kBvhOrders) {
                const double cpu_start = cpu_seconds();
                const auto start = std::chrono::steady_clock::now();
                const auto nodes = tpsim::image::compile_bvh(bvh, order, true);
                const double wall = seconds_since(start), cpu = cpu_seconds() - cpu_start;
                fmt::print("{:<14} {:<34} {:>9.1f} {:>9.1f} {:>10.1f} M {:>10}\n", scene.name,
                           fmt::format("bvh2 layout, {}", to_string(order)), wall * 1e3, cpu * 1e3,
                           double(nodes.size() * sizeof(nodes[0])) / (1 << 20), "-");
            }
            for (uint32_t width : {4u, 8u}) {
                double cpu_start = cpu_seconds();
                auto start = std::chrono::steady_clock::now();
                const WideBvh wide = collapse_bvh(bvh, width);
                fmt::print("{:<14} {:<34} {:>9.1f} {:>9.1f} {:>12} {:>10}\n", scene.name,
                           fmt::format("bvh{} collapse", width), seconds_since(start) * 1e3,
                           (cpu_seconds() - cpu_start) * 1e3, "-", "-");
                for (BvhBoxes boxes : kBvhBoxes) {
                    cpu_start = cpu_seconds();
                    start = std::chrono::steady_clock::now();
                    const auto words =
                        tpsim::image::compile_wide_bvh(wide, BvhOrder::breadth_first, boxes, 0);
                    fmt::print("{:<14} {:<34} {:>9.1f} {:>9.1f} {:>10.1f} M {:>10}\n", scene.name,
                               fmt::format("bvh{} layout, {} boxes", width, to_string(boxes)),
                               seconds_since(start) * 1e3, (cpu_seconds() - cpu_start) * 1e3,
                               double(words.size() * 4) / (1 << 20), "-");
                }
            }
            // The structures that cut space into cells: build time, size, references per
            // triangle.
            const auto cells_row = [&](auto build, auto label) {
                const double cpu_start = cpu_seconds();
                const auto start = std::chrono::steady_clock::now();
                const auto built = build();
                const double wall = seconds_since(start), cpu = cpu_seconds() - cpu_start;
                fmt::print("{:<14} {:<34} {:>9.1f} {:>9.1f} {:>10.1f} M {:>10.2f}\n", scene.name,
                           label(built.stats), wall * 1e3, cpu * 1e3,
                           double(built.stats.bytes()) / (1 << 20),
                           double(built.references.size()) / double(scene.triangles.size()));
            };
            cells_row([&] { return build_grid(scene.triangles); },
                      [](const GridStats& g) {
                          return fmt::format("grid {}x{}x{}", g.resolution[0], g.resolution[1],
                                             g.resolution[2]);
                      });
            cells_row(
                [&] { return build_kdtree(scene.triangles); },
                [](const KdTreeStats& k) { return fmt::format("kdtree depth {}", k.max_depth); });
            cells_row(
                [&] {
                    KdTreeConfig bsp;
                    bsp.general_planes = true;
                    return build_kdtree(scene.triangles, bsp);
                },
                [](const KdTreeStats& k) { return fmt::format("bsp depth {}", k.max_depth); });
            cells_row(
                [&] { return build_octree(scene.triangles); },
                [](const OctreeStats& o) { return fmt::format("octree depth {}", o.max_depth); });
        }
    } catch (const std::exception& e) {
        fmt::print(stderr, "bench_accel: {}\n", e.what());
        return 1;
    }
    return 0;
}
