#include "sim/core/memory.hpp"

#include <fmt/format.h>

#include "sim/core/error.hpp"
#include "sim/core/fault.hpp"

namespace tpsim::core {
namespace {

using namespace trax::map;

constexpr uint32_t kMinLocalStore = 256;
constexpr uint32_t kMaxLocalStore = 1u << 20;
constexpr uint32_t kMaxGlobal = kLocalTop - kStackGuard - kGlobalBase;

/// calloc leaves untouched pages unbacked, so large local stores cost only what threads use.
template <class Buffer> Buffer zeroed(size_t bytes, const char* what) {
    Buffer buffer(static_cast<uint8_t*>(std::calloc(bytes ? bytes : 1, 1)));
    if (!buffer)
        throw Error(fmt::format("out of host memory allocating {} bytes of {}; reduce the thread "
                                "count or memory sizes",
                                bytes, what));
    return buffer;
}

std::string range(uint32_t base, uint64_t end) {
    return fmt::format("[{:#010x}, {:#010x})", base, end);
}

}  // namespace

void MemoryConfig::validate() const {
    if (local_store_bytes < kMinLocalStore || local_store_bytes > kMaxLocalStore ||
        local_store_bytes % 16 != 0)
        throw Error(fmt::format("local store size {} bytes is invalid: it must be a multiple of 16 "
                                "in [{}, {}] (--local-store)",
                                local_store_bytes, kMinLocalStore, kMaxLocalStore));
    if (global_bytes > kMaxGlobal)
        throw Error(fmt::format("global memory of {} bytes does not fit the address map (max {} "
                                "bytes from {:#010x}); use a smaller scene or framebuffer",
                                global_bytes, kMaxGlobal, kGlobalBase));
    if (threads == 0) throw Error("thread count must be at least 1");
    if (read_only_global_bytes > global_bytes || read_only_global_bytes % 4 != 0)
        throw Error(fmt::format("read-only global memory of {} bytes must be a multiple of 4 and "
                                "at most the {} bytes of global memory",
                                read_only_global_bytes, global_bytes));
}

Memory::Memory(const Program& program, const MemoryConfig& config) {
    config.validate();
    for (const Segment& s : program.segments) {
        Buffer buffer = zeroed<Buffer>(s.memsz, "program segment");
        // A segment may have no file bytes (.bss alone): then bytes.data() may be null.
        if (!s.bytes.empty()) std::memcpy(buffer.get(), s.bytes.data(), s.bytes.size());
        program_regions_.push_back({s.vaddr, s.memsz, buffer.get(), s.writable});
        program_buffers_.push_back(std::move(buffer));
    }
    global_buffer_ = zeroed<Buffer>(config.global_bytes, "global memory");
    global_ = {kGlobalBase, config.global_bytes, global_buffer_.get(), true};
    read_only_global_ = config.read_only_global_bytes;
    local_stores_ =
        zeroed<Buffer>(size_t(config.threads) * config.local_store_bytes, "local stores");
    local_ = {kLocalTop - config.local_store_bytes, config.local_store_bytes, nullptr, true};
}

uint32_t Memory::code_word(uint32_t addr) const {
    for (const Region& r : program_regions_)
        if (r.holds(addr, 4)) {
            uint32_t word;
            std::memcpy(&word, r.data + (addr - r.base), 4);
            return word;
        }
    return 0;
}

GuestFault Memory::classify(uint32_t addr, uint32_t bytes, bool store) const {
    const char* verb = store ? "writes" : "reads";
    const std::string what =
        fmt::format("{} {} byte{} at {:#010x}", verb, bytes, bytes == 1 ? "" : "s", addr);
    if (addr < kCodeBase)
        return GuestFault{
            FaultKind::NullAccess,
            fmt::format("{}, inside the unmapped null guard {}", what, range(0, kCodeBase)),
            "check for a null or uninitialised pointer"};
    if (addr >= kLocalTop - kStackGuard && addr < local_.base)
        return GuestFault{FaultKind::StackOverflow,
                          fmt::format("{}, below the {}-byte local store {}", what, local_.size,
                                      range(local_.base, kLocalTop)),
                          "reduce recursion/locals or enlarge the local store "
                          "(exec --local-store N, render --set tp.local_store_bytes=N)"};

    const Region* region = nullptr;
    if (addr - local_.base < local_.size)
        region = &local_;
    else if (global_.holds(addr, 1))
        region = &global_;
    for (const Region& r : program_regions_)
        if (r.holds(addr, 1)) region = &r;

    if (region && (addr & (bytes - 1)) != 0)
        return GuestFault{FaultKind::Misaligned,
                          fmt::format("{}, which is not {}-byte aligned (TRaX hardware does not "
                                      "support misaligned accesses)",
                                      what, bytes),
                          "align the data (alignas, packed structs) or access it byte by byte"};
    if (region && !region->holds(addr, bytes))
        return GuestFault{FaultKind::Unmapped,
                          fmt::format("{}, running past the end of {}", what,
                                      range(region->base, uint64_t(region->base) + region->size)),
                          "check array bounds and the size of the scene image"};
    if (region == &global_ && store && in_read_only_global(addr))
        return GuestFault{
            FaultKind::WriteToReadOnly,
            fmt::format("{}, inside the read-only scene data {}", what,
                        range(global_.base, uint64_t(global_.base) + read_only_global_)),
            "the scene (header to BVH) is read-only while a kernel runs; write "
            "results to the framebuffer, thread_stats or ray_results sections"};
    if (region && store && !region->writable)
        return GuestFault{FaultKind::WriteToReadOnly,
                          fmt::format("{}, inside the read-only program segment {}", what,
                                      range(region->base, uint64_t(region->base) + region->size)),
                          "code and constants are read-only; write to .data/.bss, the stack or "
                          "global memory"};
    return GuestFault{FaultKind::Unmapped,
                      fmt::format("{}, which no region maps (program {} .. global {} .. local "
                                  "store {})",
                                  what,
                                  program_regions_.empty()
                                      ? std::string("none")
                                      : range(program_regions_.front().base,
                                              uint64_t(program_regions_.back().base) +
                                                  program_regions_.back().size),
                                  range(global_.base, uint64_t(global_.base) + global_.size),
                                  range(local_.base, kLocalTop)),
                      "check pointer arithmetic and array bounds (see docs/memory-map.md)"};
}

void Memory::fault(uint32_t addr, uint32_t bytes, bool store) const {
    GuestFault fault = classify(addr, bytes, store);
    namespace c = isa::cause;
    if (fault.kind == FaultKind::Misaligned)
        fault.mcause = store ? c::kMisalignedStore : c::kMisalignedLoad;
    else
        fault.mcause = store ? c::kStoreAccess : c::kLoadAccess;
    fault.mtval = addr;
    throw fault;
}

}  // namespace tpsim::core
