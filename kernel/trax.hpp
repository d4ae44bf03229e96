// The TRaX kernel API (CS 6958 style): global memory in 32-bit words, atomics, thread ids, scene
// accessors and float helpers. One header, two implementations:
//   __riscv  : inline asm on the simulated RV32IMF machine, no call overhead;
//   otherwise: the "native twin", the same functions over the context tpsim_native_run() sets up,
//              with bounds checks that report a bad access instead of crashing.
// A kernel defines `void trax_main()`; every hardware thread runs it once. docs/kernel-api.md.
#pragma once
#include <stdint.h>

#include "memory_map.hpp"
#include "scene_layout.hpp"

/// The kernel's entry point, written by the student; run once by every thread.
/// extern "C" so the start-up code can call it by its plain name; a definition after this
/// declaration inherits the C linkage.
extern "C" void trax_main();

#if defined(__riscv)

#define TRAX_INLINE inline __attribute__((always_inline))

namespace trax::detail {
/// Global word (addr + offset); the word grid starts at kGlobalBase. Pointer arithmetic rather
/// than integer arithmetic: the compiler then folds constant offsets into the load's immediate
/// and shares one base register between the fields of a record.
template <class T> TRAX_INLINE T* global_word(int addr, int offset) {
    return reinterpret_cast<T*>(map::kGlobalBase) + addr + offset;
}
}  // namespace trax::detail

// The "m" operands tell the compiler exactly which word is touched, so it may fold constant
// offsets into the instruction's immediate and order loads around stores correctly. Loads are
// not volatile: re-reading the same word may be merged, as with any memory read.
TRAX_INLINE float loadf(int addr, int offset = 0) {
    float value;
    const float* p = trax::detail::global_word<const float>(addr, offset);
    asm("flw %0, %1" : "=f"(value) : "m"(*p));
    return value;
}

TRAX_INLINE int loadi(int addr, int offset = 0) {
    int value;
    const int* p = trax::detail::global_word<const int>(addr, offset);
    asm("lw %0, %1" : "=r"(value) : "m"(*p));
    return value;
}

TRAX_INLINE void storef(float value, int addr, int offset = 0) {
    float* p = trax::detail::global_word<float>(addr, offset);
    asm volatile("fsw %1, %0" : "=m"(*p) : "f"(value));
}

TRAX_INLINE void storei(int value, int addr, int offset = 0) {
    int* p = trax::detail::global_word<int>(addr, offset);
    asm volatile("sw %1, %0" : "=m"(*p) : "r"(value));
}

/// Returns the old value of global register `reg` (0..255) and increments it, atomically over
/// all threads. `reg` must be a compile-time constant: it is the instruction's immediate.
TRAX_INLINE int atomicinc(int reg) {
    int old;
    asm volatile(".insn i 0x0b, 0, %0, x0, %1" : "=r"(old) : "i"(reg) : "memory");
    return old;
}

