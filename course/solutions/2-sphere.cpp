// Assignment 2, reference solution: ray casting one sphere the kernel knows (centre
// (0, 0, -0.7), radius 0.2, the scene's first material), Lambert shading from the scene's point
// lights plus the ambient light; rays that miss see the background.
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
float dot(Vec3 a, Vec3 b) {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
Vec3 load_vec3(int addr) {
    return {loadf(addr, 0), loadf(addr, 1), loadf(addr, 2)};
}

constexpr Vec3 kCenter{0.0f, 0.0f, -0.7f};
constexpr float kRadius = 0.2f;

/// The nearest t > 0 where origin + t * dir meets the sphere, or -1 for none.
float hit_sphere(Vec3 origin, Vec3 dir) {
    const Vec3 oc = origin - kCenter;
    const float a = dot(dir, dir), b = dot(oc, dir), c = dot(oc, oc) - kRadius * kRadius;
    const float discriminant = b * b - a * c;
    if (discriminant < 0.0f) return -1.0f;
    const float root = trax_sqrt(discriminant);
    const float near = (-b - root) / a;
    return near > 0.0f ? near : (-b + root) / a;
}

void trax_main() {
    const int width = trax_image_width(), height = trax_image_height();
    const int camera = trax_camera();
    const Vec3 eye = load_vec3(camera + kCameraEye), corner = load_vec3(camera + kCameraCorner);
    const Vec3 right = load_vec3(camera + kCameraRight), down = load_vec3(camera + kCameraDown);
    const Vec3 albedo = load_vec3(trax_materials() + kMaterialDiffuse);
    const Vec3 ambient = load_vec3(trax_ambient()), background = load_vec3(trax_background());
    const bool falloff = trax_scene_flags() & kFeatureLightFalloff;
    const int framebuffer = trax_framebuffer();

    for (int pixel = atomicinc(0); pixel < width * height; pixel = atomicinc(0)) {
        const float u = (static_cast<float>(pixel % width) + 0.5f) / static_cast<float>(width);
        const float v = (static_cast<float>(pixel / width) + 0.5f) / static_cast<float>(height);
        const Vec3 dir = corner + right * u + down * v;
        Vec3 color = background;
        const float t = hit_sphere(eye, dir);
        if (t > 0.0f) {
            const Vec3 p = eye + dir * t;
            const Vec3 n = (p - kCenter) * (1.0f / kRadius);
            Vec3 light = ambient;
            for (int i = 0; i < trax_num_lights(); ++i) {
                const int record = trax_lights() + i * kPointLightWords;
                const Vec3 to_light = load_vec3(record + kLightPosition) - p;
                const float distance2 = dot(to_light, to_light);
                const float cosine = dot(n, to_light) / trax_sqrt(distance2);
                if (cosine <= 0.0f) continue;
                const float weight = falloff ? cosine / distance2 : cosine;
                light = light + load_vec3(record + kLightColor) * weight;
            }
            color = {albedo.x * light.x, albedo.y * light.y, albedo.z * light.z};
        }
        const int out = framebuffer + pixel * kPixelWords;
        storef(color.x, out, 0);
        storef(color.y, out, 1);
        storef(color.z, out, 2);
    }
}
