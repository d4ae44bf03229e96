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
constexpr uint32_t kVersion = 6;

/// Sections start on 16-word (64-byte, one cache line) boundaries so no record of one section
/// shares a line with another section.
constexpr int32_t kSectionAlignWords = 16;

/// Name of the marker symbol a kernel's ELF defines (TRAX_USES_BVH in trax.hpp) when it
/// traverses the BVH: the host builds a BVH and lays it out only for such kernels.
constexpr const char* kUsesBvhSymbol = "trax_uses_bvh";
/// The same for a kernel that traverses the uniform grid (TRAX_USES_GRID): the host then builds
/// the grid (and no BVH) and puts its AccelRecord, cells and references in the memory image.
constexpr const char* kUsesGridSymbol = "trax_uses_grid";
/// The same for a kernel that traverses a wide BVH (TRAX_USES_WIDE_BVH): the host builds the
/// binary BVH, collapses it to 4 or 8 children per node (render --accel bvh4|bvh8) and lays out
/// only the wide nodes (AccelRecord kind kAccelWideBvh).
constexpr const char* kUsesWideBvhSymbol = "trax_uses_wide_bvh";
/// The same for a kernel that traverses the kd-tree (TRAX_USES_KDTREE).
constexpr const char* kUsesKdTreeSymbol = "trax_uses_kdtree";
/// The same for a kernel that traverses the octree (TRAX_USES_OCTREE).
constexpr const char* kUsesOctreeSymbol = "trax_uses_octree";
/// The same for a kernel that traverses the BSP tree (TRAX_USES_BSP).
constexpr const char* kUsesBspSymbol = "trax_uses_bsp";
/// Name of the marker symbol trax.hpp's emitter and random-number functions leave in a kernel's
/// ELF: the host adds the SceneExtras sections only for such kernels, so the memory image (and
/// every statistic) of a kernel that reads neither stays as it was before they existed.
constexpr const char* kUsesExtrasSymbol = "trax_uses_extras";

