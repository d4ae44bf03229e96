// Ray packets: kPacketRays rays of neighbouring pixels share one walk of the BVH (Wald, Slusallek,
// Benthin and Wagner, "Interactive Rendering with Coherent Ray Tracing", EG 2001). Each node's
// box and each leaf's triangles are loaded once for the packet and tested against every ray
// still in it; an active mask drops the rays that miss a box, so a ray is never tested against a
// triangle its own traversal could not reach, and each ray's closest hit is the one it finds
// alone (only ties between triangles at the same distance may resolve the other way). What
// packets save is loads and fetches per ray; what they cost is boxes and triangles tested for
// rays that do not need them once the rays diverge. tracer_packet measures it on the tracer's
// coherent camera and shadow rays, ao_packet on incoherent diffuse rays (docs/accel.md).
#pragma once
#include "rt.hpp"

namespace trax::rt {

/// Rays per packet: a 2 x 2 block of pixels.
constexpr int kPacketRays = 4;
constexpr int kPacketSide = 2;

/// The rays of one packet; bit i of `rays` says ray i exists and is valid (valid_ray()).
struct RayPacket {
    Vec3 origin[kPacketRays], dir[kPacketRays], inverse[kPacketRays];
    ShearedRay sheared[kPacketRays];
    float t_max[kPacketRays];
    uint32_t rays = 0;

    void set(int i, Vec3 o, Vec3 d, float t) {
        t_max[i] = t;
        if (!valid_ray(o, d, t)) return;
        rays |= 1u << i;
        origin[i] = o;
        dir[i] = d;
        inverse[i] = {1.0f / d.x, 1.0f / d.y, 1.0f / d.z};
        sheared[i] = shear(o, d);
    }
};

/// A node's box loaded once, for slab_entry_of() against every ray of the packet.
struct LoadedBox {
    float lo[3], hi[3];

    [[gnu::always_inline]] static LoadedBox of(int node) {
        return {{loadf(node, kNodeMin), loadf(node, kNodeMin + 1), loadf(node, kNodeMin + 2)},
                {loadf(node, kNodeMax), loadf(node, kNodeMax + 1), loadf(node, kNodeMax + 2)}};
    }
    [[gnu::always_inline]] float min(int axis) const { return lo[axis]; }
    [[gnu::always_inline]] float max(int axis) const { return hi[axis]; }
};

/// A triangle's nine coordinates loaded once; permuted() gives them on one ray's axes.
struct LoadedTriangle {
    float v[3][3];  ///< [vertex][axis]

    [[gnu::always_inline]] static LoadedTriangle of(int tri) {
        LoadedTriangle t;
        for (int axis = 0; axis < 3; ++axis) {
            t.v[0][axis] = loadf(tri, kTriangleV0 + axis);
            t.v[1][axis] = loadf(tri, kTriangleV1 + axis);
            t.v[2][axis] = loadf(tri, kTriangleV2 + axis);
        }
        return t;
    }
    [[gnu::always_inline]] PermutedTriangle permuted(const ShearedRay& r) const {
        return {v[0][r.kx], v[0][r.ky], v[0][r.kz], v[1][r.kx], v[1][r.ky],
                v[1][r.kz], v[2][r.kx], v[2][r.ky], v[2][r.kz]};
    }
};

/// Packet traversal of the image's BVH (scene_layout.hpp BvhNode): both children's boxes tested
/// against every active ray, the packet descends into the child more of its rays enter first
/// (the other pushed with the mask of its rays), leaves' triangles tested against the rays whose
/// own box tests reached them. Any-hit rays leave the packet at their first hit. Each ray's
/// RayStats counts the boxes and triangles tested for it; the stack depth is the packet's.
struct PacketBvhTraversal {
    int nodes, triangles;

    static PacketBvhTraversal from_scene() { return {trax_bvh(), trax_triangles()}; }

