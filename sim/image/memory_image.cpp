#include "sim/image/memory_image.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>

#include <fmt/format.h>

#include "kernel/memory_map.hpp"
#include "sim/core/error.hpp"

namespace tpsim::image {
namespace layout = trax::layout;

namespace {

void put(float (&out)[3], glm::vec3 v) {
    out[0] = v.x;
    out[1] = v.y;
    out[2] = v.z;
}

/// In double, narrowed once: a field of view just below 180° or a long thin image keeps its
/// shape (the scene compiler has checked that float holds the result).
layout::Camera compile_camera(const scene::Camera& c, uint32_t width, uint32_t height) {
    const glm::dvec3 forward = glm::normalize(glm::dvec3(c.look_at) - glm::dvec3(c.eye));
    const glm::dvec3 right = glm::normalize(glm::cross(forward, glm::dvec3(c.up)));
    const glm::dvec3 up = glm::cross(right, forward);
    const double half_height = std::tan(glm::radians(c.vertical_fov_degrees) * 0.5);
    const double half_width = half_height * double(width) / double(height);
    layout::Camera out{};
    put(out.eye, c.eye);
    put(out.corner, glm::vec3(forward - right * half_width + up * half_height));
    put(out.right, glm::vec3(right * (2.0 * half_width)));
    put(out.down, glm::vec3(up * (-2.0 * half_height)));
    return out;
}

/// Copies a record into the image at a word address.
template <class Record>
void write(std::vector<uint32_t>& words, int32_t addr, const Record& record) {
    static_assert(sizeof(Record) % 4 == 0);
    std::memcpy(words.data() + addr, &record, sizeof(Record));
}

/// The nodes of a tree in the order `order` lays them out: `children(p)` lists node p's
/// interior children, left to right; the root is 0 and every child's index is larger than its
/// parent's.
template <class Children>
std::vector<uint32_t> tree_order(size_t nodes, Children children, scene::BvhOrder order) {
    std::vector<uint32_t> out;
    out.reserve(nodes);
    if (order == scene::BvhOrder::breadth_first) {
        out.push_back(0);
        for (size_t i = 0; i < out.size(); ++i)
            for (uint32_t c : children(out[i]))
                out.push_back(c);
    } else if (order == scene::BvhOrder::depth_first) {
        std::vector<uint32_t> stack{0};
        while (!stack.empty()) {
            const uint32_t p = stack.back();
            stack.pop_back();
            out.push_back(p);
            const auto below = children(p);
            stack.insert(stack.end(), below.rbegin(), below.rend());
        }
    } else {
        // Height of each node's subtree, children before parents.
        std::vector<uint32_t> height(nodes, 0);
        for (size_t n = nodes; n-- > 0;) {
            height[n] = 1;
            for (uint32_t c : children(uint32_t(n)))
                height[n] = std::max(height[n], height[c] + 1);
        }
        // Lays out the top `levels` levels of p's subtree: the top half, then each subtree
        // hanging below it, left to right.
        const auto lay_out = [&](const auto& self, uint32_t p, uint32_t levels) -> void {
            if (levels == 1) {
                out.push_back(p);
                return;
            }
            const uint32_t top = levels / 2;
            self(self, p, top);
            std::vector<uint32_t> frontier{p};
            for (uint32_t level = 0; level < top; ++level) {
                std::vector<uint32_t> next;
                for (uint32_t q : frontier)
                    for (uint32_t c : children(q))
                        next.push_back(c);
                frontier.swap(next);
            }
            for (uint32_t q : frontier)
                self(self, q, levels - top);
        };
        lay_out(lay_out, 0, height[0]);
    }
    return out;
}

/// The builder's interior nodes (each the parent of one sibling pair) in the order their pairs
/// are laid out (scene::BvhOrder): the tree of pairs is the tree of interior nodes. Builder
/// nodes are depth-first: the left child of interior node p is p + 1, the right one is at
/// right_child.
std::vector<uint32_t> pair_order(const scene::Bvh& bvh, scene::BvhOrder order) {
    if (bvh.nodes[0].is_leaf()) return {};
    // Interior nodes are numbered densely for tree_order, keeping the builder's order.
    std::vector<uint32_t> dense(bvh.nodes.size(), 0), interior;
    for (uint32_t n = 0; n < bvh.nodes.size(); ++n)
        if (!bvh.nodes[n].is_leaf()) {
            dense[n] = uint32_t(interior.size());
            interior.push_back(n);
        }
    const auto children = [&](uint32_t d) {
        const uint32_t p = interior[d];
        std::vector<uint32_t> out;
        for (uint32_t c : {p + 1, bvh.nodes[p].right_child})
            if (!bvh.nodes[c].is_leaf()) out.push_back(dense[c]);
        return out;
    };
    std::vector<uint32_t> pairs = tree_order(interior.size(), children, order);
    for (uint32_t& p : pairs)
        p = interior[p];
    return pairs;
}

/// The exponent e of the smallest power of two with 255 * 2^e >= extent, at least -126 so that
/// the scale is a normal float; biased by 127, as the kernel rebuilds the scale from it.
uint32_t quantization_exponent(float lo, float hi) {
    const double extent = double(hi) - double(lo);  // exact
    int e = extent > 0 ? std::max(-126, std::ilogb(extent / 255)) : -126;
    while (std::ldexp(255.0, e) < extent)
        ++e;
    return uint32_t(e + 127);
}

/// The 8-bit offsets of [lo, hi] on the grid origin + q * scale (origin <= lo, hi <= origin +
/// 255 * scale), rounded outwards, so that the box the kernel decodes, fl(origin + q * scale)
/// (q * scale is exact), contains [lo, hi]. Where lo - origin is exact in double, the floor and
/// ceiling already ensure it, rounding being monotone and the bounds floats; the loops fix the
/// rest: bounds that far apart (-2^56 and -1e-20) round their difference, perhaps up.
std::array<uint32_t, 2> quantize(float lo, float hi, float origin, float scale) {
    const auto decode = [&](uint32_t q) { return origin + float(q) * scale; };
    auto q_lo = uint32_t(std::clamp(std::floor((double(lo) - origin) / scale), 0.0, 255.0));
    while (q_lo > 0 && decode(q_lo) > lo)
        --q_lo;
    auto q_hi = uint32_t(std::clamp(std::ceil((double(hi) - origin) / scale), 0.0, 255.0));
    while (q_hi < 255 && decode(q_hi) < hi)
        ++q_hi;
    return {q_lo, q_hi};
}

/// The emissive triangles of the image (in image order), each picked with probability
/// proportional to its power, area times mean radiance; zero-area triangles are left out.
std::vector<layout::Emitter> compile_emitters(const std::vector<layout::Triangle>& triangles,
                                              const std::vector<scene::Material>& materials) {
    std::vector<layout::Emitter> emitters;
    std::vector<double> power;
    for (size_t i = 0; i < triangles.size(); ++i) {
        const layout::Triangle& t = triangles[i];
        const glm::vec3 e = materials[size_t(t.material)].emission;
        const double radiance = (double(e.x) + double(e.y) + double(e.z)) / 3;
        const glm::dvec3 v0(t.v0[0], t.v0[1], t.v0[2]), v1(t.v1[0], t.v1[1], t.v1[2]),
            v2(t.v2[0], t.v2[1], t.v2[2]);
        const double area = 0.5 * glm::length(glm::cross(v1 - v0, v2 - v0));
        if (radiance == 0 || area == 0) continue;
        emitters.push_back({int32_t(i), float(area), 0.f, 0.f});
        power.push_back(area * radiance);
    }
    double total = 0;
    for (double p : power)
        total += p;
    double sum = 0;
    for (size_t i = 0; i < emitters.size(); ++i) {
        sum += power[i];
        emitters[i].probability = float(power[i] / total);
        emitters[i].cdf = i + 1 == emitters.size() ? 1.f : float(sum / total);
    }
    return emitters;
}

}  // namespace

std::vector<layout::BvhNode> compile_bvh(const scene::Bvh& bvh, scene::BvhOrder order,
                                         bool align_pairs) {
    const std::vector<uint32_t> pairs = pair_order(bvh, order);
    const uint32_t first_pair = align_pairs ? 2 : 1;
    // Output index of each builder node.
    std::vector<uint32_t> slot(bvh.nodes.size(), 0);
    for (size_t j = 0; j < pairs.size(); ++j) {
        slot[pairs[j] + 1] = first_pair + 2 * uint32_t(j);
        slot[bvh.nodes[pairs[j]].right_child] = first_pair + 2 * uint32_t(j) + 1;
    }
    std::vector<layout::BvhNode> out(pairs.empty() ? 1 : first_pair + 2 * pairs.size());
    for (size_t n = 0; n < bvh.nodes.size(); ++n) {
        const scene::BvhNode& b = bvh.nodes[n];
        layout::BvhNode& node = out[slot[n]];
        put(node.bounds_min, b.bounds.lo);
        put(node.bounds_max, b.bounds.hi);
        if (b.is_leaf()) {
            node.first = int32_t(b.first_triangle);
            node.count = int32_t(b.triangle_count);
        } else {
            node.first = int32_t(slot[n + 1]);
            node.count = 0;
        }
    }
    return out;
}

std::vector<uint32_t> compile_wide_bvh(const scene::WideBvh& bvh, scene::BvhOrder order,
                                       scene::BvhBoxes boxes, int32_t addr) {
    const auto width = int32_t(bvh.stats.width);
    const bool quantized = boxes == scene::BvhBoxes::quantized;
    const int32_t node_words = layout::wide_node_words(width, quantized);
    const auto children = [&](uint32_t n) {
        std::vector<uint32_t> out;
        const scene::WideNode& node = bvh.nodes[n];
        for (uint32_t c = 0; c < node.child_count; ++c)
            if (!node.children[c].is_leaf()) out.push_back(node.children[c].node);
        return out;
    };
    const std::vector<uint32_t> placed = tree_order(bvh.nodes.size(), children, order);
    std::vector<int32_t> node_addr(bvh.nodes.size(), 0);
    for (size_t j = 0; j < placed.size(); ++j)
        node_addr[placed[j]] = addr + int32_t(j) * node_words;
    std::vector<uint32_t> words(placed.size() * size_t(node_words), 0u);
    const auto reference = [&](const scene::WideChild& child) {
        if (!child.is_leaf()) return uint32_t(node_addr[child.node]);
        if (child.first_triangle > uint32_t(layout::kWideMaxLeafFirst))
            throw Error(fmt::format("wide BVH: a leaf starts at triangle {}; the node format "
                                    "addresses at most {} triangles",
                                    child.first_triangle, layout::kWideMaxLeafFirst));
        return layout::kWideLeafBit | child.first_triangle << 4 | child.triangle_count;
    };
    for (size_t n = 0; n < bvh.nodes.size(); ++n) {
        const scene::WideNode& node = bvh.nodes[n];
        uint32_t* out = words.data() + (node_addr[n] - addr);
        if (!quantized) {
            for (uint32_t c = 0; c < node.child_count; ++c) {
                const scene::WideChild& child = node.children[c];
                for (int a = 0; a < 3; ++a) {
                    std::memcpy(out + 6 * c + a, &child.bounds.lo[a], 4);
                    std::memcpy(out + 6 * c + 3 + a, &child.bounds.hi[a], 4);
                }
                out[6 * width + int32_t(c)] = reference(child);
            }
            continue;
        }
        glm::vec3 lo = node.children[0].bounds.lo, hi = node.children[0].bounds.hi;
        for (uint32_t c = 1; c < node.child_count; ++c) {
            lo = glm::min(lo, node.children[c].bounds.lo);
            hi = glm::max(hi, node.children[c].bounds.hi);
        }
        auto* bytes = reinterpret_cast<uint8_t*>(out) + layout::wide_quantized_boxes_byte(width);
        for (int a = 0; a < 3; ++a) {
            std::memcpy(out + a, &lo[a], 4);
            const uint32_t exponent = quantization_exponent(lo[a], hi[a]);
            out[3] |= exponent << (8 * a);
            float scale;
            const uint32_t scale_bits = exponent << 23;
            std::memcpy(&scale, &scale_bits, 4);
            for (uint32_t c = 0; c < node.child_count; ++c) {
                const scene::Aabb& box = node.children[c].bounds;
                const auto [q_lo, q_hi] = quantize(box.lo[a], box.hi[a], lo[a], scale);
                bytes[a * width + int32_t(c)] = uint8_t(q_lo);
                bytes[(3 + a) * width + int32_t(c)] = uint8_t(q_hi);
            }
        }
        for (uint32_t c = 0; c < node.child_count; ++c)
            out[layout::kWideQuantizedRefs + int32_t(c)] = reference(node.children[c]);
    }
    return words;
}

MemoryImage build_memory_image(const scene::Scene& scene, Accel accel, uint32_t threads,
                               std::span<const layout::Ray> rays,
                               std::optional<uint32_t> extras_seed) {
    if (scene.width == 0 || scene.height == 0)
        throw Error("scene has an empty image (width or height is 0)");
    if (scene.triangles.empty()) throw Error("scene has no triangles");
    const scene::Bvh* bvh = accel.bvh;
    const scene::WideBvh* wide = accel.wide_bvh;
    const scene::Grid* grid = accel.grid;
    const scene::KdTree* kdtree = accel.kdtree;
    const scene::Octree* octree = accel.octree;
    const std::vector<uint32_t>* triangle_order = bvh    ? &bvh->triangle_order
                                                  : wide ? &wide->triangle_order
                                                         : nullptr;

    layout::SceneHeader h{};
    h.magic = layout::kMagic;
    h.version = layout::kVersion;
    h.image_width = int32_t(scene.width);
    h.image_height = int32_t(scene.height);
    h.samples_per_pixel = int32_t(scene.samples_per_pixel);
    // Leave out what the scene does not need: no lights means no shadow rays and no falloff.
    if (!scene.lights.empty()) {
        if (scene.shadows) h.flags |= layout::kFeatureShadows;
        if (scene.light_falloff) h.flags |= layout::kFeatureLightFalloff;
    }
    put(h.ambient, scene.ambient);
    put(h.background, scene.background);

    const auto checked_count = [](size_t n, const char* what) {
        if (n > size_t(std::numeric_limits<int32_t>::max() / 16))
            throw Error(
                fmt::format("scene has too many {} ({}) for the 32-bit memory image", what, n));
        return int32_t(n);
    };
    std::vector<layout::BvhNode> nodes;
    if (bvh != nullptr) nodes = compile_bvh(*bvh, accel.bvh_order, accel.bvh_align_pairs);
    h.lights.count = checked_count(scene.lights.size(), "lights");
    h.materials.count = checked_count(scene.materials.size(), "materials");
    h.triangles.count = checked_count(scene.triangles.size(), "triangles");
    h.bvh_nodes.count = checked_count(nodes.size(), "BVH nodes");
    h.thread_stats.count = checked_count(threads, "threads");
    h.rays.count = checked_count(rays.size(), "rays");
    layout::AccelRecord accel_record{};
    if (grid != nullptr) {
        accel_record.kind = layout::kAccelGrid;
        accel_record.nodes.count = checked_count(grid->cell_start.size(), "grid cells");
        accel_record.refs.count = checked_count(grid->references.size(), "grid references");
        put(accel_record.bounds_min, grid->lo);
        put(accel_record.bounds_max, grid->hi);
        put(accel_record.scale, grid->scale);
        for (int a = 0; a < 3; ++a)
            accel_record.resolution[a] = int32_t(grid->stats.resolution[size_t(a)]);
    }
    const bool quantized = accel.bvh_boxes == scene::BvhBoxes::quantized;
    if (wide != nullptr) {
        accel_record.kind = layout::kAccelWideBvh;
        accel_record.width = int32_t(wide->stats.width);
        accel_record.quantized = quantized ? 1 : 0;
        accel_record.nodes.count = checked_count(
            wide->nodes.size() * size_t(layout::wide_node_words(accel_record.width, quantized)),
            "wide BVH node words");
        put(accel_record.bounds_min, wide->bounds.lo);
        put(accel_record.bounds_max, wide->bounds.hi);
    }
    if (kdtree != nullptr) {
        accel_record.kind = kdtree->general_planes ? layout::kAccelBsp : layout::kAccelKdTree;
        accel_record.nodes.count =
            checked_count(kdtree->nodes.size() * layout::kKdNodeWords, "kd-tree node words");
        accel_record.refs.count = checked_count(kdtree->references.size(), "kd-tree references");
        put(accel_record.bounds_min, kdtree->bounds.lo);
        put(accel_record.bounds_max, kdtree->bounds.hi);
    }
    if (octree != nullptr) {
        accel_record.kind = layout::kAccelOctree;
        accel_record.nodes.count =
            checked_count(octree->nodes.size() * layout::kOctreeNodeWords, "octree node words");
        accel_record.refs.count = checked_count(octree->references.size(), "octree references");
        if (octree->nodes.size() > size_t(layout::kOctreeMaxFirstChild))
            throw Error(fmt::format("the octree has {} nodes, more than the {} its nodes can "
                                    "address; lower --octree-max-depth",
                                    octree->nodes.size(), layout::kOctreeMaxFirstChild));
        put(accel_record.bounds_min, octree->bounds.lo);
        put(accel_record.bounds_max, octree->bounds.hi);
    }
    const bool has_record =
        grid != nullptr || wide != nullptr || kdtree != nullptr || octree != nullptr;
    const uint64_t pixels = uint64_t(scene.width) * scene.height;
    if (pixels > uint64_t(std::numeric_limits<int32_t>::max() / 16))
        throw Error(fmt::format("image {}x{} is too large for the 32-bit memory image", scene.width,
                                scene.height));
    const uint64_t estimate =
        uint64_t(h.triangles.count) * layout::kTriangleWords +
        uint64_t(h.bvh_nodes.count) * layout::kBvhNodeWords + pixels * layout::kPixelWords +
        uint64_t(accel_record.nodes.count) + uint64_t(accel_record.refs.count) +
        uint64_t(threads) * layout::kThreadStatsWords +
        uint64_t(rays.size()) * (layout::kRayWords + layout::kRayResultWords) +
        (extras_seed ? uint64_t(h.triangles.count) * layout::kEmitterWords +
                           uint64_t(h.materials.count) * layout::kEmissionWords
                     : 0) +
        4096;
    // Global memory spans kGlobalBase..kLocalTop - kStackGuard in the guest address space.
    constexpr uint64_t kMaxWords =
        (trax::map::kLocalTop - trax::map::kStackGuard - trax::map::kGlobalBase) / 4;
    if (estimate > kMaxWords)
        throw Error(fmt::format("scene needs about {} MiB of global memory; the address map has "
                                "room for {} MiB (reduce the image size or the mesh)",
                                estimate * 4 >> 20, kMaxWords * 4 >> 20));
    // Triangles in image order: with a BVH, leaves index contiguous runs of them (leaf order).
    std::vector<layout::Triangle> triangles;
    triangles.reserve(scene.triangles.size());
    for (size_t i = 0; i < scene.triangles.size(); ++i) {
        const scene::Triangle& t = scene.triangles[triangle_order ? (*triangle_order)[i] : i];
        if (t.material >= scene.materials.size())
            throw Error(fmt::format("triangle {} uses material {} but the scene has {}", i,
                                    t.material, scene.materials.size()));
        layout::Triangle tri{};
        put(tri.v0, t.v0);
        put(tri.v1, t.v1);
        put(tri.v2, t.v2);
        tri.material = int32_t(t.material);
        triangles.push_back(tri);
    }
    layout::SceneExtras extras{};
    std::vector<layout::Emitter> emitters;
    if (extras_seed) {
        extras.seed = *extras_seed;
        emitters = compile_emitters(triangles, scene.materials);
        extras.emitters.count = checked_count(emitters.size(), "emitters");
    }
    layout::place_sections(h, extras_seed ? &extras : nullptr,
                           has_record ? &accel_record : nullptr);

    MemoryImage image;
    image.words.assign(size_t(h.total_words), 0u);
    write(image.words, 0, h);
    if (extras_seed) {
        write(image.words, layout::kExtrasAddr, extras);
        for (size_t i = 0; i < scene.materials.size(); ++i) {
            layout::Emission emission{};
            put(emission.radiance, scene.materials[i].emission);
            write(image.words, extras.emission.addr + int32_t(i) * layout::kEmissionWords,
                  emission);
        }
        for (size_t i = 0; i < emitters.size(); ++i)
            write(image.words, extras.emitters.addr + int32_t(i) * layout::kEmitterWords,
                  emitters[i]);
    }
    write(image.words, h.camera.addr, compile_camera(scene.camera, scene.width, scene.height));
    for (size_t i = 0; i < scene.lights.size(); ++i) {
        layout::PointLight light{};
        put(light.position, scene.lights[i].position);
        put(light.color, scene.lights[i].color);
        write(image.words, h.lights.addr + int32_t(i) * layout::kPointLightWords, light);
    }
    for (size_t i = 0; i < scene.materials.size(); ++i) {
        layout::Material material{};
        put(material.diffuse, scene.materials[i].diffuse);
        write(image.words, h.materials.addr + int32_t(i) * layout::kMaterialWords, material);
    }
    for (size_t i = 0; i < triangles.size(); ++i)
        write(image.words, h.triangles.addr + int32_t(i) * layout::kTriangleWords, triangles[i]);
    for (size_t i = 0; i < nodes.size(); ++i)
        write(image.words, h.bvh_nodes.addr + int32_t(i) * layout::kBvhNodeWords, nodes[i]);
    if (grid != nullptr) {
        write(image.words, h.accel, accel_record);
        std::memcpy(image.words.data() + accel_record.nodes.addr, grid->cell_start.data(),
                    grid->cell_start.size() * 4);
        std::memcpy(image.words.data() + accel_record.refs.addr, grid->references.data(),
                    grid->references.size() * 4);
    }
    if (kdtree != nullptr) {
        write(image.words, h.accel, accel_record);
        uint32_t* out = image.words.data() + accel_record.nodes.addr;
        // The kd-tree's two bits of axis, or the BSP tree's four of orientation.
        const uint32_t bits = kdtree->general_planes ? layout::kBspShapeBits : 2;
        const uint32_t leaf = kdtree->general_planes ? layout::kBspLeaf : layout::kKdLeaf;
        for (const scene::KdNode& node : kdtree->nodes) {
            if (node.is_leaf()) {
                out[0] = node.first;
                out[1] = leaf | node.count << bits;
            } else {
                std::memcpy(&out[0], &node.split, 4);
                out[1] = node.axis | node.right_child << bits;
            }
            out += layout::kKdNodeWords;
        }
        std::memcpy(image.words.data() + accel_record.refs.addr, kdtree->references.data(),
                    kdtree->references.size() * 4);
    }
    if (octree != nullptr) {
        write(image.words, h.accel, accel_record);
        uint32_t* out = image.words.data() + accel_record.nodes.addr;
        for (const scene::OctreeNode& node : octree->nodes) {
            if (node.leaf) {
                out[layout::kOctreeFirst] = node.first;
                out[layout::kOctreeCount] = node.count;
                out[layout::kOctreeShape] = ~0u;
            } else {
                std::memcpy(&out[0], node.centre.data(), 12);
                out[layout::kOctreeShape] = node.first_child << 8 | node.occupied;
            }
            out += layout::kOctreeNodeWords;
        }
        std::memcpy(image.words.data() + accel_record.refs.addr, octree->references.data(),
                    octree->references.size() * 4);
    }
    if (wide != nullptr) {
        write(image.words, h.accel, accel_record);
        const std::vector<uint32_t> nodes =
            compile_wide_bvh(*wide, accel.bvh_order, accel.bvh_boxes, accel_record.nodes.addr);
        std::memcpy(image.words.data() + accel_record.nodes.addr, nodes.data(), nodes.size() * 4);
    }
    for (size_t i = 0; i < rays.size(); ++i)
        write(image.words, h.rays.addr + int32_t(i) * layout::kRayWords, rays[i]);

    const auto section = [](const char* name, const layout::SectionRef& ref, int32_t words) {
        return SectionSize{name, uint32_t(ref.count), uint64_t(ref.count) * uint64_t(words) * 4,
                           uint64_t(ref.addr) * 4};
    };
    image.header = h;
    // The extras' sections are listed only when present, so an image without them reports
    // (and registers statistics for) exactly the sections it always had.
    image.sections = {{"header", 1, sizeof(layout::SceneHeader)}};
    if (extras_seed)
        image.sections.push_back({"extras", 1, sizeof(extras), layout::kExtrasAddr * 4});
    image.sections.push_back(section("camera", h.camera, layout::kCameraWords));
    image.sections.push_back(section("lights", h.lights, layout::kPointLightWords));
    image.sections.push_back(section("materials", h.materials, layout::kMaterialWords));
    if (extras_seed)
        image.sections.push_back(section("emission", extras.emission, layout::kEmissionWords));
    image.sections.push_back(section("triangles", h.triangles, layout::kTriangleWords));
    if (extras_seed)
        image.sections.push_back(section("emitters", extras.emitters, layout::kEmitterWords));
    if (wide != nullptr) {
        image.sections.push_back({"bvh_root", 1, sizeof(accel_record), uint64_t(h.accel) * 4});
        image.sections.push_back({"bvh_nodes", uint32_t(wide->nodes.size()),
                                  uint64_t(accel_record.nodes.count) * 4,
                                  uint64_t(accel_record.nodes.addr) * 4});
    } else {
        image.sections.push_back(section("bvh_nodes", h.bvh_nodes, layout::kBvhNodeWords));
    }
    // The structure's sections only when it is there, named after it.
    if (grid != nullptr) {
        image.sections.push_back({"grid", 1, sizeof(accel_record), uint64_t(h.accel) * 4});
        image.sections.push_back(section("grid_cells", accel_record.nodes, 1));
        image.sections.push_back(section("grid_refs", accel_record.refs, 1));
    }
    if (kdtree != nullptr) {
        const bool bsp = kdtree->general_planes;
        image.sections.push_back(
            {bsp ? "bsp" : "kdtree", 1, sizeof(accel_record), uint64_t(h.accel) * 4});
        image.sections.push_back(
            {bsp ? "bsp_nodes" : "kdtree_nodes", uint32_t(kdtree->nodes.size()),
             uint64_t(accel_record.nodes.count) * 4, uint64_t(accel_record.nodes.addr) * 4});
        image.sections.push_back(section(bsp ? "bsp_refs" : "kdtree_refs", accel_record.refs, 1));
    }
    if (octree != nullptr) {
        image.sections.push_back({"octree", 1, sizeof(accel_record), uint64_t(h.accel) * 4});
        image.sections.push_back({"octree_nodes", uint32_t(octree->nodes.size()),
                                  uint64_t(accel_record.nodes.count) * 4,
                                  uint64_t(accel_record.nodes.addr) * 4});
        image.sections.push_back(section("octree_refs", accel_record.refs, 1));
    }
    image.sections.push_back(section("framebuffer", h.framebuffer, layout::kPixelWords));
    image.sections.push_back(section("thread_stats", h.thread_stats, layout::kThreadStatsWords));
    image.sections.push_back(section("rays", h.rays, layout::kRayWords));
    image.sections.push_back(section("ray_results", h.ray_results, layout::kRayResultWords));
    return image;
}

std::vector<float> read_framebuffer(const layout::SceneHeader& header, const uint32_t* words) {
    std::vector<float> rgb(size_t(header.framebuffer.count) * layout::kPixelWords);
    std::memcpy(rgb.data(), words + header.framebuffer.addr, rgb.size() * sizeof(float));
    return rgb;
}

TraversalTotals read_thread_stats(const layout::SceneHeader& header, const uint32_t* words) {
    TraversalTotals totals;
    const auto wide = [](const uint32_t* lo) { return uint64_t(lo[0]) | uint64_t(lo[1]) << 32; };
    for (int32_t i = 0; i < header.thread_stats.count; ++i) {
        const uint32_t* r = words + header.thread_stats.addr + i * layout::kThreadStatsWords;
        totals.primary_rays += r[layout::kStatsPrimaryRays];
        totals.shadow_rays += r[layout::kStatsShadowRays];
        totals.nodes_visited += wide(r + layout::kStatsNodesVisited);
        totals.triangles_tested += wide(r + layout::kStatsTrianglesTested);
        totals.max_stack_depth = std::max(totals.max_stack_depth, r[layout::kStatsMaxStackDepth]);
        totals.stack_overflows += r[layout::kStatsStackOverflows];
    }
    return totals;
}

std::vector<layout::RayResult> read_ray_results(const layout::SceneHeader& header,
                                                const uint32_t* words) {
    std::vector<layout::RayResult> results(size_t(header.ray_results.count));
    std::memcpy(results.data(), words + header.ray_results.addr,
                results.size() * sizeof(layout::RayResult));
    return results;
}

}  // namespace tpsim::image
