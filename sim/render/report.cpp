#include "sim/render/report.hpp"

#include <cmath>

#include <algorithm>
#include <optional>
#include <ostream>

#include <fmt/format.h>
#include <fmt/ostream.h>

#include "sim/energy/energy.hpp"
#include "sim/render/profile.hpp"
#include "sim/render/timing_run.hpp"
#include "sim/stats/thousands.hpp"

namespace tpsim::render {

namespace {

std::string_view engine_name(Engine engine) {
    switch (engine) {
    case Engine::functional:
        return "functional";
    case Engine::native:
        return "native";
    case Engine::timing:
        return "timing";
    }
    return "";
}

/// "12.3 KiB": bytes in the largest binary unit that keeps the number >= 1.
std::string bytes_text(double bytes) {
    const char* units[] = {"B", "KiB", "MiB", "GiB", "TiB"};
    size_t u = 0;
    while (bytes >= 1024 && u + 1 < std::size(units)) {
        bytes /= 1024;
        ++u;
    }
    return u == 0 ? fmt::format("{:.0f} B", bytes) : fmt::format("{:.1f} {}", bytes, units[u]);
}

/// "12,345,678": a count with thousands separators.
std::string count_text(double count) {
    return stats::with_thousands(fmt::format("{}", uint64_t(count)));
}

std::string percent_text(double numerator, double denominator) {
    return denominator > 0 ? fmt::format("{:.1f}%", 100 * numerator / denominator) : "-";
}

/// "1 host thread", "2 host threads", "1-2 host threads (2 for 64 % of the instructions)".
std::string host_threads_text(const RenderResult& r) {
    const uint32_t n = r.host_threads;
    if (n == 1) return "1 host thread";
    if (r.host_threads_share >= 1) return fmt::format("{} host threads", n);
    return fmt::format("1-{} host threads ({} for {:.0f} % of the instructions)", n, n,
                       100 * r.host_threads_share);
}

bool has_value(const stats::Snapshot& snapshot, std::string_view name) {
    return std::any_of(snapshot.values().begin(), snapshot.values().end(),
                       [&](const stats::Value& v) { return v.name == name; });
}

}  // namespace

std::string display_path(const std::filesystem::path& path) {
    std::error_code ec;
    const std::filesystem::path relative = std::filesystem::proximate(path, ec);
    return !ec && !relative.empty() && *relative.begin() != ".." ? relative.string()
                                                                 : path.string();
}

std::string describe_config(const timing::ChipConfig& chip) {
    std::string changed;
    const std::vector<timing::ConfigField> defaults = timing::config_fields({});
    const std::vector<timing::ConfigField> fields = timing::config_fields(chip);
    for (size_t i = 0; i < fields.size(); ++i)
        if (fields[i] != defaults[i])
            changed += fmt::format("{}{}={}", changed.empty() ? "" : ", ", fields[i].key,
                                   fields[i].text());
    return changed.empty() ? "the defaults (configs/trax.toml)"
                           : "the defaults (configs/trax.toml) except " + changed;
}

std::vector<std::string> region_names(const stats::Snapshot& snapshot) {
    std::vector<std::string> names;
    for (const stats::Value& v : snapshot.values()) {
        if (!v.name.starts_with("region/")) continue;
        const size_t end = v.name.find('/', 7);
        const std::string name = v.name.substr(7, end - 7);
        if (std::find(names.begin(), names.end(), name) == names.end()) names.push_back(name);
    }
    return names;
}

void print_traffic(const stats::Snapshot& snapshot, uint32_t line_bytes, std::ostream& out) {
    const std::vector<std::string> regions = region_names(snapshot);
    if (regions.empty()) return;
    const auto get = [&](const std::string& region, std::string_view leaf) {
        return snapshot.value(fmt::format("region/{}/{}", region, leaf));
    };
    fmt::print(out, "\ntraffic  {:<14} {:>12} {:>7} {:>10} {:>7} {:>11} {:>12} {:>13}\n", "region",
               "L1 accesses", "L1 hit", "L2 reads", "L2 hit", "DRAM read", "DRAM written",
               "store payload");
    for (const std::string& region : regions) {
        if (region == "local_store") {
            fmt::print(
                out, "         {:<14} {:>12}  loads and stores, {} (private: no cache)\n",
                "local store",
                count_text(get(region, "local_store/loads") + get(region, "local_store/stores")),
                bytes_text(get(region, "local_store/payload_bytes")));
            continue;
        }
        if (region == "instruction_fetch") {
            const double fetches = get(region, "icache/fetches");
            if (!has_value(snapshot, "region/instruction_fetch/l2/reads")) {
                fmt::print(out, "         {:<14} {:>12}  fetches (the I-cache never misses)\n",
                           "instructions", count_text(fetches));
                continue;
            }
            // A finite I-cache: its hits, and its line requests to the L2 and DRAM.
            // Hits: lookups that neither missed nor found every MSHR busy.
            const double not_hits = snapshot.value("chip/icache/misses") +
                                    snapshot.value("chip/icache/merged_misses") +
                                    snapshot.value("chip/icache/mshr_full");
            const double l2_reads = get(region, "l2/reads");
            fmt::print(out, "         {:<14} {:>12} {:>7} {:>10} {:>7} {:>11}  (I-cache fetches)\n",
                       "instructions", count_text(fetches),
                       percent_text(fetches - not_hits, fetches), count_text(l2_reads),
                       percent_text(get(region, "l2/hits"), l2_reads),
                       bytes_text(get(region, "dram/reads") * line_bytes));
            continue;
        }
        const double l1_reads = get(region, "l1/reads"), l1_writes = get(region, "l1/writes");
        const double l2_reads = get(region, "l2/reads");
        if (l1_reads + l1_writes == 0) continue;  // an untouched region
        // DRAM moves whole lines; the store payload is what the kernel's stores carried.
        const double read_bytes = get(region, "dram/reads") * line_bytes;
        const double written_bytes = get(region, "dram/writes") * line_bytes;
        const double store_payload = get(region, "dram/payload_bytes") - read_bytes;
        fmt::print(out, "         {:<14} {:>12} {:>7} {:>10} {:>7} {:>11} {:>12} {:>13}\n", region,
                   count_text(l1_reads + l1_writes), percent_text(get(region, "l1/hits"), l1_reads),
                   count_text(l2_reads), percent_text(get(region, "l2/hits"), l2_reads),
                   bytes_text(read_bytes), bytes_text(written_bytes), bytes_text(store_payload));
    }
}

void print_energy(const stats::Snapshot& snapshot, std::ostream& out) {
    const auto has = [&](std::string_view name) {
        return std::any_of(snapshot.values().begin(), snapshot.values().end(),
                           [&](const stats::Value& v) { return v.name == name; });
    };
    if (!has("energy/total")) return;
    const double joules = snapshot.value("energy/total");
    const double area = snapshot.value("area/total");
    fmt::print(out, "\nenergy   {:<16} {:>12} {:>7} {:>13} {:>7}\n", "part", "energy", "share",
               "area", "share");
    const auto row = [&](std::string_view name, double j, std::optional<double> mm2) {
        fmt::print(out, "         {:<16} {:>9.4f} mJ {:>7} {:>13} {:>7}\n", name, j * 1e3,
                   percent_text(j, joules),
                   mm2 ? fmt::format("{:.3f} mm^2", *mm2) : std::string("-"),
                   mm2 ? percent_text(*mm2, area) : "-");
    };
    for (const energy::Part& part : energy::estimate(timing::ChipConfig{}, {}).parts) {
        const std::string area_key = "area/" + part.name;
        row(part.name, snapshot.value("energy/" + part.name),
            has(area_key) ? std::optional<double>(snapshot.value(area_key)) : std::nullopt);
    }
    row("total", joules, area);
}

void register_stats(const RenderResult& r, stats::Registry& reg) {
    const auto number = [&reg](std::string name, auto get, std::string description,
                               std::string unit = "") {
        reg.add_derived(
            std::move(name), [get] { return double(get()); }, std::move(description),
            std::move(unit));
    };
    number(
        "scene/triangles", [&r] { return r.scene.triangles.size(); }, "triangles in the scene");
    number(
        "scene/lights", [&r] { return r.scene.lights.size(); }, "point lights");
    number(
        "scene/materials", [&r] { return r.scene.materials.size(); }, "materials used");
    number(
        "image/pixels", [&r] { return uint64_t(r.scene.width) * r.scene.height; },
        "pixels rendered");
    number(
        "image/samples_per_pixel", [&r] { return r.scene.samples_per_pixel; },
        "camera rays per pixel");

    for (const image::SectionSize& s : r.image.sections)
        number(
            "memory/" + s.name + "_bytes", [&s] { return s.bytes; },
            fmt::format("memory image: {} ({} records)", s.name, s.records), "B");
    number(
        "memory/total_bytes", [&r] { return r.image.bytes(); },
        "memory image incl. alignment padding and framebuffer", "B");

    if (r.bvh) {
        const scene::BvhStats& b = *r.bvh;
        number(
            "bvh/nodes", [&b] { return b.nodes; }, "BVH nodes (interior + leaves)");
        number(
            "bvh/leaves", [&b] { return b.leaves; }, "BVH leaves");
        number(
            "bvh/max_depth", [&b] { return b.max_depth; },
            "edges from the root to the deepest leaf");
        number(
            "bvh/sah_cost", [&b] { return b.sah_cost; },
            "SAH cost (traversal 1, intersection 1, relative to the root's area)");
        number(
            "bvh/depth_limited_nodes", [&b] { return b.depth_limited_nodes; },
            "nodes where the traversal-stack depth limit overrode the SAH");
        number(
            "host/bvh_seconds", [&r] { return r.bvh_seconds; }, "BVH build time", "s");
    }
    if (r.wide_bvh) {
        const scene::WideBvhStats& w = *r.wide_bvh;
        number(
            "wide_bvh/width", [&w] { return w.width; }, "children per wide BVH node, at most");
        number(
            "wide_bvh/nodes", [&w] { return w.nodes; }, "wide BVH nodes");
        number(
            "wide_bvh/leaves", [&w] { return w.leaves; }, "wide BVH leaves");
        number(
            "wide_bvh/max_depth", [&w] { return w.max_depth; },
            "wide nodes from the root to the deepest leaf");
        number(
            "wide_bvh/mean_children", [&w] { return w.mean_children; },
            "children per wide node, on average");
        number(
            "wide_bvh/worst_stack", [&w] { return w.worst_stack; },
            "most traversal-stack entries a ray could need");
        number(
            "host/wide_bvh_seconds", [&w] { return w.collapse_seconds; },
            "time to collapse the binary BVH into the wide one", "s");
    }
    if (r.grid) {
        const scene::GridStats& g = *r.grid;
        number(
            "grid/cells", [&g] { return g.cells; }, "uniform grid cells", "cells");
        for (int a = 0; a < 3; ++a)
            number(
                fmt::format("grid/resolution_{}", "xyz"[a]), [&g, a] { return g.resolution[a]; },
                fmt::format("grid cells along {}", "xyz"[a]), "cells");
        number(
            "grid/references", [&g] { return g.references; },
            "triangle entries over all cells (a triangle in k cells counts k)");
        number(
            "grid/references_per_triangle",
            [&g, &r] { return double(g.references) / double(r.scene.triangles.size()); },
            "cells a triangle is listed in, on average");
        number(
            "grid/empty_cells", [&g] { return g.empty_cells; }, "cells with no triangle", "cells");
        number(
            "grid/max_cell_triangles", [&g] { return g.max_cell_triangles; },
            "most triangles listed in one cell");
        number(
            "host/grid_seconds", [&r] { return r.grid_seconds; }, "grid build time", "s");
    }
    if (r.kdtree) {
        // The kd-tree's keys, or the BSP tree's (the same builder).
        const scene::KdTreeStats& k = *r.kdtree;
        const std::string prefix(scene::to_string(r.accel));
        const std::string tree = r.accel == scene::AccelStructure::bsp ? "BSP tree" : "kd-tree";
        number(
            prefix + "/nodes", [&k] { return k.nodes; }, tree + " nodes (interior + leaves)");
        number(
            prefix + "/leaves", [&k] { return k.leaves; }, tree + " leaves");
        number(
            prefix + "/empty_leaves", [&k] { return k.empty_leaves; },
            tree + " leaves with no triangle");
        number(
            prefix + "/max_depth", [&k] { return k.max_depth; },
            "edges from the root to the deepest leaf");
        number(
            prefix + "/references", [&k] { return k.references; },
            "leaf entries (a triangle in k leaves counts k)");
        number(
            prefix + "/references_per_triangle",
            [&k, &r] { return double(k.references) / double(r.scene.triangles.size()); },
            "leaves a triangle is listed in, on average");
        number(
            prefix + "/max_leaf_triangles", [&k] { return k.max_leaf_triangles; },
            "most triangles listed in one leaf");
        if (r.accel == scene::AccelStructure::bsp)
            number(
                "bsp/diagonal_planes", [&k] { return k.diagonal_planes; },
                "interior nodes whose plane is a face or space diagonal's, not an axis's");
        number(
            "host/" + prefix + "_seconds", [&r] { return r.kdtree_seconds; }, tree + " build time",
            "s");
    }
    if (r.octree) {
        const scene::OctreeStats& o = *r.octree;
        number(
            "octree/nodes", [&o] { return o.nodes; },
            "octree node slots (empty octants' and the root group's included)");
        number(
            "octree/interior", [&o] { return o.interior; }, "octree cells cut into eight");
        number(
            "octree/leaves", [&o] { return o.leaves; }, "octree leaves (cells with triangles)");
        number(
            "octree/max_depth", [&o] { return o.max_depth; },
            "edges from the root to the deepest leaf");
        number(
            "octree/references", [&o] { return o.references; },
            "leaf entries (a triangle in k leaves counts k)");
        number(
            "octree/references_per_triangle",
            [&o, &r] { return double(o.references) / double(r.scene.triangles.size()); },
            "leaves a triangle is listed in, on average");
        number(
            "octree/max_leaf_triangles", [&o] { return o.max_leaf_triangles; },
            "most triangles listed in one leaf");
        number(
            "host/octree_seconds", [&r] { return r.octree_seconds; }, "octree build time", "s");
    }

    const image::TraversalTotals& t = r.traversal;
    const auto per_ray = [&t](uint64_t count) {
        return t.rays() > 0 ? double(count) / double(t.rays()) : 0.0;
    };
    number(
        "rays/total", [&t] { return t.rays(); }, "rays traced (primary + shadow)", "rays");
    number(
        "rays/primary", [&t] { return t.primary_rays; }, "closest-hit (camera) rays", "rays");
    number(
        "rays/shadow", [&t] { return t.shadow_rays; }, "any-hit (shadow) rays", "rays");
    number(
        "traversal/nodes_per_ray", [&t, per_ray] { return per_ray(t.nodes_visited); },
        "BVH node boxes tested (grid cells walked) per ray, on average", "nodes");
    number(
        "traversal/triangles_per_ray", [&t, per_ray] { return per_ray(t.triangles_tested); },
        "ray/triangle tests per ray, on average", "triangles");
    number(
        "traversal/max_stack_depth", [&t] { return t.max_stack_depth; },
        "most traversal-stack entries any ray used", "entries");

    if (r.instructions.total > 0) {
        reg.add_counter("instructions/total", r.instructions.total, "instructions executed",
                        "instructions");
        for (size_t fu = 0; fu < r.instructions.per_fu.size(); ++fu)
            if (r.instructions.per_fu[fu] != 0)
                reg.add_counter(fmt::format("instructions/fu/{}", isa::to_string(isa::FuClass(fu))),
                                r.instructions.per_fu[fu], "instructions of this FU class",
                                "instructions");
        for (size_t op = 0; op < r.instructions.per_op.size(); ++op)
            if (r.instructions.per_op[op] != 0)
                reg.add_counter(fmt::format("instructions/op/{}", isa::info(isa::Op(op)).mnemonic),
                                r.instructions.per_op[op], "instructions with this opcode",
                                "instructions");
        const energy::RegisterAccesses rf = energy::register_accesses(r.instructions.per_op);
        number(
            "registers/reads", [rf] { return rf.reads; },
            "register-file reads: the source registers of every executed instruction", "accesses");
        number(
            "registers/writes", [rf] { return rf.writes; },
            "register-file writes: the destination register of every executed instruction",
            "accesses");
    }
    if (r.timing) {
        r.timing->chip->register_stats(reg);
        if (reg.contains("rays/total"))
            reg.add_formula(
                "chip/rays_per_second", {"rays/total", "chip/frame_seconds"},
                [](std::span<const double> v) { return v[1] > 0 ? v[0] / v[1] : 0.0; },
                "rays traced per simulated second (rays/total / chip/frame_seconds)", "rays/s");
        energy::register_stats(r.timing->config, reg);
    }
    number(
        "host/load_seconds", [&r] { return r.load_seconds; }, "scene load and import time", "s");
    number(
        "host/run_seconds", [&r] { return r.run_seconds; }, "kernel run time on the host", "s");
    if (r.instructions.total > 0) {
        number(
            "host/simulated_instructions_per_second",
            [&r] { return r.run_seconds > 0 ? double(r.instructions.total) / r.run_seconds : 0.0; },
            "simulation speed", "instr/s");
        number(
            "host/threads", [&r] { return double(r.host_threads); },
            "most host threads the kernel run used", "threads");
        number(
            "host/threads_share", [&r] { return r.host_threads_share; },
            "share of the instructions simulated on host/threads threads (the rest on one)");
    }
}

RunStatistics run_statistics(const RenderResult& result) {
    RunStatistics statistics;
    register_stats(result, statistics.registry);
    statistics.values = stats::Snapshot(statistics.registry);
    if (result.timing && result.timing->sampling && !result.timing->sampling->exact) {
        statistics.estimate =
            stats::estimate(statistics.registry, statistics.values, result.timing->samples);
        statistics.values = statistics.estimate->values;
    }
    return statistics;
}

namespace {

/// "1234567 ± 0.8 %": an estimate with its interval relative to it.
std::string with_interval(const stats::Estimate& e, std::string_view name, std::string value) {
    const double estimate = e.values.value(name);
    const double half = e.interval(name);
    if (std::isnan(half))
        return fmt::format("{} ± ? (too rare: fewer than 5 units saw one)", value);
    return estimate != 0 ? fmt::format("{} ± {:.2f} %", value, 100 * half / std::abs(estimate))
                         : fmt::format("{} ± {:.3g}", value, half);
}

void print_sampling(const RenderResult& r, const stats::Estimate& e, std::ostream& out) {
    const SamplingSummary& s = *r.timing->sampling;
    const double total = double(r.instructions.total);
    fmt::print(out,
               "sampled  ESTIMATES, {:.0f} % confidence: {} units of {} cycles after {} cycles "
               "of warm-up, one per {} instructions (rate {}, seed {}); head and tail measured "
               "whole ({:.1f} % of the instructions), {:.1f} % functionally warmed, {} cycles "
               "simulated\n",
               100 * e.confidence, s.units, s.options.unit_cycles, s.options.warmup_cycles,
               s.period_instructions, s.options.rate, s.options.seed,
               100 * double(s.head_instructions + s.tail_instructions) / total,
               100 * double(s.warmed_instructions) / total, s.simulated_cycles);
    const auto row = [&](std::string_view label, std::string_view name, std::string value) {
        fmt::print(out, "         {:<22} {}\n", label, with_interval(e, name, std::move(value)));
    };
    row("frame cycles", "chip/cycles", fmt::format("{:.0f}", e.values.value("chip/cycles")));
    row("issue rate", "chip/issue_rate", fmt::format("{:.4f}", e.values.value("chip/issue_rate")));
    row("L1 hit rate", "chip/l1/hit_rate",
        fmt::format("{:.4f}", e.values.value("chip/l1/hit_rate")));
    row("L2 hit rate", "chip/l2/hit_rate",
        fmt::format("{:.4f}", e.values.value("chip/l2/hit_rate")));
    row("DRAM bytes read", "dram/bytes_read",
        fmt::format("{:.0f}", e.values.value("dram/bytes_read")));
    row("DRAM bytes written", "dram/bytes_written",
        fmt::format("{:.0f}", e.values.value("dram/bytes_written")));
    if (s.too_few_units())
        fmt::print(out,
                   "         WARNING: only {} units; intervals from fewer than {} come out too "
                   "narrow (docs/error-vs-time.md): --sample-rate {:.2g} would measure about {}\n",
                   s.units, SamplingSummary::kTrustedUnits, s.rate_for_trusted_units(),
                   SamplingSummary::kTrustedUnits);
}

}  // namespace

void print_summary(const RenderOptions& options, const RenderResult& r,
                   const RunStatistics& statistics, std::ostream& out) {
    // What the command line overrode is marked, and the seed shown to kernels that read it.
    const auto overridden = [](uint32_t value) { return value != 0 ? " (set by option)" : ""; };
    const bool has_extras =
        std::any_of(r.image.sections.begin(), r.image.sections.end(),
                    [](const image::SectionSize& s) { return s.name == "extras"; });
    fmt::print(out,
               "scene    {} ({} triangles, {} lights, {} materials), {}x{} pixels{}, {} spp{}{}\n",
               options.scene.string(), r.scene.triangles.size(), r.scene.lights.size(),
               r.scene.materials.size(), r.scene.width, r.scene.height,
               overridden(options.image_width | options.image_height), r.scene.samples_per_pixel,
               overridden(options.samples_per_pixel),
               has_extras ? fmt::format(", seed {}", options.seed) : "");
    fmt::print(out, "kernel   {}{} on {} ({} TMs x {} TPs = {} threads)\n",
               display_path(options.kernel),
               r.params.empty() ? "" : " (" + describe_params(r.params) + ")",
               options.engine == Engine::native   ? "the native twin"
               : options.engine == Engine::timing ? "the cycle-level chip model"
                                                  : "the functional simulator",
               options.chip.chip.num_tms, options.chip.chip.tps_per_tm, r.threads);
    fmt::print(out, "config   {}\n", describe_config(options.chip));
    fmt::print(out,
               "memory   {:.1f} KiB ({:.1f} KiB read-only scene):", double(r.image.bytes()) / 1024,
               double(r.image.read_only_bytes()) / 1024);
    const char* separator = " ";
    for (const image::SectionSize& s : r.image.sections)
        if (s.records > 0) {
            fmt::print(out, "{}{} {:.1f} KiB", separator, s.name, double(s.bytes) / 1024);
            separator = ", ";
        }
    fmt::print(out, "\n");
    if (r.bvh)
        fmt::print(out,
                   "bvh      {} nodes, {} leaves, depth {}, SAH cost {:.2f}, built in {:.3f} s{}\n",
                   r.bvh->nodes, r.bvh->leaves, r.bvh->max_depth, r.bvh->sah_cost, r.bvh_seconds,
                   r.bvh->depth_limited_nodes
                       ? fmt::format(" (depth limit shaped {} nodes)", r.bvh->depth_limited_nodes)
                       : "");
    if (r.wide_bvh) {
        const scene::WideBvhStats& w = *r.wide_bvh;
        fmt::print(out,
                   "{:<8} {} nodes, {} leaves, depth {}, {:.2f} children per node, {} boxes, "
                   "collapsed in {:.3f} s\n",
                   scene::to_string(r.accel), w.nodes, w.leaves, w.max_depth, w.mean_children,
                   scene::to_string(r.accel_configs.bvh.boxes), w.collapse_seconds);
    }
    if (r.grid) {
        const scene::GridStats& g = *r.grid;
        fmt::print(out,
                   "grid     {}x{}x{} = {} cells, {} references ({:.2f} per triangle), {:.1f} % "
                   "empty, at most {} in a cell, built in {:.3f} s\n",
                   g.resolution[0], g.resolution[1], g.resolution[2], g.cells, g.references,
                   double(g.references) / double(r.scene.triangles.size()),
                   100.0 * double(g.empty_cells) / double(g.cells), g.max_cell_triangles,
                   r.grid_seconds);
    }
    if (r.kdtree) {
        const scene::KdTreeStats& k = *r.kdtree;
        fmt::print(out,
                   "{:<8} {} nodes, {} leaves ({} empty), depth {} (limit {}), {} references "
                   "({:.2f} per triangle), at most {} in a leaf, built in {:.3f} s\n",
                   scene::to_string(r.accel), k.nodes, k.leaves, k.empty_leaves, k.max_depth,
                   k.depth_limit, k.references,
                   double(k.references) / double(r.scene.triangles.size()), k.max_leaf_triangles,
                   r.kdtree_seconds);
        if (r.accel == scene::AccelStructure::bsp)
            fmt::print(out, "         {} of {} planes diagonal\n", k.diagonal_planes,
                       k.nodes - k.leaves);
    }
    if (r.octree) {
        const scene::OctreeStats& o = *r.octree;
        fmt::print(out,
                   "octree   {} cells cut, {} leaves, depth {} (limit {}), {} references ({:.2f} "
                   "per triangle), at most {} in a leaf, built in {:.3f} s\n",
                   o.interior, o.leaves, o.max_depth, o.depth_limit, o.references,
                   double(o.references) / double(r.scene.triangles.size()), o.max_leaf_triangles,
                   r.octree_seconds);
    }
    if (r.traversal.rays() > 0) {
        const double rays = double(r.traversal.rays());
        fmt::print(out, "rays     {} ({} primary, {} shadow): {:.1f} {}, {:.1f} triangles per ray",
                   r.traversal.rays(), r.traversal.primary_rays, r.traversal.shadow_rays,
                   double(r.traversal.nodes_visited) / rays, r.grid ? "cells" : "nodes",
                   double(r.traversal.triangles_tested) / rays);
        if (r.grid)
            fmt::print(out, "\n");
        else
            fmt::print(out, ", stack depth up to {}\n", r.traversal.max_stack_depth);
    }
    if (r.timing) {
        // From the statistics, so that a sampled run shows its estimates.
        const double cycles = statistics.values.value("chip/cycles");
        const double seconds = cycles / (options.chip.chip.clock_mhz * 1e6);
        fmt::print(out,
                   "timing   {}{:.0f} cycles = {:.3f} ms at {} MHz ({:.1f} frames/s), {:.2f} "
                   "instructions per TP-cycle{}\n",
                   statistics.estimate ? "~" : "", cycles, seconds * 1e3,
                   options.chip.chip.clock_mhz, 1 / seconds,
                   double(r.instructions.total) / (cycles * r.threads),
                   r.traversal.rays() > 0 ? fmt::format(", {:.1f} M rays/s",
                                                        double(r.traversal.rays()) / seconds / 1e6)
                                          : "");
    }
    if (r.timing) {  // the cycle-level engine registered the energy estimate
        const stats::Snapshot& s = statistics.values;
        const auto get = [&](std::string_view name) { return s.value(name); };
        const bool rays = r.traversal.rays() > 0;
        fmt::print(out,
                   "energy   {}{:.3f} mJ per frame{}, {:.2f} W average at {} MHz{} (65 nm "
                   "estimate, docs/energy.md)\n",
                   statistics.estimate ? "~" : "", get("energy/total") * 1e3,
                   rays ? fmt::format(" = {:.2f} nJ per ray", get("energy/per_ray") * 1e9) : "",
                   get("energy/average_watts"), options.chip.chip.clock_mhz,
                   rays ? fmt::format(", {:.1f} M rays/J", get("energy/mrays_per_joule")) : "");
        fmt::print(out, "area     {:.2f} mm^2 (65 nm)\n", get("area/total"));
    }
    if (r.timing && has_value(statistics.values, "chip/icache/misses")) {
        const stats::Snapshot& v = statistics.values;
        fmt::print(
            out,
            "icache   {} misses and {} merged misses in {} fetches ({:.2f} % missed), {} TP-cycles "
            "of fetch-miss stalls ({} of active TP-cycles)\n",
            count_text(v.value("chip/icache/misses")),
            count_text(v.value("chip/icache/merged_misses")),
            count_text(v.value("chip/icache/fetches")), 100 * v.value("chip/icache/miss_rate"),
            count_text(v.value("chip/stalls/fetch_miss")),
            percent_text(v.value("chip/stalls/fetch_miss"), v.value("chip/active_tp_cycles")));
    }
    if (r.instructions.total > 0)
        fmt::print(out,
                   "run      {} instructions in {:.3f} s = {:.1f} M simulated instructions/s on "
                   "{}\n",
                   r.instructions.total, r.run_seconds,
                   double(r.instructions.total) / r.run_seconds / 1e6, host_threads_text(r));
    else
        fmt::print(out, "run      {:.3f} s\n", r.run_seconds);
    if (statistics.estimate) print_sampling(r, *statistics.estimate, out);
}

nlohmann::ordered_json stats_document(const RenderOptions& options, const RenderResult& r,
                                      const RunStatistics& statistics,
                                      const std::filesystem::path& json_path,
                                      const OutputPaths& outputs) {
    const stats::Snapshot& snapshot = statistics.values;
    const std::filesystem::path base =
        json_path.has_parent_path() ? json_path.parent_path() : std::filesystem::path(".");
    const auto relative = [&](const std::filesystem::path& path) {
        return std::filesystem::proximate(path, base).generic_string();
    };
    nlohmann::ordered_json doc;
    doc["format"] = "tpsim-stats";
    doc["version"] = kStatsFileVersion;
    nlohmann::ordered_json& run = doc["run"];
    run["scene"] = options.scene.generic_string();
    run["kernel"] = options.kernel.generic_string();
    run["kernel_name"] = options.kernel.stem().string();
    run["engine"] = engine_name(options.engine);
    // How the cycle-level engine ran: every cycle, or sampled (its figures are estimates).
    if (r.timing) run["timing"] = r.timing->sampling ? "sampled" : "cycle";
    run["accel"] = scene::to_string(r.accel);
    if (r.grid) {
        run["grid_resolution"] = r.accel_configs.grid.resolution;
        run["grid_density"] = r.accel_configs.grid.density;
    }
    if (r.kdtree) {
        run["kdtree_max_depth"] = r.accel_configs.kdtree.max_depth;
        run["kdtree_max_references"] = r.accel_configs.kdtree.max_references_per_triangle;
    }
    if (r.octree) run["octree_max_depth"] = r.accel_configs.octree.max_depth;
    run["bvh_builder"] = scene::to_string(r.accel_configs.bvh.builder);
    run["max_leaf"] = r.accel_configs.bvh.max_leaf_size;
    run["bvh_order"] = scene::to_string(r.accel_configs.bvh.order);
    run["bvh_align_pairs"] = r.accel_configs.bvh.align_pairs;
    run["bvh_boxes"] = scene::to_string(r.accel_configs.bvh.boxes);
    run["width"] = r.scene.width;
    run["height"] = r.scene.height;
    run["samples_per_pixel"] = r.scene.samples_per_pixel;
    run["seed"] = options.seed;
    if (!r.params.empty()) {
        nlohmann::ordered_json& params = run["params"];
        for (const KernelParam& p : r.params)
            params[p.name] = nlohmann::ordered_json::parse(p.text());
    }
    run["threads"] = r.threads;
    run["image"] = relative(outputs.image);
    if (!outputs.heatmap.empty()) run["heatmap"] = relative(outputs.heatmap);
    nlohmann::ordered_json& config = doc["config"];
    for (const timing::ConfigField& field : timing::config_fields(options.chip)) {
        if (field.is_real)
            config[field.key] = field.real;
        else if (field.is_bool)
            config[field.key] = field.value != 0;
        else
            config[field.key] = field.value;
    }
    doc["stats"] = stats::values_json(snapshot);
    doc["units"] = stats::units_json(snapshot);
    if (const std::vector<std::string> regions = region_names(snapshot); !regions.empty())
        doc["regions"] = regions;
    if (r.timing && r.timing->timeline) doc["timeline"] = r.timing->timeline->json();
    if (r.timing && r.timing->sampling) {
        const SamplingSummary& s = *r.timing->sampling;
        nlohmann::ordered_json& sampling = doc["sampling"];
        sampling["rate"] = s.options.rate;
        sampling["unit_cycles"] = s.options.unit_cycles;
        sampling["warmup_cycles"] = s.options.warmup_cycles;
        sampling["seed"] = s.options.seed;
        sampling["units"] = s.units;
        sampling["trusted_units"] = SamplingSummary::kTrustedUnits;
        sampling["too_few_units"] = s.too_few_units();
        sampling["period_instructions"] = s.period_instructions;
        sampling["head_instructions"] = s.head_instructions;
        sampling["body_instructions"] = s.body_instructions;
        sampling["tail_instructions"] = s.tail_instructions;
        sampling["warmed_instructions"] = s.warmed_instructions;
        sampling["simulated_cycles"] = s.simulated_cycles;
        sampling["estimated"] = statistics.estimate.has_value();
        if (statistics.estimate) {
            const stats::Estimate& e = *statistics.estimate;
            sampling["confidence"] = e.confidence;
            nlohmann::ordered_json intervals = nlohmann::ordered_json::object();
            for (size_t i = 0; i < e.half_width.size(); ++i)
                if (e.half_width[i] != 0)  // null: unknown (stats::Estimate::half_width)
                    intervals[e.values.values()[i].name] =
                        std::isnan(e.half_width[i]) ? nlohmann::ordered_json()
                                                    : nlohmann::ordered_json(e.half_width[i]);
            doc["intervals"] = std::move(intervals);
        }
    }
    if (r.profile) doc["profile"] = profile_json(*r.profile);
    return doc;
}

}  // namespace tpsim::render