    template <bool kAnyHit>
    void trace(const RayPacket& p, Hit (&hits)[kPacketRays], RayStats (&stats)[kPacketRays]) const {
        for (int i = 0; i < kPacketRays; ++i)
            hits[i].t = p.t_max[i];
        uint32_t live = p.rays;  // rays still looking (any-hit rays leave at their first hit)
        if (live == 0) return;
        int stack_node[kTraversalStackEntries];
        uint32_t stack_mask[kTraversalStackEntries];
        int depth = 0;

        int node = nodes;
        uint32_t mask = 0;  // rays whose box tests reached `node`
        const LoadedBox root = LoadedBox::of(node);
        for (int i = 0; i < kPacketRays; ++i) {
            if (!(live >> i & 1u)) continue;
            ++stats[i].nodes_visited;
            if (slab_entry_of(root, p.origin[i], p.inverse[i], hits[i].t) <= hits[i].t)
                mask |= 1u << i;
        }
        while (mask != 0) {
            const int count = loadi(node, kNodeCount);
            const int first = loadi(node, kNodeFirst);
            if (count == 0) {
                const int left = nodes + first * kBvhNodeWords, right = left + kBvhNodeWords;
                const LoadedBox left_box = LoadedBox::of(left), right_box = LoadedBox::of(right);
                uint32_t left_mask = 0, right_mask = 0;
                int left_first_votes = 0;  // rays entering both: nearer left minus nearer right
                for (int i = 0; i < kPacketRays; ++i) {
                    if (!(mask >> i & 1u)) continue;
                    stats[i].nodes_visited += 2;
                    const float limit = hits[i].t;
                    const float t_left = slab_entry_of(left_box, p.origin[i], p.inverse[i], limit);
                    const float t_right =
                        slab_entry_of(right_box, p.origin[i], p.inverse[i], limit);
                    const bool hit_left = t_left <= limit, hit_right = t_right <= limit;
                    if (hit_left) left_mask |= 1u << i;
                    if (hit_right) right_mask |= 1u << i;
                    if (hit_left && hit_right) left_first_votes += t_left <= t_right ? 1 : -1;
                }
                if (left_mask != 0 && right_mask != 0) {
                    const bool left_first = left_first_votes >= 0;
                    node = left_first ? left : right;
                    mask = left_first ? left_mask : right_mask;
                    const uint32_t far_mask = left_first ? right_mask : left_mask;
                    if (depth == kTraversalStackEntries) {
                        for (int i = 0; i < kPacketRays; ++i)
                            if (far_mask >> i & 1u) ++stats[i].stack_overflows;
                    } else {
                        stack_node[depth] = left_first ? right : left;
                        stack_mask[depth] = far_mask;
                        ++depth;
                        for (int i = 0; i < kPacketRays; ++i)
                            if (uint32_t(depth) > stats[i].max_stack_depth)
                                stats[i].max_stack_depth = depth;
                    }
                    continue;
                }
                if (left_mask != 0 || right_mask != 0) {
                    node = left_mask != 0 ? left : right;
                    mask = left_mask | right_mask;
                    continue;
                }
            } else {
                for (int t = first; t < first + count && mask != 0; ++t) {
                    const LoadedTriangle tri = LoadedTriangle::of(triangles + t * kTriangleWords);
                    for (int i = 0; i < kPacketRays; ++i) {
                        if (!(mask >> i & 1u)) continue;
                        ++stats[i].triangles_tested;
                        TriangleHit found;
                        if (intersect_vertices(p.sheared[i], tri.permuted(p.sheared[i]), hits[i].t,
                                               found)) {
                            record<kAnyHit>(hits[i], t, found);
                            if (kAnyHit) {
                                mask &= ~(1u << i);
                                live &= ~(1u << i);
                            }
                        }
                    }
                }
            }
            // Pop the next subtree that rays still looking entered.
            mask = 0;
            while (mask == 0 && depth > 0) {
                --depth;
                node = stack_node[depth];
                mask = stack_mask[depth] & live;
            }
        }
    }
};

/// The tracer's shading (shade_with() with the default policy) for a packet of camera rays: the
/// same hits, the same shadow rays, traced as packets, one per light: the colours of the rays of
/// `pixels` (>= 0) go to `colors`.
inline void shade_lambert(const Shading& s, const PacketBvhTraversal& bvh,
                          const RayPacket& camera_rays, const int (&pixels)[kPacketRays],
                          Vec3 (&colors)[kPacketRays], ThreadTotals& totals) {
    Hit hits[kPacketRays];
    RayStats stats[kPacketRays];
    bvh.trace<false>(camera_rays, hits, stats);
    LitPoint lit[kPacketRays];
    Vec3 light_sum[kPacketRays];
    uint32_t lit_rays = 0;
    for (int i = 0; i < kPacketRays; ++i) {
        if (pixels[i] < 0) continue;
        totals.add(stats[i], false);
        if (hits[i].triangle < 0) {
            colors[i] = s.background;
            continue;
        }
        lit[i] = lit_point(s, hits[i], camera_rays.origin[i], camera_rays.dir[i]);
        light_sum[i] = s.ambient;
        lit_rays |= 1u << i;
    }
    for (int l = 0; l < s.num_lights; ++l) {
        const int light = s.lights + l * kPointLightWords;
        const Vec3 light_position = load_vec3(light, kLightPosition);
        RayPacket shadow_rays;
        float weight[kPacketRays];
        uint32_t lighting = 0;  // rays the light faces (and, after the shadow rays, reaches)
        for (int i = 0; i < kPacketRays; ++i) {
            if (!(lit_rays >> i & 1u) || !light_weight(s, lit[i], light_position, weight[i]))
                continue;
            lighting |= 1u << i;
            if (!(s.flags & kFeatureShadows)) continue;
            const Vec3 start = offset_origin(lit[i].surface, light_position - lit[i].surface.p);
            shadow_rays.set(i, start, light_position - start, 1.0f);
        }
        if ((s.flags & kFeatureShadows) && lighting != 0) {
            Hit blockers[kPacketRays];
            RayStats shadow_stats[kPacketRays];
            bvh.trace<true>(shadow_rays, blockers, shadow_stats);
            for (int i = 0; i < kPacketRays; ++i) {
                if (!(lighting >> i & 1u)) continue;
                totals.add(shadow_stats[i], true);
                if (blockers[i].triangle >= 0) lighting &= ~(1u << i);
            }
        }
        if (lighting == 0) continue;
        const Vec3 light_color = load_vec3(light, kLightColor);
        for (int i = 0; i < kPacketRays; ++i)
            if (lighting >> i & 1u) light_sum[i] = light_sum[i] + light_color * weight[i];
    }
    for (int i = 0; i < kPacketRays; ++i)
        if (lit_rays >> i & 1u) colors[i] = lit[i].albedo * light_sum[i];
}

/// The pixels of packet `block` of a width x height image (2 x 2 blocks, row by row), -1 for
/// those outside the image.
inline void packet_pixels(int block, int width, int height, int (&pixels)[kPacketRays]) {
    const int across = (width + kPacketSide - 1) / kPacketSide;
    const int x0 = (block % across) * kPacketSide, y0 = (block / across) * kPacketSide;
    for (int i = 0; i < kPacketRays; ++i) {
        const int x = x0 + i % kPacketSide, y = y0 + i / kPacketSide;
        pixels[i] = x < width && y < height ? y * width + x : -1;
    }
}

/// The packet loop of the packet kernels: 2 x 2 pixel blocks handed out with atomicinc(0); each
/// block gets samples_per_pixel packets of camera rays (the directions of CameraRays::direction,
/// so the rays of render_pixels()), shaded by shade_packet(camera_rays, pixels, sample, colors,
/// totals), averaged into the framebuffer; the thread's statistics record is written at the end.
template <class ShadePacket>
[[gnu::always_inline]] inline void render_packets(const ShadePacket& shade_packet) {
    const int width = trax_image_width(), height = trax_image_height();
    const int samples = trax_samples_per_pixel();
    const CameraRays camera = CameraRays::from_scene();
    const int framebuffer = trax_framebuffer();
    ThreadTotals totals;

    const int blocks =
        ((width + kPacketSide - 1) / kPacketSide) * ((height + kPacketSide - 1) / kPacketSide);
    for (int block = atomicinc(0); block < blocks; block = atomicinc(0)) {
        int pixels[kPacketRays];
        packet_pixels(block, width, height, pixels);
        Vec3 color[kPacketRays] = {};
        for (int sample = 0; sample < samples; ++sample) {
            RayPacket camera_rays;
            for (int i = 0; i < kPacketRays; ++i)
                if (pixels[i] >= 0)
                    camera_rays.set(i, camera.eye, camera.direction(pixels[i], sample, samples),
                                    3.0e38f);
            Vec3 shaded[kPacketRays];
            shade_packet(camera_rays, pixels, sample, shaded, totals);
            for (int i = 0; i < kPacketRays; ++i)
                color[i] = color[i] + shaded[i];
        }
        for (int i = 0; i < kPacketRays; ++i) {
            if (pixels[i] < 0) continue;
            const Vec3 c = color[i] * (1.0f / static_cast<float>(samples));
            const int out = framebuffer + pixels[i] * kPixelWords;
            storef(c.x, out, 0);
            storef(c.y, out, 1);
            storef(c.z, out, 2);
        }
    }
    totals.store();
}

}  // namespace trax::rt
