// Assignment 3, reference solution: triangles from memory, brute force. Every camera ray is
// tested against every triangle (Moeller-Trumbore), the closest hit is shaded with Lambert's
// law from every point light (1/d^2 falloff when the scene asks for it), and a shadow ray to
// each light, from the hit point nudged off the surface, leaves the light out when any
// triangle lies in between.
#include "trax.hpp"

using namespace trax::layout;

struct Vec3 {
    float x, y, z;
};
Vec3 operator+(Vec3 a, Vec3 b) {
    return {a.x + b.x, a.y + b.y, a.z + b.z};
}
Vec3 operator-(Vec3 a, Vec3 b) {
    return {a.x - b.x, a.y - b.y, a.z - b.z};
}
Vec3 operator*(Vec3 a, float s) {
    return {a.x * s, a.y * s, a.z * s};
}
Vec3 operator*(Vec3 a, Vec3 b) {
    return {a.x * b.x, a.y * b.y, a.z * b.z};
}
float dot(Vec3 a, Vec3 b) {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
Vec3 cross(Vec3 a, Vec3 b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
Vec3 load_vec3(int addr) {
    return {loadf(addr, 0), loadf(addr, 1), loadf(addr, 2)};
}

/// Moeller and Trumbore, "Fast, Minimum Storage Ray/Triangle Intersection", JGT 2(1), 1997:
/// the distance t along dir to the triangle at `tri`, or -1 when the ray misses it.
float intersect(Vec3 origin, Vec3 dir, int tri) {
    const Vec3 v0 = load_vec3(tri + kTriangleV0);
    const Vec3 e1 = load_vec3(tri + kTriangleV1) - v0, e2 = load_vec3(tri + kTriangleV2) - v0;
    const Vec3 p = cross(dir, e2);
    const float det = dot(e1, p);
    if (det == 0.0f) return -1.0f;
    const float inverse = 1.0f / det;
    const Vec3 s = origin - v0;
    const float u = dot(s, p) * inverse;
    if (u < 0.0f || u > 1.0f) return -1.0f;
    const Vec3 q = cross(s, e1);
    const float v = dot(dir, q) * inverse;
    if (v < 0.0f || u + v > 1.0f) return -1.0f;
    return dot(e2, q) * inverse;
}

struct Scene {
    int triangles, num_triangles;
};

/// The closest triangle hit with 0 < t < t_max (its address, or -1), and its t.
int closest_hit(const Scene& scene, Vec3 origin, Vec3 dir, float t_max, float& t) {
    int hit = -1;
    t = t_max;
    for (int i = 0; i < scene.num_triangles; ++i) {
        const int tri = scene.triangles + i * kTriangleWords;
        const float d = intersect(origin, dir, tri);
        if (d > 0.0f && d < t) {
            t = d;
            hit = tri;
        }
    }
    return hit;
}

/// Whether any triangle lies on the segment origin + t * dir, 0 < t < 1.
bool blocked(const Scene& scene, Vec3 origin, Vec3 dir) {
    for (int i = 0; i < scene.num_triangles; ++i) {
        const float d = intersect(origin, dir, scene.triangles + i * kTriangleWords);
        if (d > 0.0f && d < 1.0f) return true;
    }
    return false;
}

void trax_main() {
    const Scene scene{trax_triangles(), trax_num_triangles()};
    const int width = trax_image_width(), height = trax_image_height();
    const int camera = trax_camera();
    const Vec3 eye = load_vec3(camera + kCameraEye), corner = load_vec3(camera + kCameraCorner);
    const Vec3 right = load_vec3(camera + kCameraRight), down = load_vec3(camera + kCameraDown);
    const Vec3 ambient = load_vec3(trax_ambient()), background = load_vec3(trax_background());
    const int flags = trax_scene_flags();
    const int framebuffer = trax_framebuffer();
    // The scene is scaled to fit in [-1, 1]: 1e-4 is far above float's rounding there and far
    // below any feature of the scene.
    const float kOffset = 1e-4f;

    for (int pixel = atomicinc(0); pixel < width * height; pixel = atomicinc(0)) {
        const float u = (static_cast<float>(pixel % width) + 0.5f) / static_cast<float>(width);
        const float v = (static_cast<float>(pixel / width) + 0.5f) / static_cast<float>(height);
        const Vec3 dir = corner + right * u + down * v;
        Vec3 color = background;
        float t;
        const int tri = closest_hit(scene, eye, dir, 3.0e38f, t);
        if (tri >= 0) {
            const Vec3 p = eye + dir * t;
            const Vec3 v0 = load_vec3(tri + kTriangleV0);
            Vec3 n = cross(load_vec3(tri + kTriangleV1) - v0, load_vec3(tri + kTriangleV2) - v0);
            n = n * (1.0f / trax_sqrt(dot(n, n)));
            if (dot(n, dir) > 0.0f) n = n * -1.0f;  // the side the camera sees
            const Vec3 start = p + n * kOffset;
            Vec3 light = ambient;
            for (int i = 0; i < trax_num_lights(); ++i) {
                const int record = trax_lights() + i * kPointLightWords;
                const Vec3 to_light = load_vec3(record + kLightPosition) - p;
                const float distance2 = dot(to_light, to_light);
                const float cosine = dot(n, to_light) / trax_sqrt(distance2);
                if (cosine <= 0.0f) continue;
                if ((flags & kFeatureShadows) &&
                    blocked(scene, start, load_vec3(record + kLightPosition) - start))
                    continue;
                const float weight = (flags & kFeatureLightFalloff) ? cosine / distance2 : cosine;
                light = light + load_vec3(record + kLightColor) * weight;
            }
            const int material = trax_materials() + loadi(tri, kTriangleMaterial) * kMaterialWords;
            color = load_vec3(material + kMaterialDiffuse) * light;
        }
        const int out = framebuffer + pixel * kPixelWords;
        storef(color.x, out, 0);
        storef(color.y, out, 1);
        storef(color.z, out, 2);
    }
}
