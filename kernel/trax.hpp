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

/// The byte at byte offset `byte` (0..) from word address `addr`, zero-extended: one lbu, for
/// packed records such as the quantized wide-BVH node (scene_layout.hpp). Bytes are little-endian
/// within a word.
TRAX_INLINE uint32_t loadbyte(int addr, int byte) {
    uint32_t value;
    const uint8_t* p =
        reinterpret_cast<const uint8_t*>(trax::detail::global_word<const uint32_t>(addr, 0)) + byte;
    asm("lbu %0, %1" : "=r"(value) : "m"(*p));
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

/// Waits until every thread that has not exited has called trax_barrier() (the tp.barrier
/// instruction): memory written before it by any thread is seen after it by every thread.
TRAX_INLINE void trax_barrier() {
    asm volatile(".insn i 0x0b, 2, x0, x0, 0" ::: "memory");
}

/// Acquires the binary semaphore in global register `reg` (0..255, a compile-time constant),
/// waiting while another thread holds it; waiters get it in the order they asked.
TRAX_INLINE void trax_semacquire(int reg) {
    asm volatile(".insn i 0x0b, 3, x0, x0, %0" ::"i"(reg) : "memory");
}

/// Releases the semaphore in global register `reg`, which the thread acquired.
TRAX_INLINE void trax_semrelease(int reg) {
    asm volatile(".insn i 0x0b, 4, x0, x0, %0" ::"i"(reg) : "memory");
}

namespace trax::detail {
/// Appends `length` bytes to the thread's output (the tp.print instruction).
TRAX_INLINE void print_bytes(const char* bytes, int length) {
    asm volatile(".insn r 0x0b, 1, 0, x0, %0, %1" ::"r"(bytes), "r"(length) : "memory");
}
}  // namespace trax::detail

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

/// Write `TRAX_USES_GRID;` at file scope in a kernel that traverses the uniform grid (kernel/
/// grid.hpp): tpsim then builds the grid instead of a BVH (trax::layout::kUsesGridSymbol).
#define TRAX_USES_GRID                                                                             \
    asm(".pushsection .text.trax_uses_grid, \"ax\", @progbits\n"                                   \
        ".globl trax_uses_grid\n.type trax_uses_grid, @function\n"                                 \
        "trax_uses_grid:\n  ret\n.size trax_uses_grid, . - trax_uses_grid\n.popsection")

/// Write `TRAX_USES_WIDE_BVH;` at file scope in a kernel that traverses a wide BVH (kernel/
/// wide_bvh.hpp): tpsim then builds the 4- or 8-wide BVH that render --accel names
/// (trax::layout::kUsesWideBvhSymbol).
#define TRAX_USES_WIDE_BVH                                                                         \
    asm(".pushsection .text.trax_uses_wide_bvh, \"ax\", @progbits\n"                               \
        ".globl trax_uses_wide_bvh\n.type trax_uses_wide_bvh, @function\n"                         \
        "trax_uses_wide_bvh:\n  ret\n.size trax_uses_wide_bvh, . - "                               \
        "trax_uses_wide_bvh\n.popsection")

/// Write `TRAX_USES_KDTREE;` at file scope in a kernel that traverses the kd-tree (kernel/
/// kdtree.hpp): tpsim then builds the kd-tree (trax::layout::kUsesKdTreeSymbol).
#define TRAX_USES_KDTREE                                                                           \
    asm(".pushsection .text.trax_uses_kdtree, \"ax\", @progbits\n"                                 \
        ".globl trax_uses_kdtree\n.type trax_uses_kdtree, @function\n"                             \
        "trax_uses_kdtree:\n  ret\n.size trax_uses_kdtree, . - trax_uses_kdtree\n.popsection")

/// Write `TRAX_USES_BSP;` at file scope in a kernel that traverses the BSP tree (kernel/
/// kdtree.hpp's BspTraversal): tpsim then builds the BSP tree (trax::layout::kUsesBspSymbol).
/// `TRAX_USES_OCTREE;` does the same for the octree (kernel/octree.hpp). in a kernel that traverses
/// the octree (kernel/ octree.hpp): tpsim then builds the octree (trax::layout::kUsesOctreeSymbol).
#define TRAX_USES_BSP                                                                              \
    asm(".pushsection .text.trax_uses_bsp, \"ax\", @progbits\n"                                    \
        ".globl trax_uses_bsp\n.type trax_uses_bsp, @function\n"                                   \
        "trax_uses_bsp:\n  ret\n.size trax_uses_bsp, . - trax_uses_bsp\n.popsection")

#define TRAX_USES_OCTREE                                                                           \
    asm(".pushsection .text.trax_uses_octree, \"ax\", @progbits\n"                                 \
        ".globl trax_uses_octree\n.type trax_uses_octree, @function\n"                             \
        "trax_uses_octree:\n  ret\n.size trax_uses_octree, . - trax_uses_octree\n.popsection")

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
/// The twin is told about the BVH or grid by the host, which reads the marker from the ELF.
#define TRAX_USES_BVH static_assert(true)
#define TRAX_USES_GRID static_assert(true)
#define TRAX_USES_WIDE_BVH static_assert(true)
#define TRAX_USES_KDTREE static_assert(true)
#define TRAX_USES_OCTREE static_assert(true)
#define TRAX_USES_BSP static_assert(true)

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

// Defined by the twin's driver (kernel/runtime/native_twin.cpp), which runs the threads.
void print_bytes(const char* bytes, int length);
void barrier();
void sem_acquire(int reg);
void sem_release(int reg);

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
inline uint32_t loadbyte(int addr, int byte) {
    return trax::native::word("loadbyte", addr, byte >> 2) >> ((byte & 3) * 8) & 255u;
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
inline void trax_barrier() {
    trax::native::barrier();
}
inline void trax_semacquire(int reg) {
    trax::native::sem_acquire(reg);
}
inline void trax_semrelease(int reg) {
    trax::native::sem_release(reg);
}
namespace trax::detail {
inline void print_bytes(const char* bytes, int length) {
    trax::native::print_bytes(bytes, length);
}
}  // namespace trax::detail
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

// Run-time parameters (docs/kernel-api.md, "Run-time parameters").
namespace trax::detail {
/// Whether TRAX_PARAM's type is spelt as tpsim reads it back from the symbol's name.
constexpr bool is_param_type(const char* type) {
    const auto same = [](const char* a, const char* b) {
        while (*a != '\0' && *a == *b) {
            ++a;
            ++b;
        }
        return *a == *b;
    };
    return same(type, "float") || same(type, "int");
}
}  // namespace trax::detail

/// A run-time parameter: `TRAX_PARAM(float, threshold, 0.05f);` at file scope, outside any
/// namespace, declares `threshold`, read like a const variable: 0.05f unless the run sets it
/// (`tpsim render --param threshold=0.02`). The type is float or int. The value is the global
/// `trax_param_<type>_<name>` in the kernel's .data, which tpsim finds in the ELF's symbol table
/// (the simulator) or with dlsym (the native twin) and writes before any thread starts, so every
/// engine runs with the same value. Kept by the link script even when unused.
#define TRAX_PARAM(type, name, default_value)                                                      \
    static_assert(trax::detail::is_param_type(#type),                                              \
                  "TRAX_PARAM: the type must be float or int");                                    \
    extern "C" {                                                                                   \
    __attribute__((used, visibility("default"), section(".data.trax_params")))                     \
    type trax_param_##type##_##name = default_value;                                               \
    }                                                                                              \
    [[maybe_unused]] static const type& name = trax_param_##type##_##name

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

// ---- Printing: trax_printf formats in kernel code, the same on both sides (no libc, no
// doubles: a variadic template takes every argument at its own type, so a float stays a float),
// and hands the text to the thread's output in pieces. ----------------------------------------

namespace trax::detail {

/// One trax_printf argument, at the type it was given.
struct PrintArg {
    enum class Kind : uint8_t { None, Int, Unsigned, Float, Char, String };
    Kind kind = Kind::None;
    union {
        int32_t i;
        uint32_t u;
        float f;
        const char* s;
    };
    PrintArg() : u(0) {}
};

inline PrintArg print_arg_of(PrintArg::Kind kind, uint32_t bits) {
    PrintArg a;
    a.kind = kind;
    a.u = bits;
    return a;
}
// Overloads rather than a template, so that bool, short and the like promote as in C.
inline PrintArg print_arg(int v) {
    return print_arg_of(PrintArg::Kind::Int, uint32_t(v));
}
inline PrintArg print_arg(long v) {  // 32 bits on the guest; the twin prints the same bits
    return print_arg_of(PrintArg::Kind::Int, uint32_t(v));
}
inline PrintArg print_arg(unsigned v) {
    return print_arg_of(PrintArg::Kind::Unsigned, v);
}
inline PrintArg print_arg(unsigned long v) {
    return print_arg_of(PrintArg::Kind::Unsigned, uint32_t(v));
}
inline PrintArg print_arg(char v) {
    return print_arg_of(PrintArg::Kind::Char, uint8_t(v));
}
inline PrintArg print_arg(bool v) {
    return print_arg_of(PrintArg::Kind::Int, v);
}
inline PrintArg print_arg(float v) {
    PrintArg a;
    a.kind = PrintArg::Kind::Float;
    a.f = v;
    return a;
}
inline PrintArg print_arg(const char* v) {
    PrintArg a;
    a.kind = PrintArg::Kind::String;
    a.s = v;
    return a;
}
/// Chosen for a double (an exact match beats double -> float): stops the build with a reason.
template <class D = double> PrintArg print_arg(double v) {
    static_assert(sizeof(D) == 0, "trax_printf: a double argument: TRaX has no double-precision "
                                  "unit; print a float (write 0.5f, not 0.5)");
    return print_arg(float(v));
}

/// Collects formatted text and hands it over in pieces of kPiece bytes.
struct PrintSink {
    static constexpr int kPiece = 96;  // local-store bytes on the stack while printing
    char text[kPiece];
    int used = 0;
    void put(char c) {
        if (used == kPiece) flush();
        text[used++] = c;
    }
    void put(const char* s, int n) {
        for (int i = 0; i < n; ++i)
            put(s[i]);
    }
    void flush() {
        if (used != 0) print_bytes(text, used);
        used = 0;
    }
};

/// A number of up to 144 bits in 16-bit limbs (least significant first), so that all its
/// arithmetic fits 32-bit operations: the guest has no 64-bit division.
struct WideNumber {
    static constexpr int kLimbs = 9;
    uint32_t limb[kLimbs] = {};

    void multiply(uint32_t factor) {  // factor < 2^16
        uint32_t carry = 0;
        for (uint32_t& l : limb) {
            const uint32_t v = l * factor + carry;
            l = v & 0xffff;
            carry = v >> 16;
        }
    }
    uint32_t divide(uint32_t divisor) {  // returns the remainder; divisor < 2^16
        uint32_t rest = 0;
        for (int k = kLimbs - 1; k >= 0; --k) {
            const uint32_t v = rest << 16 | limb[k];
            limb[k] = v / divisor;
            rest = v % divisor;
        }
        return rest;
    }
    bool bit(int i) const { return i < 16 * kLimbs && (limb[i >> 4] >> (i & 15) & 1) != 0; }
    bool any_below(int i) const {  // any bit below bit i set?
        for (int k = 0; k < kLimbs && 16 * k < i; ++k) {
            const int bits = i - 16 * k;
            const uint32_t mask = bits >= 16 ? 0xffff : (1u << bits) - 1;
            if ((limb[k] & mask) != 0) return true;
        }
        return false;
    }
    void shift_right(int s) {
        for (int k = 0; k < kLimbs; ++k) {
            const int from = k * 16 + s;
            uint32_t v = 0;
            if ((from >> 4) < kLimbs) v = limb[from >> 4] >> (from & 15);
            if ((from >> 4) + 1 < kLimbs && (from & 15) != 0)
                v |= limb[(from >> 4) + 1] << (16 - (from & 15));
            limb[k] = v & 0xffff;
        }
    }
    void shift_left(int s) {
        for (int k = kLimbs - 1; k >= 0; --k) {
            const int from = k * 16 - s;  // bit of the old number that lands on limb k's bit 0
            uint32_t v = 0;
            if (from >= 0) {
                v = limb[from >> 4] >> (from & 15);
                if ((from & 15) != 0 && (from >> 4) + 1 < kLimbs)
                    v |= limb[(from >> 4) + 1] << (16 - (from & 15));
            } else if (from > -16) {
                v = limb[0] << -from;
            }
            limb[k] = v & 0xffff;
        }
    }
    void increment() {
        for (uint32_t& l : limb) {
            l = (l + 1) & 0xffff;
            if (l != 0) return;
        }
    }
    bool is_odd() const { return (limb[0] & 1) != 0; }
    /// Decimal digits, most significant first, into out (at least 45 bytes); returns the count.
    int digits(char* out) {
        char reversed[48];
        int n = 0;
        do {
            reversed[n++] = char('0' + divide(10));
        } while (!is_zero());
        for (int i = 0; i < n; ++i)
            out[i] = reversed[n - 1 - i];
        return n;
    }
    bool is_zero() const {
        for (uint32_t l : limb)
            if (l != 0) return false;
        return true;
    }
};

/// The most digits %.Nf prints after the point.
constexpr int kMaxFloatPrecision = 20;

/// |x| with `precision` decimals, correctly rounded (ties to even, as C's printf does), into out
/// (at least 70 bytes); returns the length. x is finite.
inline int fixed_digits(float x, int precision, char* out) {
    const uint32_t bits = __builtin_bit_cast(uint32_t, x);
    const uint32_t exponent = bits >> 23 & 0xff;
    const uint32_t fraction = bits & 0x7fffff;
    // |x| = m * 2^e exactly.
    const uint32_t m = exponent == 0 ? fraction : fraction | 0x800000;
    const int e = exponent == 0 ? -149 : int(exponent) - 150;
    WideNumber n;
    n.limb[0] = m & 0xffff;
    n.limb[1] = m >> 16;
    if (e >= 0) {
        n.shift_left(e);
    } else {
        // round(m * 10^precision / 2^-e), then the point goes before the last `precision` digits.
        for (int i = 0; i < precision; ++i)
            n.multiply(10);
        const int s = -e;
        const bool half = n.bit(s - 1);
        const bool below_half = n.any_below(s - 1);
        n.shift_right(s);
        if (half && (below_half || n.is_odd())) n.increment();
    }
    char whole[48];
    int count = n.digits(whole);
    int length = 0;
    const int point = e >= 0 ? count : count - precision;  // digits before the point
    if (point <= 0) {                                      // 0.00ddd
        out[length++] = '0';
        if (precision > 0) out[length++] = '.';
        for (int i = point; i < 0; ++i)
            out[length++] = '0';
        for (int i = 0; i < count; ++i)
            out[length++] = whole[i];
        return length;
    }
    for (int i = 0; i < point; ++i)
        out[length++] = whole[i];
    if (precision > 0) out[length++] = '.';
    for (int i = point; i < count; ++i)
        out[length++] = whole[i];
    for (int i = 0; e >= 0 && i < precision; ++i)
        out[length++] = '0';
    return length;
}

/// One conversion's flags, width and precision (-1: none given).
struct PrintSpec {
    bool left = false, zero = false, plus = false;
    int width = 0, precision = -1;
};

inline void put_padded(PrintSink& sink, const PrintSpec& spec, const char* sign, const char* body,
                       int length) {
    int sign_length = 0;
    while (sign[sign_length] != '\0')
        ++sign_length;
    const int pad = spec.width > sign_length + length ? spec.width - sign_length - length : 0;
    if (!spec.left && !spec.zero)
        for (int i = 0; i < pad; ++i)
            sink.put(' ');
    sink.put(sign, sign_length);
    if (!spec.left && spec.zero)
        for (int i = 0; i < pad; ++i)
            sink.put('0');
    sink.put(body, length);
    if (spec.left)
        for (int i = 0; i < pad; ++i)
            sink.put(' ');
}

inline const char* kind_name(PrintArg::Kind kind) {
    switch (kind) {
    case PrintArg::Kind::Int:
        return "int";
    case PrintArg::Kind::Unsigned:
        return "unsigned";
    case PrintArg::Kind::Float:
        return "float";
    case PrintArg::Kind::Char:
        return "char";
    case PrintArg::Kind::String:
        return "string";
    case PrintArg::Kind::None:
        break;
    }
    return "missing";
}

/// Formats `format` with args[0..count) into the thread's output. Out of line on the guest:
/// one copy serves every call site (instruction-cache space).
#if defined(__riscv)
__attribute__((noinline))
#endif
inline void
print_formatted(const char* format, const PrintArg* args, int count) {
    PrintSink sink;
    int next = 0;
    for (const char* p = format; *p != '\0'; ++p) {
        if (*p != '%') {
            sink.put(*p);
            continue;
        }
        PrintSpec spec;
        for (++p;; ++p) {
            if (*p == '-')
                spec.left = true;
            else if (*p == '0')
                spec.zero = true;
            else if (*p == '+')
                spec.plus = true;
            else
                break;
        }
        for (; *p >= '0' && *p <= '9'; ++p)
            spec.width = spec.width * 10 + (*p - '0');
        if (*p == '.') {
            spec.precision = 0;
            for (++p; *p >= '0' && *p <= '9'; ++p)
                spec.precision = spec.precision * 10 + (*p - '0');
        }
        while (*p == 'l' || *p == 'h' || *p == 'z')
            ++p;
        const char conversion = *p;
        if (conversion == '\0') break;
        if (conversion == '%') {
            sink.put('%');
            continue;
        }
        const PrintArg arg = next < count ? args[next] : PrintArg();
        ++next;
        using Kind = PrintArg::Kind;
        const bool integer =
            arg.kind == Kind::Int || arg.kind == Kind::Unsigned || arg.kind == Kind::Char;
        char body[72];
        int length = 0;
        const char* sign = "";
        bool fits = true;
        switch (conversion) {
        case 'd':
        case 'i':
        case 'u':
        case 'x':
        case 'X': {
            fits = integer;
            if (!fits) break;
            uint32_t value = arg.u;
            if ((conversion == 'd' || conversion == 'i') && arg.kind != Kind::Unsigned) {
                if (arg.i < 0) {
                    sign = "-";
                    value = 0u - arg.u;
                } else if (spec.plus) {
                    sign = "+";
                }
            }
            const uint32_t base = conversion == 'x' || conversion == 'X' ? 16 : 10;
            const char* numerals = conversion == 'X' ? "0123456789ABCDEF" : "0123456789abcdef";
            char reversed[40];
            int n = 0;
            do {
                reversed[n++] = numerals[value % base];
                value /= base;
            } while (value != 0);
            while (n < spec.precision && n < 40)  // the precision is the least digits
                reversed[n++] = '0';
            for (int i = 0; i < n; ++i)
                body[length++] = reversed[n - 1 - i];
            break;
        }
        case 'c':
            fits = integer;
            if (fits) body[length++] = char(arg.u);
            spec.zero = false;
            break;
        case 's':
            fits = arg.kind == Kind::String;
            if (!fits) break;
            {
                const char* text = arg.s != nullptr ? arg.s : "(null)";
                int n = 0;
                while (text[n] != '\0' && (spec.precision < 0 || n < spec.precision))
                    ++n;
                spec.zero = false;
                put_padded(sink, spec, "", text, n);
                continue;
            }
        case 'f':
        case 'F': {
            fits = arg.kind == Kind::Float;
            if (!fits) break;
            const uint32_t bits = __builtin_bit_cast(uint32_t, arg.f);
            if (bits >> 31)
                sign = "-";
            else if (spec.plus)
                sign = "+";
            const int precision = spec.precision < 0                    ? 6
                                  : spec.precision > kMaxFloatPrecision ? kMaxFloatPrecision
                                                                        : spec.precision;
            if ((bits >> 23 & 0xff) == 0xff) {
                const char* special = (bits & 0x7fffff) != 0 ? "nan" : "inf";
                for (int i = 0; i < 3; ++i)
                    body[length++] = special[i];
                spec.zero = false;
            } else {
                length = fixed_digits(arg.f, precision, body);
            }
            break;
        }
        default:
            fits = false;
            break;
        }
        if (fits) {
            put_padded(sink, spec, sign, body, length);
            continue;
        }
        // A conversion its argument does not fit (or none tpsim knows): say so in the output.
        const bool known = conversion == 'd' || conversion == 'i' || conversion == 'u' ||
                           conversion == 'x' || conversion == 'X' || conversion == 'c' ||
                           conversion == 's' || conversion == 'f' || conversion == 'F';
        const char* what = known ? kind_name(arg.kind) : "unsupported";
        if (!known) --next;  // an unknown conversion takes no argument
        sink.put("%!", 2);
        sink.put(conversion);
        sink.put('(');
        for (; *what != '\0'; ++what)
            sink.put(*what);
        sink.put(')');
    }
    sink.flush();
}

}  // namespace trax::detail

/// printf for kernels: %d %i %u %x %X %c %s %f (and %%), with the flags - 0 +, a width and a
/// precision (%.3f; at most 20 decimals). Each argument is printed at its own type; one a
/// conversion does not fit shows as %!d(float). The text goes to the thread's output, which
/// tpsim prints after the run, each line tagged with its thread ([thread 5] ...).
template <class... Args> TRAX_INLINE void trax_printf(const char* format, const Args&... args) {
    const trax::detail::PrintArg list[] = {trax::detail::print_arg(args)..., {}};
    trax::detail::print_formatted(format, list, int(sizeof...(Args)));
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
/// simtrax's debug prints: the value and a newline.
TRAX_INLINE void trax_printi(int value) {
    trax_printf("%d\n", value);
}
TRAX_INLINE void trax_printf(float value) {
    trax_printf("%f\n", value);
}
// simtrax's printf. The twin sees the C library's printf (the standard headers declare it),
// which would win over a template for a plain string; there a macro makes printf(...) the
// kernel's.
#if defined(__riscv)
template <class... Args> TRAX_INLINE int printf(const char* format, const Args&... args) {
    trax_printf(format, args...);
    return 0;
}
#else
#define printf(...) (trax_printf(__VA_ARGS__), 0)
#endif
/// simtrax's barrier over a global register: tpsim has one barrier for all threads, so the
/// register is not needed (and not touched).
TRAX_INLINE void barrier(int reg = 5) {
    (void)reg;
    trax_barrier();
}
TRAX_INLINE void trax_semacq(int reg) {
    trax_semacquire(reg);
}
TRAX_INLINE void trax_semrel(int reg) {
    trax_semrelease(reg);
}

#undef TRAX_INLINE
