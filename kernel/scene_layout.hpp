// The guest memory image of a scene: the one layout shared by the scene compiler (host) and the
// kernels (guest). Freestanding: only <stddef.h>/<stdint.h>, no host types, no pointers.
//
// Addresses here are WORD addresses relative to trax::map::kGlobalBase (word 0 = first word of
// global memory = the scene header), the unit the kernel API (loadf/loadi ...) takes.
// Every struct is plain 32-bit words so a kernel can read any field with loadf(base, offset).
// See docs/kernel-api.md.
#pragma once
#include <stddef.h>
#include <stdint.h>

namespace trax::layout {

/// "TPSC" little-endian: lets the loader and the twin reject a memory image that is not a scene.
constexpr uint32_t kMagic = 0x4353'5054u;
/// Bumped whenever a struct below changes shape.
constexpr uint32_t kVersion = 1;

/// Sections start on 16-word (64-byte, one cache line) boundaries so no record of one section
/// shares a line with another section.
constexpr int32_t kSectionAlignWords = 16;

/// Feature flags in SceneHeader::flags: rendering choices the scene file makes.
enum Feature : uint32_t {
    kFeatureShadows = 1u << 0,          ///< cast a shadow ray to every light
    kFeatureLightFalloff = 1u << 1,     ///< divide light intensity by squared distance
};

/// Where a section lives: word address (relative to kGlobalBase) and number of records.
/// A section with count 0 takes no space; its addr is where it would start.
struct SectionRef {
    int32_t addr;
    int32_t count;
};

/// Camera, precomputed so a primary ray costs a few multiply-adds: the ray through image point
/// (u, v) in [0,1]^2, u to the right and v DOWN from the top-left corner, is
///   origin = eye, direction = corner + u * right + v * down   (not normalised).
struct Camera {
    float eye[3];
    float corner[3];  ///< from eye to the top-left corner of the image plane
    float right[3];   ///< spans the full image width on the image plane
    float down[3];    ///< spans the full image height on the image plane
};

/// Point light: position and radiant intensity per channel (linear RGB).
struct PointLight {
    float position[3];
    float color[3];
};

/// Lambertian material.
struct Material {
    float diffuse[3];  ///< albedo, linear RGB
};

/// Triangle as the Woop et al. 2013 watertight test wants it: the three vertices.
struct Triangle {
    float v0[3];
    float v1[3];
    float v2[3];
    int32_t material;  ///< index into the materials section
};

/// Binary BVH node, 32 bytes. Node 0 is the root. Triangles are stored in leaf order, so a
/// leaf references a contiguous range of the triangles section (no index indirection).
///   count == 0: interior node; children are nodes first and first + 1.
///   count  > 0: leaf holding triangles [first, first + count), count <= kMaxLeafTriangles.
struct BvhNode {
    float bounds_min[3];
    float bounds_max[3];
    int32_t first;
    int32_t count;
};
constexpr int32_t kMaxLeafTriangles = 8;

/// The first words of global memory.
struct SceneHeader {
    uint32_t magic;
    uint32_t version;
    int32_t image_width;
    int32_t image_height;
    int32_t samples_per_pixel;
    uint32_t flags;        ///< Feature bits
    int32_t total_words;   ///< size of the whole image, framebuffer included
    float ambient[3];      ///< ambient light, multiplied by the diffuse albedo
    float background[3];   ///< colour of rays that hit nothing
    SectionRef camera;     ///< count 1
    SectionRef lights;
    SectionRef materials;
    SectionRef triangles;
    SectionRef bvh_nodes;  ///< count 0 when the scene has no BVH
    SectionRef framebuffer;  ///< count = width * height pixels, 3 floats (linear RGB) each, row 0 = top
};

/// Size of each record in words, the stride a kernel uses to step through a section.
constexpr int32_t kCameraWords = sizeof(Camera) / 4;
constexpr int32_t kPointLightWords = sizeof(PointLight) / 4;
constexpr int32_t kMaterialWords = sizeof(Material) / 4;
constexpr int32_t kTriangleWords = sizeof(Triangle) / 4;
constexpr int32_t kBvhNodeWords = sizeof(BvhNode) / 4;
constexpr int32_t kPixelWords = 3;
constexpr int32_t kHeaderWords = sizeof(SceneHeader) / 4;

/// Word offsets of header fields, for loadi(0, kHeader...) in kernels.
enum HeaderWord : int32_t {
    kHeaderMagic = 0,
    kHeaderVersion = 1,
    kHeaderImageWidth = 2,
    kHeaderImageHeight = 3,
    kHeaderSamplesPerPixel = 4,
    kHeaderFlags = 5,
    kHeaderTotalWords = 6,
    kHeaderAmbient = 7,
    kHeaderBackground = 10,
    kHeaderCamera = 13,       ///< SectionRef: +0 addr, +1 count
    kHeaderLights = 15,
    kHeaderMaterials = 17,
    kHeaderTriangles = 19,
    kHeaderBvhNodes = 21,
    kHeaderFramebuffer = 23,
};

/// Word offsets of record fields, for loadf(record_addr, kTri...) in kernels.
enum RecordWord : int32_t {
    kCameraEye = 0, kCameraCorner = 3, kCameraRight = 6, kCameraDown = 9,
    kLightPosition = 0, kLightColor = 3,
    kMaterialDiffuse = 0,
    kTriangleV0 = 0, kTriangleV1 = 3, kTriangleV2 = 6, kTriangleMaterial = 9,
    kNodeMin = 0, kNodeMax = 3, kNodeFirst = 6, kNodeCount = 7,
};

// The enums above and the structs must agree, and every record must be whole words: a kernel
// reading with loadf(addr, kX) and a host writing through the struct see the same word.
#define TRAX_LAYOUT_WORD(type, field, word) static_assert(offsetof(type, field) == 4 * (word))
TRAX_LAYOUT_WORD(SceneHeader, magic, kHeaderMagic);
TRAX_LAYOUT_WORD(SceneHeader, version, kHeaderVersion);
TRAX_LAYOUT_WORD(SceneHeader, image_width, kHeaderImageWidth);
TRAX_LAYOUT_WORD(SceneHeader, image_height, kHeaderImageHeight);
TRAX_LAYOUT_WORD(SceneHeader, samples_per_pixel, kHeaderSamplesPerPixel);
TRAX_LAYOUT_WORD(SceneHeader, flags, kHeaderFlags);
TRAX_LAYOUT_WORD(SceneHeader, total_words, kHeaderTotalWords);
TRAX_LAYOUT_WORD(SceneHeader, ambient, kHeaderAmbient);
TRAX_LAYOUT_WORD(SceneHeader, background, kHeaderBackground);
TRAX_LAYOUT_WORD(SceneHeader, camera, kHeaderCamera);
TRAX_LAYOUT_WORD(SceneHeader, lights, kHeaderLights);
TRAX_LAYOUT_WORD(SceneHeader, materials, kHeaderMaterials);
TRAX_LAYOUT_WORD(SceneHeader, triangles, kHeaderTriangles);
TRAX_LAYOUT_WORD(SceneHeader, bvh_nodes, kHeaderBvhNodes);
TRAX_LAYOUT_WORD(SceneHeader, framebuffer, kHeaderFramebuffer);
TRAX_LAYOUT_WORD(Camera, eye, kCameraEye);
TRAX_LAYOUT_WORD(Camera, corner, kCameraCorner);
TRAX_LAYOUT_WORD(Camera, right, kCameraRight);
TRAX_LAYOUT_WORD(Camera, down, kCameraDown);
TRAX_LAYOUT_WORD(PointLight, position, kLightPosition);
TRAX_LAYOUT_WORD(PointLight, color, kLightColor);
TRAX_LAYOUT_WORD(Material, diffuse, kMaterialDiffuse);
TRAX_LAYOUT_WORD(Triangle, v0, kTriangleV0);
TRAX_LAYOUT_WORD(Triangle, v1, kTriangleV1);
TRAX_LAYOUT_WORD(Triangle, v2, kTriangleV2);
TRAX_LAYOUT_WORD(Triangle, material, kTriangleMaterial);
TRAX_LAYOUT_WORD(BvhNode, bounds_min, kNodeMin);
TRAX_LAYOUT_WORD(BvhNode, bounds_max, kNodeMax);
TRAX_LAYOUT_WORD(BvhNode, first, kNodeFirst);
TRAX_LAYOUT_WORD(BvhNode, count, kNodeCount);
#undef TRAX_LAYOUT_WORD

static_assert(sizeof(float) == 4 && sizeof(int32_t) == 4);
static_assert(sizeof(SectionRef) == 8);
static_assert(sizeof(Camera) == 48);
static_assert(sizeof(PointLight) == 24);
static_assert(sizeof(Material) == 12);
static_assert(sizeof(Triangle) == 40);
static_assert(sizeof(BvhNode) == 32, "the BVH node is one half cache line");
static_assert(sizeof(SceneHeader) == 100);

/// Rounds a word address up to the section alignment.
constexpr int32_t align_section(int32_t word) {
    return (word + kSectionAlignWords - 1) / kSectionAlignWords * kSectionAlignWords;
}

/// THE section placement rule. Given a header whose counts (and image size) are filled in,
/// assigns every section's addr and total_words: sections follow the header in the order
/// camera, lights, materials, triangles, bvh_nodes, framebuffer, each aligned to
/// kSectionAlignWords; empty sections take no space. The framebuffer count is set from the
/// image size. The scene compiler calls this; tests check images against it.
constexpr void place_sections(SceneHeader& h) {
    h.camera.count = 1;
    h.framebuffer.count = h.image_width * h.image_height;
    struct Section {
        SectionRef* ref;
        int32_t record_words;
    };
    const Section order[] = {
        {&h.camera, kCameraWords},       {&h.lights, kPointLightWords},
        {&h.materials, kMaterialWords},  {&h.triangles, kTriangleWords},
        {&h.bvh_nodes, kBvhNodeWords},   {&h.framebuffer, kPixelWords},
    };
    int32_t next = align_section(kHeaderWords);
    for (const Section& s : order) {
        s.ref->addr = next;
        if (s.ref->count > 0) next = align_section(next + s.ref->count * s.record_words);
    }
    h.total_words = next;
}

}  // namespace trax::layout
