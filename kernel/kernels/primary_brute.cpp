// Primary-ray casting by brute force: every ray is tested against every triangle.
// Pixels are handed out with atomicinc(0); each gets samples_per_pixel camera rays (pixel centre
// for one sample, deterministic hashed jitter for more), Lambert shading from every point light
// over an ambient term, optional hard shadows and 1/d^2 falloff (scene feature flags), and the
// background colour for misses. Writes linear RGB floats to the framebuffer.
#include "trax.hpp"

namespace {

using namespace trax::layout;

struct Vec3 {
    float x, y, z;
};
Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
Vec3 operator*(Vec3 a, float s) { return {a.x * s, a.y * s, a.z * s}; }
Vec3 operator*(Vec3 a, Vec3 b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
float dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
Vec3 cross(Vec3 a, Vec3 b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
Vec3 load_vec3(int addr, int offset) {
    return {loadf(addr, offset), loadf(addr, offset + 1), loadf(addr, offset + 2)};
}
float component(Vec3 v, int axis) { return axis == 0 ? v.x : axis == 1 ? v.y : v.z; }

/// A ray prepared for the watertight test of Woop, Benthin and Wald, "Watertight Ray/Triangle
/// Intersection", JCGT 2(1), 2013: axes permuted so the direction's largest component is z, and
/// a shear that maps the direction to +z. The origin is kept per permuted axis so a triangle
/// vertex coordinate is one loadf(triangle, vertex + axis) away.
struct ShearedRay {
    int kx, ky, kz;
    float ox, oy, oz;
    float sx, sy, sz;
};

ShearedRay shear(Vec3 origin, Vec3 dir) {
    ShearedRay r;
    const float ax = trax_abs(dir.x), ay = trax_abs(dir.y), az = trax_abs(dir.z);
    r.kz = ax > ay ? (ax > az ? 0 : 2) : (ay > az ? 1 : 2);
    r.kx = r.kz == 2 ? 0 : r.kz + 1;
    r.ky = r.kx == 2 ? 0 : r.kx + 1;
    const float dz = component(dir, r.kz);
    if (dz < 0.0f) {  // keep the winding: swap x and y when the ray looks down -z
        const int k = r.kx;
        r.kx = r.ky;
        r.ky = k;
    }
    r.sx = component(dir, r.kx) / dz;
    r.sy = component(dir, r.ky) / dz;
    r.sz = 1.0f / dz;
    r.ox = component(origin, r.kx);
    r.oy = component(origin, r.ky);
    r.oz = component(origin, r.kz);
    return r;
}

/// Hit distance along the (unnormalised) direction, if the ray meets the triangle at address
/// `tri` with t_min < t < t_max. Two-sided. The paper's double-precision fallback for edge
/// coefficients that are exactly zero is left out (TRaX has no doubles): such rays count as
/// hits, so a ray through a shared edge is never lost, at worst reported by both triangles.
/// Always inlined into the two loops so the ray stays in registers across triangles.
[[gnu::always_inline]] inline bool intersect(const ShearedRay& r, int tri, float t_min, float t_max,
                                            float& t) {
    // Vertices relative to the origin, sheared and scaled. One address per permuted axis, so
    // the three vertices' coordinates on it are constant offsets from it (one flw each).
    const int x = tri + r.kx, y = tri + r.ky, z = tri + r.kz;
    const float a_z = loadf(z, kTriangleV0) - r.oz;
    const float b_z = loadf(z, kTriangleV1) - r.oz;
    const float c_z = loadf(z, kTriangleV2) - r.oz;
    const float a_x = loadf(x, kTriangleV0) - r.ox - r.sx * a_z;
    const float a_y = loadf(y, kTriangleV0) - r.oy - r.sy * a_z;
    const float b_x = loadf(x, kTriangleV1) - r.ox - r.sx * b_z;
    const float b_y = loadf(y, kTriangleV1) - r.oy - r.sy * b_z;
    const float c_x = loadf(x, kTriangleV2) - r.ox - r.sx * c_z;
    const float c_y = loadf(y, kTriangleV2) - r.oy - r.sy * c_z;

    // Scaled barycentrics: edge functions in the sheared 2D space.
    const float u = c_x * b_y - c_y * b_x;
    const float v = a_x * c_y - a_y * c_x;
    const float w = b_x * a_y - b_y * a_x;
    if ((u < 0.0f || v < 0.0f || w < 0.0f) && (u > 0.0f || v > 0.0f || w > 0.0f)) return false;
    const float det = u + v + w;
    if (det == 0.0f) return false;

    // Scaled distance; compare before dividing so misses cost no division.
    const float scaled_t = r.sz * (u * a_z + v * b_z + w * c_z);
    if (det > 0.0f ? (scaled_t <= t_min * det || scaled_t >= t_max * det)
                   : (scaled_t >= t_min * det || scaled_t <= t_max * det))
        return false;
    t = scaled_t / det;
    return true;
}

/// Offsets a hit point along the normal so a ray leaving it does not hit its own surface:
/// Wächter and Binder, "A Fast and Robust Method for Avoiding Self-Intersection", Ray Tracing
/// Gems ch. 6, 2019 (integer ulp steps away from the origin, a float step near it).
float offset_coordinate(float p, float n) {
    constexpr float kOrigin = 1.0f / 32.0f, kFloatScale = 1.0f / 65536.0f, kIntScale = 256.0f;
    const int ulps = static_cast<int>(kIntScale * n);
    const int bits = __builtin_bit_cast(int, p) + (p < 0.0f ? -ulps : ulps);
    return trax_abs(p) < kOrigin ? p + kFloatScale * n : __builtin_bit_cast(float, bits);
}
Vec3 offset_origin(Vec3 p, Vec3 n) {
    return {offset_coordinate(p.x, n.x), offset_coordinate(p.y, n.y), offset_coordinate(p.z, n.z)};
}

struct Scene {
    int triangles, num_triangles;
    int lights, num_lights;
    int materials;
    uint32_t flags;
    Vec3 ambient, background;
};

/// Closest hit: index of the triangle and its distance, or -1.
int closest_hit(const Scene& s, Vec3 origin, Vec3 dir, float& t_hit) {
    const ShearedRay r = shear(origin, dir);
    int hit = -1;
    t_hit = 3.0e38f;
    for (int i = 0; i < s.num_triangles; ++i) {
        float t;
        if (intersect(r, s.triangles + i * kTriangleWords, 0.0f, t_hit, t)) {
            t_hit = t;
            hit = i;
        }
    }
    return hit;
}

/// Is anything between origin and origin + dir (exclusive)?
bool occluded(const Scene& s, Vec3 origin, Vec3 dir) {
    const ShearedRay r = shear(origin, dir);
    for (int i = 0; i < s.num_triangles; ++i) {
        float t;
        if (intersect(r, s.triangles + i * kTriangleWords, 0.0f, 1.0f, t)) return true;
    }
    return false;
}

Vec3 shade(const Scene& s, Vec3 origin, Vec3 dir) {
    float t;
    const int hit = closest_hit(s, origin, dir, t);
    if (hit < 0) return s.background;

    const int tri = s.triangles + hit * kTriangleWords;
    const Vec3 v0 = load_vec3(tri, kTriangleV0);
    Vec3 n = cross(load_vec3(tri, kTriangleV1) - v0, load_vec3(tri, kTriangleV2) - v0);
    n = n * (1.0f / trax_sqrt(dot(n, n)));
    if (dot(n, dir) > 0.0f) n = n * -1.0f;  // two-sided: face the incoming ray
    const Vec3 p = origin + dir * t;
    const Vec3 albedo = load_vec3(s.materials + loadi(tri, kTriangleMaterial) * kMaterialWords,
                                  kMaterialDiffuse);

    Vec3 light_sum = s.ambient;
    for (int i = 0; i < s.num_lights; ++i) {
        const int light = s.lights + i * kPointLightWords;
        const Vec3 to_light = load_vec3(light, kLightPosition) - p;
        const float n_dot_l = dot(n, to_light);
        if (n_dot_l <= 0.0f) continue;
        const float distance2 = dot(to_light, to_light);
        float weight = n_dot_l / trax_sqrt(distance2);  // cosine
        if (s.flags & kFeatureLightFalloff) weight = weight / distance2;
        if (s.flags & kFeatureShadows) {
            const Vec3 start = offset_origin(p, n);
            if (occluded(s, start, load_vec3(light, kLightPosition) - start)) continue;
        }
        light_sum = light_sum + load_vec3(light, kLightColor) * weight;
    }
    return albedo * light_sum;
}

/// Integer hash (Wellons' "lowbias32"): decorrelated jitter that depends only on its input.
uint32_t hash(uint32_t x) {
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}
/// Uniform in [0, 1), 24 bits: exactly representable, the same on both sides.
float unit_float(uint32_t bits) { return static_cast<float>(bits >> 8) * (1.0f / 16777216.0f); }

}  // namespace

void trax_main() {
    Scene s;
    s.triangles = trax_triangles();
    s.num_triangles = trax_num_triangles();
    s.lights = trax_lights();
    s.num_lights = trax_num_lights();
    s.materials = trax_materials();
    s.flags = static_cast<uint32_t>(trax_scene_flags());
    s.ambient = load_vec3(trax_ambient(), 0);
    s.background = load_vec3(trax_background(), 0);

    const int width = trax_image_width(), height = trax_image_height();
    const int samples = trax_samples_per_pixel();
    const int camera = trax_camera();
    const Vec3 eye = load_vec3(camera, kCameraEye);
    const Vec3 corner = load_vec3(camera, kCameraCorner);
    const Vec3 right = load_vec3(camera, kCameraRight);
    const Vec3 down = load_vec3(camera, kCameraDown);
    const int framebuffer = trax_framebuffer();
    const float fwidth = static_cast<float>(width), fheight = static_cast<float>(height);

    for (int pixel = atomicinc(0); pixel < width * height; pixel = atomicinc(0)) {
        const float x = static_cast<float>(pixel % width), y = static_cast<float>(pixel / width);
        Vec3 color{0.0f, 0.0f, 0.0f};
        for (int sample = 0; sample < samples; ++sample) {
            float jx = 0.5f, jy = 0.5f;
            if (samples > 1) {
                const uint32_t key = 2u * static_cast<uint32_t>(pixel * samples + sample);
                jx = unit_float(hash(key));
                jy = unit_float(hash(key + 1u));
            }
            const Vec3 dir = corner + right * ((x + jx) / fwidth) + down * ((y + jy) / fheight);
            color = color + shade(s, eye, dir);
        }
        color = color * (1.0f / static_cast<float>(samples));
        const int out = framebuffer + pixel * kPixelWords;
        storef(color.x, out, 0);
        storef(color.y, out, 1);
        storef(color.z, out, 2);
    }
}
