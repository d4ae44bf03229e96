// A second, independent solution of assignment 3, written differently from
// course/solutions/3-shadows.cpp on purpose, so the checker's thresholds are seen to accept a
// correct kernel that is not the reference: the ray meets the triangle's plane first and is
// then tested against the three edges (inside-outside test), normals come from the plane, the
// shadow ray starts at the hit point itself and ignores hits closer than an epsilon, and pixels
// are dealt out by thread id in column order rather than taken with atomicinc.
#include "trax.hpp"

using namespace trax::layout;

namespace {

struct V {
    float x, y, z;
};
V sub(V a, V b) {
    return {a.x - b.x, a.y - b.y, a.z - b.z};
}
V add_scaled(V a, V b, float s) {
    return {a.x + b.x * s, a.y + b.y * s, a.z + b.z * s};
}
float dot(V a, V b) {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
V cross(V a, V b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
V at(int addr, int offset) {
    return {loadf(addr, offset), loadf(addr, offset + 1), loadf(addr, offset + 2)};
}

/// Plane first, then the edges: t of the hit, or a negative number for a miss.
float hit_triangle(V o, V d, int tri, V& normal) {
    const V a = at(tri, kTriangleV0), b = at(tri, kTriangleV1), c = at(tri, kTriangleV2);
    normal = cross(sub(b, a), sub(c, a));
    const float facing = dot(normal, d);
    if (facing == 0.0f) return -1.0f;
    const float t = dot(normal, sub(a, o)) / facing;
    if (!(t > 0.0f)) return -1.0f;
    const V p = add_scaled(o, d, t);
    if (dot(normal, cross(sub(b, a), sub(p, a))) < 0.0f) return -1.0f;
    if (dot(normal, cross(sub(c, b), sub(p, b))) < 0.0f) return -1.0f;
    if (dot(normal, cross(sub(a, c), sub(p, c))) < 0.0f) return -1.0f;
    return t;
}

}  // namespace

void trax_main() {
    const int width = trax_image_width(), height = trax_image_height();
    const int tris = trax_triangles(), count = trax_num_triangles();
    const int cam = trax_camera();
    const V eye = at(cam, kCameraEye), corner = at(cam, kCameraCorner);
    const V right = at(cam, kCameraRight), down = at(cam, kCameraDown);
    const int flags = trax_scene_flags();
    const int pixels = width * height;

    for (int k = trax_thread_id(); k < pixels; k += trax_num_threads()) {
        const int x = k / height, y = k % height;  // column by column
        const V d = add_scaled(add_scaled(corner, right, (float(x) + 0.5f) / float(width)), down,
                               (float(y) + 0.5f) / float(height));
        float best = 3.0e38f;
        int hit = -1;
        V n{0.0f, 0.0f, 0.0f};
        for (int i = 0; i < count; ++i) {
            V normal;
            const float t = hit_triangle(eye, d, tris + i * kTriangleWords, normal);
            if (t > 0.0f && t < best) {
                best = t;
                hit = tris + i * kTriangleWords;
                n = normal;
            }
        }
        V rgb = at(trax_background(), 0);
        if (hit >= 0) {
            const V p = add_scaled(eye, d, best);
            n = add_scaled(V{0.0f, 0.0f, 0.0f}, n, 1.0f / trax_sqrt(dot(n, n)));
            if (dot(n, d) > 0.0f) n = add_scaled(V{0.0f, 0.0f, 0.0f}, n, -1.0f);
            V sum = at(trax_ambient(), 0);
            for (int l = 0; l < trax_num_lights(); ++l) {
                const int light = trax_lights() + l * kPointLightWords;
                const V to = sub(at(light, kLightPosition), p);
                const float len2 = dot(to, to);
                float w = dot(n, to) / trax_sqrt(len2);
                if (w <= 0.0f) continue;
                bool shadowed = false;
                for (int i = 0; (flags & kFeatureShadows) && !shadowed && i < count; ++i) {
                    V ignored;
                    const float t = hit_triangle(p, to, tris + i * kTriangleWords, ignored);
                    shadowed = t > 1e-3f && t < 1.0f;
                }
                if (shadowed) continue;
                if (flags & kFeatureLightFalloff) w = w / len2;
                sum = add_scaled(sum, at(light, kLightColor), w);
            }
            const V albedo = at(trax_materials() + loadi(hit, kTriangleMaterial) * kMaterialWords,
                                kMaterialDiffuse);
            rgb = {albedo.x * sum.x, albedo.y * sum.y, albedo.z * sum.z};
        }
        const int out = trax_framebuffer() + (y * width + x) * kPixelWords;
        storef(rgb.x, out, 0);
        storef(rgb.y, out, 1);
        storef(rgb.z, out, 2);
    }
}
