// Assignment 2: ray casting a sphere (docs/course/2-sphere.md).
//
// The memory holds triangles only, so the sphere lives in the kernel: centre (0, 0, -0.7),
// radius 0.2, in the scene's coordinates (the camera's eye is at the origin). As given, every
// camera ray is made but nothing is hit, so the image is the background colour.
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

[[maybe_unused]] constexpr Vec3 kCenter{0.0f, 0.0f, -0.7f};
[[maybe_unused]] constexpr float kRadius = 0.2f;

/// The nearest t > 0 where origin + t * dir meets the sphere, or -1 for none.
float hit_sphere(Vec3 origin, Vec3 dir) {
    // TODO 1: solve |origin + t * dir - kCenter|^2 = kRadius^2 for t (a quadratic; trax_sqrt
    // is the square root) and return the smallest root > 0.
    (void)origin;
    (void)dir;
    return -1.0f;
}

void trax_main() {
    const int width = trax_image_width(), height = trax_image_height();
    const int camera = trax_camera();
    const Vec3 eye = load_vec3(camera + kCameraEye), corner = load_vec3(camera + kCameraCorner);
    const Vec3 right = load_vec3(camera + kCameraRight), down = load_vec3(camera + kCameraDown);
    const Vec3 albedo = load_vec3(trax_materials() + kMaterialDiffuse);
    const Vec3 background = load_vec3(trax_background());
    const int framebuffer = trax_framebuffer();

    for (int pixel = atomicinc(0); pixel < width * height; pixel = atomicinc(0)) {
        // The ray through the pixel's centre: u to the right, v down, both in [0, 1].
        const float u = (static_cast<float>(pixel % width) + 0.5f) / static_cast<float>(width);
        const float v = (static_cast<float>(pixel / width) + 0.5f) / static_cast<float>(height);
        const Vec3 dir = corner + right * u + down * v;
        Vec3 color = background;
        const float t = hit_sphere(eye, dir);
        if (t > 0.0f) {
            // TODO 2: Lambert shading. At p = eye + dir * t the unit normal is
            // (p - kCenter) / kRadius; the colour is albedo * (ambient + the sum over the
            // lights of light colour * max(0, cosine between the normal and the direction to
            // the light)). Read the lights with trax_lights(), trax_num_lights(),
            // kPointLightWords, kLightPosition, kLightColor and the ambient light at
            // trax_ambient().
            color = albedo;
        }
        const int out = framebuffer + pixel * kPixelWords;
        storef(color.x, out, 0);
        storef(color.y, out, 1);
        storef(color.z, out, 2);
    }
}
