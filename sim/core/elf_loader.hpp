// Loads a kernel ELF (RV32, little-endian, statically linked) into a self-contained Program.
#pragma once
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace tpsim::core {

/// One PT_LOAD segment: `bytes` holds the file contents (p_filesz); the rest of memsz is zero.
struct Segment {
    uint32_t vaddr = 0;
    uint32_t memsz = 0;
    std::vector<uint8_t> bytes;
    bool readable = false, writable = false, executable = false;

    uint32_t end() const { return vaddr + memsz; }
    bool contains(uint32_t addr) const { return addr - vaddr < memsz; }
};

/// A function (or code label) from the symbol table, for pc -> name lookups.
struct Symbol {
    std::string name;
    uint32_t address = 0;
    uint32_t size = 0;  ///< 0 when the symbol carries no size (plain assembly labels)
};

struct SourceLocation {
    std::string file;  ///< file name as recorded by the compiler (no directory), for messages
    uint32_t line = 0;
    /// The full path DWARF gives (DW_AT_comp_dir, the line table's directory and the file
    /// name), for reading the source; it need not exist on this machine.
    std::string path;
};

/// Everything the simulator needs from the ELF; no libelf handles are kept.
class Program {
public:
    std::string name;  ///< path or label, for messages
    uint32_t entry = 0;
    std::vector<Segment> segments;  ///< sorted by vaddr, non-overlapping
    std::vector<Symbol> functions;  ///< sorted by address
    std::vector<Symbol> objects;    ///< data objects in writable segments, sorted by address

    /// The function containing pc, or the nearest preceding unsized label; nullptr if none.
    const Symbol* function_at(uint32_t pc) const;
    /// "name+0x40" or "" when pc lies in no known function.
    std::string describe_pc(uint32_t pc) const;
    /// The source line of pc from DWARF .debug_line, when the ELF was built with -g.
    std::optional<SourceLocation> source_at(uint32_t pc) const;
    /// Where the inlined functions around pc were called from, innermost first (e.g. the
    /// kernel line that called storef() when pc is in storef's inlined body); empty if pc is in
    /// no inlined code or the ELF has no DWARF.
    std::vector<SourceLocation> inlined_call_sites(uint32_t pc) const;
    /// The function whose source holds source_at(pc): the innermost function inlined at pc,
    /// else the symbol's (both demangled); "" when DWARF or the symbol table names none.
    std::string source_function_at(uint32_t pc) const;
    /// The segment holding addr, or nullptr.
    const Segment* segment_at(uint32_t addr) const;

    /// A function's stack frame, from the .stack_sizes section clang writes with
    /// -fstack-size-section (every kernel has it; stack_bound.hpp uses it).
    struct FrameSize {
        uint32_t address;  ///< the function's first instruction
        uint32_t bytes;    ///< its frame: how far it moves sp down
    };
    std::vector<FrameSize> frame_sizes;  ///< in section order; empty without the section

    /// Loader-internal: one row of the DWARF line table (sorted by address).
    struct LineRow {
        uint32_t address;
        uint32_t line;
        uint32_t file;  ///< index into line_files
        bool end_sequence;
    };
    std::vector<LineRow> line_rows;
    struct SourceFile {
        std::string file, path;  ///< as in SourceLocation
    };
    std::vector<SourceFile> line_files;
    /// Loader-internal: one address range of an inlined call (DW_TAG_inlined_subroutine).
    struct InlinedCall {
        uint32_t low, high;  ///< [low, high)
        uint32_t depth;      ///< nesting depth in the DIE tree: larger = more inner
        SourceLocation call_site;
        std::string function;  ///< the inlined function, demangled ("" if DWARF names none)
    };
    std::vector<InlinedCall> inlined_calls;
};

/// A C++ symbol as the student wrote it ("(anonymous namespace)::depth(int)"), or the name
/// itself when it is not a mangled C++ name.
std::string demangle(const std::string& name);

/// The largest kernel ELF file tpsim reads (program and debug information): the program itself
/// must fit in the 256 MiB below global memory (docs/memory-map.md); a -g kernel is about 1 MiB.
constexpr uint64_t kMaxElfBytes = uint64_t(64) << 20;

/// Reads (through read_input_file: regular files of at most kMaxElfBytes) and validates an ELF
/// file. Throws tpsim::Error (one line naming the file, the problem
/// and the fix) for anything tpsim cannot run.
Program load_elf(const std::string& path);

/// Same, from bytes already in memory; `name` is used in messages.
Program load_elf(std::span<const uint8_t> image, const std::string& name);

}  // namespace tpsim::core