// Thread ids come from CSRs: mhartid (standard) and the read-only custom CSRs 0xCC0..0xCC4.
// Not volatile: they never change while a thread runs, so repeated reads may be merged.
#define TRAX_CSR_FUNCTION(name, csr)                                                               \
    TRAX_INLINE int name() {                                                                       \
        int value;                                                                                 \
        asm("csrr %0, " #csr : "=r"(value));                                                       \
        return value;                                                                              \
    }
TRAX_CSR_FUNCTION(trax_thread_id, mhartid)
TRAX_CSR_FUNCTION(trax_num_threads, 0xCC0)
TRAX_CSR_FUNCTION(trax_tm_id, 0xCC1)
TRAX_CSR_FUNCTION(trax_num_tms, 0xCC2)
TRAX_CSR_FUNCTION(trax_tp_id, 0xCC3)
TRAX_CSR_FUNCTION(trax_tm_size, 0xCC4)
#undef TRAX_CSR_FUNCTION

/// Write `TRAX_USES_BVH;` at file scope in a kernel that traverses the BVH: it defines the marker
/// symbol trax::layout::kUsesBvhSymbol (a one-instruction function the link script keeps), and
/// tpsim then builds the BVH and puts it in the memory image; other kernels get none.
#define TRAX_USES_BVH                                                                              \
    asm(".pushsection .text.trax_uses_bvh, \"ax\", @progbits\n"                                    \
        ".globl trax_uses_bvh\n.type trax_uses_bvh, @function\n"                                   \
        "trax_uses_bvh:\n  ret\n.size trax_uses_bvh, . - trax_uses_bvh\n.popsection")

namespace trax::detail {
/// Leaves the marker trax::layout::kUsesExtrasSymbol in the ELF (once per object file: .ifndef;
/// weak, so objects may share it; kept by the link script). Called by every function that reads
/// the SceneExtras record, so a kernel gets that record exactly when it uses it. No code.
TRAX_INLINE void mark_uses_extras() {
    asm volatile(".ifndef trax_uses_extras\n"
                 ".pushsection .text.trax_uses_extras, \"ax\", @progbits\n"
                 ".weak trax_uses_extras\n.type trax_uses_extras, @function\n"
                 "trax_uses_extras:\n  ret\n.size trax_uses_extras, . - trax_uses_extras\n"
                 ".popsection\n.endif");
}
/// trax_rand()'s state lives in the thread-pointer register tp (x4): private to the thread,
/// 0 at start, never used by compiled code (the kernels have no thread-local variables).
/// Volatile: the compiler does not know that trax_rand() changes it.
TRAX_INLINE uint32_t rand_state() {
    uint32_t state;
    asm volatile("mv %0, tp" : "=r"(state));
    return state;
}
TRAX_INLINE void set_rand_state(uint32_t state) {
    asm volatile("mv tp, %0" : : "r"(state));
}
}  // namespace trax::detail

#else  // the native twin

#include <stdexcept>
#include <string>

#define TRAX_INLINE inline
/// The twin is told about the BVH by the host, which reads the marker from the ELF.
#define TRAX_USES_BVH static_assert(true)

namespace trax::native {

/// What the kernel API sees while the twin runs one thread. Set by tpsim_native_run().
struct ThreadContext {
    uint32_t* words = nullptr;  ///< global memory, word 0 at kGlobalBase
    int64_t word_count = 0;
    int64_t read_only_words = 0;           ///< the scene, words [0, read_only_words): stores fault
    uint32_t* global_registers = nullptr;  ///< kGlobalRegisters of them, all 0 at start
    int thread_id = 0, num_threads = 0, tm_id = 0, num_tms = 0, tp_id = 0, tm_size = 0;
    uint32_t rand_state = 0;  ///< trax_rand()'s state (the guest keeps it in register tp)
};
constexpr int kGlobalRegisters = 256;

/// The thread the twin is running now. One per loaded twin library (hidden visibility);
/// tpsim_native_run() serialises calls so concurrent runs cannot share it.
inline ThreadContext* current = nullptr;

/// A kernel mistake the twin caught; tpsim_native_run() turns it into its error message.
struct KernelFault : std::runtime_error {
    using std::runtime_error::runtime_error;
};

inline uint32_t& word(const char* api, int addr, int offset) {
    const int64_t index = int64_t{addr} + offset;
    if (index < 0 || index >= current->word_count)
        throw KernelFault(std::string(api) + "(addr=" + std::to_string(addr) +
                          ", offset=" + std::to_string(offset) + ") in thread " +
                          std::to_string(current->thread_id) + ": word " + std::to_string(index) +
                          " is outside global memory [0, " + std::to_string(current->word_count) +
                          ") — check the address arithmetic");
    return current->words[index];
}

inline uint32_t& writable_word(const char* api, int addr, int offset) {
    uint32_t& w = word(api, addr, offset);
    const int64_t index = int64_t{addr} + offset;
    if (index < current->read_only_words)
        throw KernelFault(std::string(api) + "(addr=" + std::to_string(addr) +
                          ", offset=" + std::to_string(offset) + ") in thread " +
                          std::to_string(current->thread_id) + ": word " + std::to_string(index) +
                          " is in the read-only scene data [0, " +
                          std::to_string(current->read_only_words) +
                          ") — write results to the framebuffer, thread_stats or ray_results");
    return w;
}

}  // namespace trax::native

inline float loadf(int addr, int offset = 0) {
    return __builtin_bit_cast(float, trax::native::word("loadf", addr, offset));
}
inline int loadi(int addr, int offset = 0) {
    return static_cast<int>(trax::native::word("loadi", addr, offset));
}
inline void storef(float value, int addr, int offset = 0) {
    trax::native::writable_word("storef", addr, offset) = __builtin_bit_cast(uint32_t, value);
}
inline void storei(int value, int addr, int offset = 0) {
    trax::native::writable_word("storei", addr, offset) = static_cast<uint32_t>(value);
}
inline int atomicinc(int reg) {
    using trax::native::current;
    if (reg < 0 || reg >= trax::native::kGlobalRegisters)
        throw trax::native::KernelFault("atomicinc(" + std::to_string(reg) + ") in thread " +
                                        std::to_string(current->thread_id) +
                                        ": global registers are 0..255");
    return static_cast<int>(current->global_registers[reg]++);
}
inline int trax_thread_id() {
    return trax::native::current->thread_id;
}
inline int trax_num_threads() {
    return trax::native::current->num_threads;
}
inline int trax_tm_id() {
    return trax::native::current->tm_id;
}
inline int trax_num_tms() {
    return trax::native::current->num_tms;
}
inline int trax_tp_id() {
    return trax::native::current->tp_id;
}
inline int trax_tm_size() {
    return trax::native::current->tm_size;
}

namespace trax::detail {
inline void mark_uses_extras() {}  // the host reads the marker from the guest ELF
inline uint32_t rand_state() {
    return trax::native::current->rand_state;
}
inline void set_rand_state(uint32_t state) {
    trax::native::current->rand_state = state;
}
}  // namespace trax::detail

#endif

// ---- Both sides from here on: written only in terms of the primitives above. ----------------

// Scene accessors: read the scene header (trax/scene_layout.hpp) at word 0.
TRAX_INLINE int trax_image_width() {
    return loadi(0, trax::layout::kHeaderImageWidth);
}
TRAX_INLINE int trax_image_height() {
    return loadi(0, trax::layout::kHeaderImageHeight);
}
TRAX_INLINE int trax_samples_per_pixel() {
    return loadi(0, trax::layout::kHeaderSamplesPerPixel);
}
TRAX_INLINE int trax_scene_flags() {
    return loadi(0, trax::layout::kHeaderFlags);
}
/// Word address of the ambient (3 floats) and background (3 floats) colours.
TRAX_INLINE int trax_ambient() {
    return trax::layout::kHeaderAmbient;
}
TRAX_INLINE int trax_background() {
    return trax::layout::kHeaderBackground;
}
// Section word addresses and record counts.
TRAX_INLINE int trax_camera() {
    return loadi(0, trax::layout::kHeaderCamera);
}
TRAX_INLINE int trax_lights() {
    return loadi(0, trax::layout::kHeaderLights);
}
TRAX_INLINE int trax_num_lights() {
    return loadi(0, trax::layout::kHeaderLights + 1);
}
TRAX_INLINE int trax_materials() {
    return loadi(0, trax::layout::kHeaderMaterials);
}
TRAX_INLINE int trax_num_materials() {
    return loadi(0, trax::layout::kHeaderMaterials + 1);
}
TRAX_INLINE int trax_triangles() {
    return loadi(0, trax::layout::kHeaderTriangles);
}
TRAX_INLINE int trax_num_triangles() {
    return loadi(0, trax::layout::kHeaderTriangles + 1);
}
TRAX_INLINE int trax_bvh() {
    return loadi(0, trax::layout::kHeaderBvhNodes);
}
TRAX_INLINE int trax_num_bvh_nodes() {
    return loadi(0, trax::layout::kHeaderBvhNodes + 1);
}
TRAX_INLINE int trax_framebuffer() {
    return loadi(0, trax::layout::kHeaderFramebuffer);
}

// Emitters and the run seed: the SceneExtras record (scene_layout.hpp), which tpsim lays out
// for a kernel that calls any of these (they leave a marker in its ELF; docs/kernel-api.md).
/// The run's seed, `tpsim render --seed N` (default 0).
TRAX_INLINE uint32_t trax_run_seed() {
    trax::detail::mark_uses_extras();
    return uint32_t(loadi(trax::layout::kExtrasAddr, trax::layout::kExtrasSeed));
}
/// Word address of the radiance (3 floats, linear RGB) a material emits; 0, 0, 0 for most.
TRAX_INLINE int trax_emission(int material) {
    trax::detail::mark_uses_extras();
    return loadi(trax::layout::kExtrasAddr, trax::layout::kExtrasEmission) +
           material * trax::layout::kEmissionWords;
}
/// Word address of the emitters section: one Emitter (triangle, area, probability, cdf) per
/// emissive triangle, for light sampling.
TRAX_INLINE int trax_emitters() {
    trax::detail::mark_uses_extras();
    return loadi(trax::layout::kExtrasAddr, trax::layout::kExtrasEmitters);
}
TRAX_INLINE int trax_num_emitters() {
    trax::detail::mark_uses_extras();
    return loadi(trax::layout::kExtrasAddr, trax::layout::kExtrasEmitters + 1);
}

// Random numbers: integer operations only, so both sides draw the same bits.
/// A well-mixed 32-bit hash (lowbias32, C. Wellons' hash prospector): for seeds, e.g.
/// trax_srand(trax_hash(trax_hash(pixel, sample), trax_run_seed())).
TRAX_INLINE uint32_t trax_hash(uint32_t x) {
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}
/// Two values hashed into one (order matters).
TRAX_INLINE uint32_t trax_hash(uint32_t a, uint32_t b) {
    return trax_hash(a ^ trax_hash(b));
}
/// Restarts this thread's sequence of trax_rand() numbers; the same seed gives the same numbers.
TRAX_INLINE void trax_srand(uint32_t seed) {
    const uint32_t state = trax_hash(seed);
    trax::detail::set_rand_state(state != 0 ? state : 0x9e3779b9u);  // xorshift's state is never 0
}
/// Uniform float in [0, 1), 24 random bits: Marsaglia's xorshift32 (13, 17, 5), one state per
/// thread. A thread that never called trax_srand() starts from trax_hash(thread id, run seed),
/// so the numbers a pixel gets depend on which thread draws them: seed per pixel (and sample)
/// for an image that does not depend on how atomicinc hands out the work.
TRAX_INLINE float trax_rand() {
    uint32_t x = trax::detail::rand_state();
    if (x == 0) {  // the thread's first draw
        trax_srand(trax_hash(uint32_t(trax_thread_id()), trax_run_seed()));
        x = trax::detail::rand_state();
    }
    x ^= x << 13;
    x ^= x >> 17;
    x ^= x << 5;
    trax::detail::set_rand_state(x);
    return float(x >> 8) * 0x1p-24f;
}

// Float helpers that give the same bits on both sides: IEEE operations only, no libm.
/// Correctly rounded square root: fsqrt.s on the guest, sqrtss on x86-64.
TRAX_INLINE float trax_sqrt(float x) {
    return __builtin_sqrtf(x);
}
TRAX_INLINE float trax_abs(float x) {
    return __builtin_fabsf(x);
}
// Comparisons rather than fmin/fmax: the two ISAs disagree on NaN operands, a compare does not.
TRAX_INLINE float trax_min(float a, float b) {
    return a < b ? a : b;
}
TRAX_INLINE float trax_max(float a, float b) {
    return a > b ? a : b;
}

// Course (simtrax) names, so CS 6958 starter code compiles unchanged where the meaning matches.
TRAX_INLINE int GetXRes() {
    return trax_image_width();
}
TRAX_INLINE int GetYRes() {
    return trax_image_height();
}
TRAX_INLINE int GetFrameBuffer() {
    return trax_framebuffer();
}
TRAX_INLINE int GetCamera() {
    return trax_camera();
}
TRAX_INLINE int GetMaterials() {
    return trax_materials();
}
TRAX_INLINE int GetStartTriangles() {
    return trax_triangles();
}
TRAX_INLINE int GetNumTriangles() {
    return trax_num_triangles();
}
TRAX_INLINE int GetLight() {
    return trax_lights();
}
TRAX_INLINE int GetNumLights() {
    return trax_num_lights();
}
TRAX_INLINE int GetBVH() {
    return trax_bvh();
}
TRAX_INLINE float min(float a, float b) {
    return trax_min(a, b);
}
TRAX_INLINE float max(float a, float b) {
    return trax_max(a, b);
}
TRAX_INLINE float invsqrt(float x) {
    return 1.0f / trax_sqrt(x);
}

#undef TRAX_INLINE
