#include "sim/scene/wide_bvh.hpp"

#include <algorithm>
#include <chrono>
#include <stdexcept>

#include <fmt/format.h>

namespace tpsim::scene {

namespace {

class Collapser {
public:
    Collapser(const Bvh& binary, uint32_t width) : binary_(binary), width_(width) {}

    /// Appends the wide node for binary interior node `b` and, after it, its subtrees'.
    uint32_t collapse(uint32_t b, std::vector<WideNode>& nodes) const {
        const uint32_t index = uint32_t(nodes.size());
        nodes.emplace_back();
        std::vector<uint32_t> open = children(b);
        while (open.size() < width_) {
            // The interior child with the largest box: opening it saves the most box tests.
            size_t best = open.size();
            for (size_t i = 0; i < open.size(); ++i)
                if (!binary_.nodes[open[i]].is_leaf() &&
                    (best == open.size() || area(open[i]) > area(open[best])))
                    best = i;
            if (best == open.size()) break;
            const std::vector<uint32_t> grandchildren = children(open[best]);
            open[best] = grandchildren[0];
            open.insert(open.begin() + std::ptrdiff_t(best) + 1, grandchildren[1]);
        }
        WideNode node;
        node.child_count = uint32_t(open.size());
        for (size_t i = 0; i < open.size(); ++i) {
            const BvhNode& from = binary_.nodes[open[i]];
            WideChild& child = node.children[i];
            child.bounds = from.bounds;
            if (from.is_leaf()) {
                child.first_triangle = from.first_triangle;
                child.triangle_count = from.triangle_count;
            } else {
                child.node = collapse(open[i], nodes);
            }
        }
        nodes[index] = node;
        return index;
    }

private:
    std::vector<uint32_t> children(uint32_t b) const {
        return {b + 1, binary_.nodes[b].right_child};
    }
    float area(uint32_t b) const { return binary_.nodes[b].bounds.surface_area(); }

    const Bvh& binary_;
    uint32_t width_;
};

void fill_stats(WideBvh& wide) {
    WideBvhStats& s = wide.stats;
    s.nodes = uint32_t(wide.nodes.size());
    uint64_t children = 0;
    // (node, depth, stack entries pushed on the way to it)
    std::vector<std::array<uint32_t, 3>> pending{{0, 1, 0}};
    while (!pending.empty()) {
        const auto [index, depth, pushed] = pending.back();
        pending.pop_back();
        const WideNode& node = wide.nodes[index];
        children += node.child_count;
        const uint32_t below = pushed + node.child_count - 1;
        for (uint32_t c = 0; c < node.child_count; ++c) {
            const WideChild& child = node.children[c];
            if (child.is_leaf()) {
                ++s.leaves;
                s.max_depth = std::max(s.max_depth, depth);
                s.worst_stack = std::max(s.worst_stack, below);
            } else {
                pending.push_back({child.node, depth + 1, below});
            }
        }
    }
    s.mean_children = double(children) / double(s.nodes);
}

}  // namespace

WideBvh collapse_bvh(const Bvh& binary, uint32_t width) {
    if (width != 4 && width != 8)
        throw std::invalid_argument(fmt::format("wide BVH: width must be 4 or 8, got {}", width));
    const auto start = std::chrono::steady_clock::now();
    WideBvh wide;
    wide.bounds = binary.nodes.at(0).bounds;
    wide.triangle_order = binary.triangle_order;
    wide.stats.width = width;
    const BvhNode& root = binary.nodes[0];
    if (root.is_leaf()) {
        WideNode node;
        node.child_count = 1;
        node.children[0] = {root.bounds, 0, root.first_triangle, root.triangle_count};
        wide.nodes.push_back(node);
    } else {
        Collapser(binary, width).collapse(0, wide.nodes);
    }
    fill_stats(wide);
    wide.stats.collapse_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return wide;
}

}  // namespace tpsim::scene