/// Feature flags in SceneHeader::flags: rendering choices the scene file makes.
enum Feature : uint32_t {
    kFeatureShadows = 1u << 0,       ///< cast a shadow ray to every light
    kFeatureLightFalloff = 1u << 1,  ///< divide light intensity by squared distance
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

/// What a material emits: radiance per channel (linear RGB), the same from every point of the
/// surface and in every direction of its front side, the side the triangle's normal
/// (v1 - v0) x (v2 - v0) points to (an OBJ's counter-clockwise face). Independent of the scene's
/// scale.
struct Emission {
    float radiance[3];
};

/// One emissive triangle, for light sampling (next-event estimation): pick emitter i with
/// probability `probability` (proportional to area times mean radiance; draw u in [0,1) and
/// take the first i with u < cdf), then a uniform point on it (density 1 / area).
struct Emitter {
    int32_t triangle;   ///< index into the triangles section (image order)
    float area;         ///< in the image's units
    float probability;  ///< of picking this emitter; they sum to 1
    float cdf;          ///< sum of the probabilities up to and including this one; last = 1
};

/// The optional part of the image: present only for kernels that read it (kUsesExtrasSymbol),
/// always at word kExtrasAddr, the first section after the header.
struct SceneExtras {
    uint32_t seed;        ///< the run's seed (tpsim render --seed), for trax_rand()'s seeding
    SectionRef emission;  ///< one Emission per material (count = materials count)
    SectionRef emitters;  ///< one Emitter per emissive triangle (count 0: nothing emits)
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
/// Entries in the kernels' BVH traversal stack (kernel/rt.hpp). They keep the current node in a
/// register and push only the far child, so a BVH whose deepest leaf is at depth <= this never
/// overflows: the host builds with scene::BvhConfig::traversal_stack_entries set to it.
constexpr int32_t kTraversalStackEntries = 32;

/// Entries in the wide-BVH traversal stack (kernel/wide_bvh.hpp). It pushes every child a ray
/// hits but the nearest; the host refuses a wide BVH in which some path could need more
/// (scene::WideBvhStats::worst_stack).
constexpr int32_t kWideStackEntries = 64;

/// Which acceleration structure an AccelRecord describes.
enum AccelKind : int32_t {
    kAccelGrid = 1,
    kAccelWideBvh = 2,
    kAccelKdTree = 3,
    kAccelOctree = 4,
    kAccelBsp = 5,
};

/// Entries in the kd-tree traversal stack (kernel/kdtree.hpp): one per level, the host builds
/// no deeper tree (scene::kKdMaxDepth).
constexpr int32_t kKdStackEntries = 40;
/// kd-tree nodes are two words: an interior node holds its plane's position (float) and
/// axis | right child << 2 (axis 0..2; the left child is the next node); a leaf holds the
/// first of its references and kKdLeaf | count << 2.
constexpr int32_t kKdNodeWords = 2;
constexpr uint32_t kKdLeaf = 3;

/// The orientations of a BSP tree's planes n.x = split: the three axes, the six face diagonals
/// and the four space diagonals of the cube, as integer normals (kernel/kdtree.hpp computes n.v
/// as the same sums and differences of coordinates).
constexpr int32_t kBspDirections = 13;
constexpr int32_t kBspDirection[kBspDirections][3] = {
    {1, 0, 0}, {0, 1, 0},  {0, 0, 1}, {1, 1, 0},  {1, -1, 0}, {1, 0, 1}, {1, 0, -1},
    {0, 1, 1}, {0, 1, -1}, {1, 1, 1}, {1, 1, -1}, {1, -1, 1}, {-1, 1, 1}};
/// BSP nodes are the kd-tree's two words with four bits for the orientation: an interior node
/// holds split (float) and direction | right child << 4, a leaf its first reference and
/// kBspLeaf | count << 4.
constexpr uint32_t kBspShapeBits = 4;
constexpr uint32_t kBspLeaf = 15;

/// Entries in the octree traversal stack (kernel/octree.hpp): a cell pushes at most the three
/// octants after the first, the host builds no deeper tree than a third of this
/// (scene::kOctreeMaxDepth).
constexpr int32_t kOctreeStackEntries = 48;
/// Octree nodes are four words, in groups of eight siblings (octant c at + c: bit 0 set above
/// the centre on x, bit 1 on y, bit 2 on z; 128 bytes, two lines), the root alone in group 0.
/// Word kOctreeShape is first_child << 8 | occupied (bit c: octant c holds triangles; the
/// others are never read) for an interior node, -1 for a leaf. An interior node's words 0..2
/// hold the centre it cuts its cell at; a leaf's words kOctreeFirst and kOctreeCount its first
/// reference and how many.
constexpr int32_t kOctreeNodeWords = 4;
constexpr int32_t kOctreeShape = 3, kOctreeFirst = 0, kOctreeCount = 1;
constexpr int32_t kOctreeMaxFirstChild = (1 << 23) - 1;

/// A wide-BVH child reference, the same in both box formats: 0 is no child (a node's children
/// come first, its empty slots last); > 0 is the word address of an interior child's node; < 0
/// is a leaf holding triangles [first, first + count) of the triangles section, encoded as
/// kWideLeafBit | first << 4 | count (count 1..kMaxLeafTriangles, first < 2^27).
constexpr uint32_t kWideLeafBit = 0x8000'0000u;
constexpr int32_t kWideMaxLeafFirst = (1 << 27) - 1;
/// Words of one wide node: every node starts on a 64-byte line.
///   Float boxes: words [6c, 6c + 6) hold child c's box (min xyz, max xyz), word 6 * width + c
///   its reference; 8 * width words (padding to the line).
///   Quantized boxes (Ylitie et al. 2017): words 0..2 the node's box origin o (floats); word 3
///   the biased exponents e_x | e_y << 8 | e_z << 16 (scale s_a = 2^(e_a - 127), the float with
///   bits e_a << 23); words [4, 4 + width) the references; then six byte vectors of `width`
///   bytes, lo_x, lo_y, lo_z, hi_x, hi_y, hi_z: child c's box on axis a is
///   [o_a + lo_a[c] * s_a, o_a + hi_a[c] * s_a], computed in float (the product is exact), and
///   contains the child's float box; 4 * width words.
constexpr int32_t wide_node_words(int32_t width, bool quantized) {
    return quantized ? 4 * width : 8 * width;
}
/// Quantized nodes: the word of the first reference, and the byte offset of the byte vectors.
constexpr int32_t kWideQuantizedRefs = 4;
constexpr int32_t wide_quantized_boxes_byte(int32_t width) {
    return (kWideQuantizedRefs + width) * 4;
}

/// The acceleration structure other than the binary BVH (which has its own header section),
/// one record the header's `accel` word points to.
///
/// Uniform grid (kAccelGrid): the box [bounds_min, bounds_max] cut into resolution[0] x
/// resolution[1] x resolution[2] cells; the cell of point p on axis a is
/// floor((p[a] - bounds_min[a]) * scale[a]), scale = resolution / extent, and cell (x, y, z) is
/// number x + resolution[0] * (y + resolution[1] * z). `nodes` holds one word per cell plus one:
/// cell i's triangles are refs[nodes[i] .. nodes[i + 1]), image triangle indices, every triangle
/// listed in every cell its bounding box overlaps (so a triangle may appear in many cells).
///
/// kd-tree (kAccelKdTree): the bounds are the tree's box; `nodes` holds the nodes
/// (kKdNodeWords each, count in words, the root first, depth-first), `refs` the leaves'
/// triangles (image triangle indices, in scene order; a triangle is listed in every leaf its
/// bounding box reaches).
///
/// BSP tree (kAccelBsp): as the kd-tree, its nodes in the BSP layout (kBspShapeBits).
///
/// Octree (kAccelOctree): the bounds are the root cell; `nodes` holds the nodes
/// (kOctreeNodeWords each, count in words), `refs` the leaves' triangles (image triangle
/// indices, in scene order; a triangle is listed in every leaf its bounding box reaches).
///
/// Wide BVH (kAccelWideBvh): `width` (4 or 8) children per node, boxes quantized or not; the
/// bounds are the root's box; `nodes` holds the nodes (count in words, the root first, each
/// wide_node_words long); refs, scale and resolution are unused.
struct AccelRecord {
    int32_t kind;  ///< AccelKind
    SectionRef nodes;
    SectionRef refs;
    float bounds_min[3];
    float bounds_max[3];
    float scale[3];
    int32_t resolution[3];
    int32_t width;
    int32_t quantized;  ///< 1: quantized child boxes, 0: float
};

/// The first words of global memory.
struct SceneHeader {
    uint32_t magic;
    uint32_t version;
    int32_t image_width;
    int32_t image_height;
    int32_t samples_per_pixel;
    uint32_t flags;       ///< Feature bits
    int32_t total_words;  ///< size of the whole image, framebuffer included
    float ambient[3];     ///< ambient light, multiplied by the diffuse albedo
    float background[3];  ///< colour of rays that hit nothing
    SectionRef camera;    ///< count 1
    SectionRef lights;
    SectionRef materials;
    SectionRef triangles;
    SectionRef bvh_nodes;  ///< count 0 when the scene has no BVH
    SectionRef
        framebuffer;  ///< count = width * height pixels, 3 floats (linear RGB) each, row 0 = top
    SectionRef thread_stats;  ///< one ThreadStats per hardware thread, written by the kernel
    SectionRef rays;          ///< ray_query input batch (count 0 for renders)
    SectionRef ray_results;   ///< ray_query output, one RayResult per ray
    int32_t accel;            ///< word address of the AccelRecord, 0 when the image has none
};

/// Traversal statistics of one hardware thread. The kernel counts in registers and writes its
/// record once, before returning; the host sums the records. 64-bit counts are split in two
/// words (lo, hi) so every field stays one 32-bit word.
struct ThreadStats {
    uint32_t primary_rays;      ///< closest-hit rays (camera rays, ray_query closest queries)
    uint32_t shadow_rays;       ///< any-hit rays
    uint32_t nodes_visited_lo;  ///< BVH node boxes tested (root included), summed over rays
    uint32_t nodes_visited_hi;
    uint32_t triangles_tested_lo;  ///< ray/triangle tests, summed over rays
    uint32_t triangles_tested_hi;
    uint32_t max_stack_depth;  ///< most traversal-stack entries in use at once
    uint32_t stack_overflows;  ///< pushes refused because the stack was full (must stay 0)
};

/// Query modes of a Ray (bits).
enum RayMode : int32_t {
    kRayClosestHit = 0,
    kRayAnyHit = 1,  ///< stop at the first hit, as a shadow ray does
    /// Shading's two rays: the ray (a camera ray) is traced to its closest hit, then a second
    /// ray leaves that surface point, as a shadow ray does, on the segment to Ray::target
    /// (0 < t < 1 from the offset origin). kRayAnyHit applies to the second ray.
    kRayFromSurface = 2,
};

/// One query of the ray_query kernel: the segment origin + t * direction, 0 < t < t_max.
struct Ray {
    float origin[3];
    float direction[3];
    float t_max;
    int32_t mode;     ///< RayMode bits
    float target[3];  ///< kRayFromSurface: where the second ray goes (a light)
};

/// What ray_query writes for one Ray.
struct RayResult {
    int32_t triangle;  ///< image triangle index of the hit, or -1 (kRayFromSurface: second ray)
    float t;           ///< hit distance in units of the direction; t_max when nothing was hit
    /// kRayFromSurface: the first ray's hit (image triangle, -1 if it missed and no second ray
    /// was traced) and distance
    int32_t surface_triangle;
    float surface_t;
    uint32_t nodes_visited;
    uint32_t triangles_tested;
    uint32_t max_stack_depth;
    uint32_t stack_overflows;
};

/// Size of each record in words, the stride a kernel uses to step through a section.
constexpr int32_t kCameraWords = sizeof(Camera) / 4;
constexpr int32_t kPointLightWords = sizeof(PointLight) / 4;
constexpr int32_t kMaterialWords = sizeof(Material) / 4;
constexpr int32_t kEmissionWords = sizeof(Emission) / 4;
constexpr int32_t kEmitterWords = sizeof(Emitter) / 4;
constexpr int32_t kExtrasWords = sizeof(SceneExtras) / 4;
constexpr int32_t kTriangleWords = sizeof(Triangle) / 4;
constexpr int32_t kBvhNodeWords = sizeof(BvhNode) / 4;
constexpr int32_t kPixelWords = 3;
constexpr int32_t kThreadStatsWords = sizeof(ThreadStats) / 4;
constexpr int32_t kRayWords = sizeof(Ray) / 4;
constexpr int32_t kRayResultWords = sizeof(RayResult) / 4;
constexpr int32_t kHeaderWords = sizeof(SceneHeader) / 4;
constexpr int32_t kAccelRecordWords = sizeof(AccelRecord) / 4;

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
    kHeaderCamera = 13,  ///< SectionRef: +0 addr, +1 count
    kHeaderLights = 15,
    kHeaderMaterials = 17,
    kHeaderTriangles = 19,
    kHeaderBvhNodes = 21,
    kHeaderFramebuffer = 23,
    kHeaderThreadStats = 25,
    kHeaderRays = 27,
    kHeaderRayResults = 29,
    kHeaderAccel = 31,
};

/// Word offsets of record fields, for loadf(record_addr, kTri...) in kernels.
enum RecordWord : int32_t {
    kCameraEye = 0,
    kCameraCorner = 3,
    kCameraRight = 6,
    kCameraDown = 9,
    kLightPosition = 0,
    kLightColor = 3,
    kMaterialDiffuse = 0,
    kEmissionRadiance = 0,
    kEmitterTriangle = 0,
    kEmitterArea = 1,
    kEmitterProbability = 2,
    kEmitterCdf = 3,
    kExtrasSeed = 0,
    kExtrasEmission = 1,  ///< SectionRef: +0 addr, +1 count
    kExtrasEmitters = 3,
    kTriangleV0 = 0,
    kTriangleV1 = 3,
    kTriangleV2 = 6,
    kTriangleMaterial = 9,
    kNodeMin = 0,
    kNodeMax = 3,
    kNodeFirst = 6,
    kNodeCount = 7,
    kAccelKind = 0,
    kAccelNodes = 1,  ///< SectionRef: +0 addr, +1 count
    kAccelRefs = 3,
    kAccelBoundsMin = 5,
    kAccelBoundsMax = 8,
    kAccelScale = 11,
    kAccelResolution = 14,
    kAccelWidth = 17,
    kAccelQuantized = 18,
    kStatsPrimaryRays = 0,
    kStatsShadowRays = 1,
    kStatsNodesVisited = 2,
    kStatsTrianglesTested = 4,
    kStatsMaxStackDepth = 6,
    kStatsStackOverflows = 7,
    kRayOrigin = 0,
    kRayDirection = 3,
    kRayTMax = 6,
    kRayMode = 7,
    kRayTarget = 8,
    kResultTriangle = 0,
    kResultT = 1,
    kResultSurfaceTriangle = 2,
    kResultSurfaceT = 3,
    kResultNodesVisited = 4,
    kResultTrianglesTested = 5,
    kResultMaxStackDepth = 6,
    kResultStackOverflows = 7,
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
TRAX_LAYOUT_WORD(SceneHeader, thread_stats, kHeaderThreadStats);
TRAX_LAYOUT_WORD(SceneHeader, rays, kHeaderRays);
TRAX_LAYOUT_WORD(SceneHeader, ray_results, kHeaderRayResults);
TRAX_LAYOUT_WORD(SceneHeader, accel, kHeaderAccel);
TRAX_LAYOUT_WORD(AccelRecord, kind, kAccelKind);
TRAX_LAYOUT_WORD(AccelRecord, nodes, kAccelNodes);
TRAX_LAYOUT_WORD(AccelRecord, refs, kAccelRefs);
TRAX_LAYOUT_WORD(AccelRecord, bounds_min, kAccelBoundsMin);
TRAX_LAYOUT_WORD(AccelRecord, bounds_max, kAccelBoundsMax);
TRAX_LAYOUT_WORD(AccelRecord, scale, kAccelScale);
TRAX_LAYOUT_WORD(AccelRecord, resolution, kAccelResolution);
TRAX_LAYOUT_WORD(AccelRecord, width, kAccelWidth);
TRAX_LAYOUT_WORD(AccelRecord, quantized, kAccelQuantized);
TRAX_LAYOUT_WORD(ThreadStats, primary_rays, kStatsPrimaryRays);
TRAX_LAYOUT_WORD(ThreadStats, shadow_rays, kStatsShadowRays);
TRAX_LAYOUT_WORD(ThreadStats, nodes_visited_lo, kStatsNodesVisited);
TRAX_LAYOUT_WORD(ThreadStats, triangles_tested_lo, kStatsTrianglesTested);
TRAX_LAYOUT_WORD(ThreadStats, max_stack_depth, kStatsMaxStackDepth);
TRAX_LAYOUT_WORD(ThreadStats, stack_overflows, kStatsStackOverflows);
TRAX_LAYOUT_WORD(Ray, origin, kRayOrigin);
TRAX_LAYOUT_WORD(Ray, direction, kRayDirection);
TRAX_LAYOUT_WORD(Ray, t_max, kRayTMax);
TRAX_LAYOUT_WORD(Ray, mode, kRayMode);
TRAX_LAYOUT_WORD(Ray, target, kRayTarget);
TRAX_LAYOUT_WORD(RayResult, triangle, kResultTriangle);
TRAX_LAYOUT_WORD(RayResult, t, kResultT);
TRAX_LAYOUT_WORD(RayResult, surface_triangle, kResultSurfaceTriangle);
TRAX_LAYOUT_WORD(RayResult, surface_t, kResultSurfaceT);
TRAX_LAYOUT_WORD(RayResult, nodes_visited, kResultNodesVisited);
TRAX_LAYOUT_WORD(RayResult, triangles_tested, kResultTrianglesTested);
TRAX_LAYOUT_WORD(RayResult, max_stack_depth, kResultMaxStackDepth);
TRAX_LAYOUT_WORD(RayResult, stack_overflows, kResultStackOverflows);
TRAX_LAYOUT_WORD(Camera, eye, kCameraEye);
TRAX_LAYOUT_WORD(Camera, corner, kCameraCorner);
TRAX_LAYOUT_WORD(Camera, right, kCameraRight);
TRAX_LAYOUT_WORD(Camera, down, kCameraDown);
TRAX_LAYOUT_WORD(PointLight, position, kLightPosition);
TRAX_LAYOUT_WORD(PointLight, color, kLightColor);
TRAX_LAYOUT_WORD(Material, diffuse, kMaterialDiffuse);
TRAX_LAYOUT_WORD(Emission, radiance, kEmissionRadiance);
TRAX_LAYOUT_WORD(Emitter, triangle, kEmitterTriangle);
TRAX_LAYOUT_WORD(Emitter, area, kEmitterArea);
TRAX_LAYOUT_WORD(Emitter, probability, kEmitterProbability);
TRAX_LAYOUT_WORD(Emitter, cdf, kEmitterCdf);
TRAX_LAYOUT_WORD(SceneExtras, seed, kExtrasSeed);
TRAX_LAYOUT_WORD(SceneExtras, emission, kExtrasEmission);
TRAX_LAYOUT_WORD(SceneExtras, emitters, kExtrasEmitters);
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
static_assert(sizeof(Emission) == 12 && sizeof(Emitter) == 16 && sizeof(SceneExtras) == 20);
static_assert(sizeof(Triangle) == 40);
static_assert(sizeof(BvhNode) == 32, "the BVH node is one half cache line");
/// 32 words: one cache line pair, and the sections still start at word 32 as they did when the
/// header was 31 words.
static_assert(sizeof(SceneHeader) == 128);
static_assert(sizeof(AccelRecord) == 76);
static_assert(wide_quantized_boxes_byte(4) + 6 * 4 <= 4 * wide_node_words(4, true) &&
              wide_quantized_boxes_byte(8) + 6 * 8 <= 4 * wide_node_words(8, true));
static_assert(sizeof(ThreadStats) == 32 && sizeof(Ray) == 44 && sizeof(RayResult) == 32);

/// Rounds a word address up to the section alignment.
constexpr int32_t align_section(int32_t word) {
    return (word + kSectionAlignWords - 1) / kSectionAlignWords * kSectionAlignWords;
}

/// Word address of the SceneExtras record when the image has one: the first section.
constexpr int32_t kExtrasAddr = align_section(kHeaderWords);

/// THE section placement rule. Given a header whose counts (and image size) are filled in,
/// assigns every section's addr and total_words: sections follow the header in the order
/// [extras], camera, lights, materials, [emission], triangles, [emitters], bvh_nodes, [accel,
/// accel nodes, accel refs], framebuffer, thread_stats, rays, ray_results, each aligned to
/// kSectionAlignWords; empty sections take no space. The bracketed ones exist only with `extras`
/// (its emitters count filled in; the emission count is set to the materials count) or `accel`
/// (its nodes and refs counts filled in, one word per entry; h.accel is set to the record's
/// address); without them the image is laid out as if they did not exist. The framebuffer count
/// is set from the image size, the ray_results count from the rays count. The scene compiler
/// calls this; tests check images against it.
constexpr void place_sections(SceneHeader& h, SceneExtras* extras = nullptr,
                              AccelRecord* accel = nullptr) {
    h.camera.count = 1;
    h.framebuffer.count = h.image_width * h.image_height;
    h.ray_results.count = h.rays.count;
    SectionRef extras_record{0, 0}, no_emission{0, 0}, no_emitters{0, 0};
    SectionRef accel_record{0, 0}, no_accel_nodes{0, 0}, no_accel_refs{0, 0};
    if (extras != nullptr) {
        extras_record.count = 1;
        extras->emission.count = h.materials.count;
    }
    if (accel != nullptr) accel_record.count = 1;
    struct Section {
        SectionRef* ref;
        int32_t record_words;
    };
    const Section order[] = {
        {&extras_record, kExtrasWords},
        {&h.camera, kCameraWords},
        {&h.lights, kPointLightWords},
        {&h.materials, kMaterialWords},
        {extras ? &extras->emission : &no_emission, kEmissionWords},
        {&h.triangles, kTriangleWords},
        {extras ? &extras->emitters : &no_emitters, kEmitterWords},
        {&h.bvh_nodes, kBvhNodeWords},
        {&accel_record, kAccelRecordWords},
        {accel ? &accel->nodes : &no_accel_nodes, 1},
        {accel ? &accel->refs : &no_accel_refs, 1},
        {&h.framebuffer, kPixelWords},
        {&h.thread_stats, kThreadStatsWords},
        {&h.rays, kRayWords},
        {&h.ray_results, kRayResultWords},
    };
    int32_t next = align_section(kHeaderWords);
    for (const Section& s : order) {
        s.ref->addr = next;
        if (s.ref->count > 0) next = align_section(next + s.ref->count * s.record_words);
    }
    h.accel = accel != nullptr ? accel_record.addr : 0;
    h.total_words = next;
}

}  // namespace trax::layout
