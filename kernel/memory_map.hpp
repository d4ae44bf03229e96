// The guest address map, shared by the kernel runtime and the simulator (docs/memory-map.md).
// Byte addresses. Freestanding: no includes beyond <stdint.h>.
#pragma once
#include <stdint.h>

namespace trax::map {

/// [0, kCodeBase) is never mapped: a null-pointer access faults.
constexpr uint32_t kCodeBase = 0x0001'0000;
/// The kernel ELF is linked here: text and rodata read-only, data and bss read-write.
/// Global memory (scene image, then framebuffer) starts here; the scene header is first.
constexpr uint32_t kGlobalBase = 0x1000'0000;
/// Each thread's private local store ends here (the stack grows down from it). Its size is a
/// chip parameter; the window [kLocalTop - size, kLocalTop) is private to every thread.
constexpr uint32_t kLocalTop = 0x8000'0000;
/// Accesses in [kLocalTop - kStackGuard, kLocalTop - size) are reported as stack overflow.
constexpr uint32_t kStackGuard = 0x0100'0000;

}  // namespace trax::map
