// Guest memory: the documented address map (docs/memory-map.md) over flat host buffers.
#pragma once
#include <bit>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <span>
#include <vector>

#include "kernel/memory_map.hpp"
#include "sim/core/elf_loader.hpp"
#include "sim/core/fault.hpp"

namespace tpsim::core {

struct MemoryConfig {
    /// Bytes of global memory at kGlobalBase (scene image + framebuffer).
    uint32_t global_bytes = 0;
    /// The first this many bytes of global memory are read-only (the scene a render loads;
    /// stores there fault). At most global_bytes, a multiple of 4.
    uint32_t read_only_global_bytes = 0;
    /// Bytes of each thread's private local store ending at kLocalTop (holds the stack).
    /// A multiple of 16 in [256, 1 MiB].
    uint32_t local_store_bytes = 4096;
    /// Number of threads, each with its own local store.
    uint32_t threads = 1;

    /// Throws tpsim::Error naming the bad field and its allowed range.
    void validate() const;
};

/// The machine's memory. Loads and stores take the calling thread's local store; the fast path
/// is an alignment test, one or two range compares and a memcpy. Anything else is classified
/// by a cold path that throws GuestFault.
class Memory {
public:
    Memory(const Program& program, const MemoryConfig& config);

    /// Global memory, for the host to write the scene image and read the framebuffer.
    std::span<uint8_t> global() { return {global_.data, global_.size}; }
    std::span<const uint8_t> global() const { return {global_.data, global_.size}; }
    /// Thread t's local store; byte 0 is at address local_base().
    std::span<uint8_t> local_store(uint32_t thread) {
        return {local_stores_.get() + size_t(thread) * local_.size, local_.size};
    }
    uint32_t local_base() const { return local_.base; }
    /// True if `addr` is in the read-only part of global memory.
    bool in_read_only_global(uint32_t addr) const {
        return addr - global_.base < read_only_global_;
    }
    /// True if no store can change `addr`: the read-only part of global memory or a read-only
    /// segment of the program (its code and constants).
    bool in_read_only(uint32_t addr) const {
        if (in_read_only_global(addr)) return true;
        for (const Region& r : program_regions_)
            if (!r.writable && addr - r.base < r.size) return true;
        return false;
    }
    uint32_t local_store_bytes() const { return local_.size; }

    template <class T> T load(uint32_t addr, uint8_t* local) const {
        T value;
        std::memcpy(&value, locate(addr, sizeof(T), local, /*store=*/false), sizeof(T));
        return value;
    }

    template <class T> void store(uint32_t addr, T value, uint8_t* local) {
        std::memcpy(locate(addr, sizeof(T), local, /*store=*/true), &value, sizeof(T));
    }
    /// Throws the GuestFault a store of `bytes` at `addr` would, without storing.
    void check_store(uint32_t addr, uint32_t bytes, uint8_t* local) const {
        locate(addr, bytes, local, /*store=*/true);
    }
    /// Stores the low `bytes` bytes of `value` at `addr`, outside every local store (a held
    /// store, checked when it executed).
    void write(uint32_t addr, uint32_t bytes, uint32_t value) {
        static_assert(std::endian::native == std::endian::little, "low bytes first");
        std::memcpy(locate(addr, bytes, nullptr, /*store=*/true), &value, bytes);
    }

    /// Reads an instruction word of the program (for disassembly in messages); 0 if unmapped.
    uint32_t code_word(uint32_t addr) const;

private:
    struct Region {
        uint32_t base = 0;
        uint32_t size = 0;
        uint8_t* data = nullptr;
        bool writable = false;

        bool holds(uint32_t addr, uint32_t bytes) const {
            const uint32_t offset = addr - base;
            return offset < size && size - offset >= bytes;
        }
    };
    struct FreeDeleter {
        void operator()(uint8_t* p) const { std::free(p); }
    };
    using Buffer = std::unique_ptr<uint8_t[], FreeDeleter>;

    uint8_t* locate(uint32_t addr, uint32_t bytes, uint8_t* local, bool store) const {
        if ((addr & (bytes - 1)) == 0) {
            // Aligned accesses never straddle the local store: its base and size are multiples
            // of 16.
            if (addr - local_.base < local_.size) return local + (addr - local_.base);
            if (global_.holds(addr, bytes) && !(store && in_read_only_global(addr)))
                return global_.data + (addr - global_.base);
            for (const Region& r : program_regions_)
                if (r.holds(addr, bytes) && (r.writable || !store)) return r.data + (addr - r.base);
        }
        fault(addr, bytes, store);
    }

    /// Throws the GuestFault of a failed access, with the exception a trap handler may take.
    [[noreturn]] void fault(uint32_t addr, uint32_t bytes, bool store) const;
    GuestFault classify(uint32_t addr, uint32_t bytes, bool store) const;

    std::vector<Buffer> program_buffers_;
    std::vector<Region> program_regions_;  ///< ELF segments, by address
    Buffer global_buffer_;
    Region global_;
    uint32_t read_only_global_ = 0;  ///< bytes at the start of global_
    Buffer local_stores_;            ///< threads x local_.size bytes, zeroed lazily by calloc
    Region local_;                   ///< the window; data is per thread
};

}  // namespace tpsim::core
