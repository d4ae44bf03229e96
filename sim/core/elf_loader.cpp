#include "sim/core/elf_loader.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iterator>
#include <map>
#include <memory>

#include <cxxabi.h>
#include <dwarf.h>
#include <elf.h>
#include <elfutils/libdw.h>
#include <fmt/format.h>
#include <gelf.h>
#include <libelf.h>

#include "kernel/memory_map.hpp"
#include "sim/core/error.hpp"
#include "sim/core/input_file.hpp"

namespace tpsim::core {

std::string demangle(const std::string& name) {
    int status = 0;
    const std::unique_ptr<char, void (*)(void*)> plain(
        abi::__cxa_demangle(name.c_str(), nullptr, nullptr, &status), std::free);
    return status == 0 && plain ? std::string(plain.get()) : name;
}

namespace {

constexpr const char* kBuildHint =
    "build it with clang --target=riscv32-unknown-elf -march=rv32imf -mabi=ilp32f";

[[noreturn]] void reject(const std::string& name, const std::string& problem) {
    throw Error(fmt::format("cannot load '{}': {}", name, problem));
}

struct ElfCloser {
    void operator()(Elf* e) const { elf_end(e); }
};
using ElfHandle = std::unique_ptr<Elf, ElfCloser>;

std::string machine_name(uint16_t machine) {
    switch (machine) {
    case EM_386:
        return "x86 (3)";
    case EM_X86_64:
        return "x86-64 (62)";
    case EM_ARM:
        return "ARM (40)";
    case EM_AARCH64:
        return "AArch64 (183)";
    case EM_MIPS:
        return "MIPS (8)";
    default:
        return std::to_string(machine);
    }
}

/// Header checks done on raw bytes first, so a hostile or truncated file never reaches libelf
/// with offsets pointing outside the buffer. The machine is checked before the class: e_machine
/// sits at the same offset in ELF32 and ELF64, and "x86-64, not RISC-V" is the better message.
void check_identity(std::span<const uint8_t> image, const std::string& name) {
    if (image.size() < SELFMAG || std::memcmp(image.data(), ELFMAG, SELFMAG) != 0)
        reject(name, "not an ELF file (bad magic number); " + std::string(kBuildHint));
    constexpr size_t kMachineEnd = offsetof(Elf32_Ehdr, e_machine) + 2;
    if (image.size() < kMachineEnd)
        reject(name, "truncated ELF identification; the file is damaged, rebuild it");
    if (image[EI_DATA] != ELFDATA2LSB)
        reject(name, "big-endian ELF, tpsim runs little-endian RISC-V; " + std::string(kBuildHint));
    const uint16_t machine = uint16_t(image[kMachineEnd - 2] | image[kMachineEnd - 1] << 8);
    if (machine != EM_RISCV)
        reject(name, fmt::format("ELF machine {} is not RISC-V ({}); {}", machine_name(machine),
                                 EM_RISCV, kBuildHint));
    if (image[EI_CLASS] == ELFCLASS64)
        reject(name, "64-bit (RV64) ELF, tpsim runs RV32 programs; " + std::string(kBuildHint));
    if (image[EI_CLASS] != ELFCLASS32)
        reject(name, fmt::format("unknown ELF class {}; the file is damaged, rebuild it",
                                 image[EI_CLASS]));
    if (image.size() < sizeof(Elf32_Ehdr))
        reject(name, fmt::format("truncated ELF header ({} of {} bytes); rebuild the program",
                                 image.size(), sizeof(Elf32_Ehdr)));
}

void check_header(const Elf32_Ehdr& eh, size_t file_size, const std::string& name) {
    if (eh.e_type != ET_EXEC)
        reject(name, fmt::format("ELF type {} is not an executable (ET_EXEC); link the object "
                                 "files into a static executable with ld.lld",
                                 eh.e_type));
    if (eh.e_flags & EF_RISCV_RVC)
        reject(name, "built with compressed instructions (C extension), which TRaX does not "
                     "execute; use -march=rv32imf");
    if (eh.e_phnum == 0) reject(name, "no program headers; link it as a static executable");
    if (eh.e_phentsize != sizeof(Elf32_Phdr))
        reject(name, fmt::format("program header size {} (expected {}); the file is damaged",
                                 eh.e_phentsize, sizeof(Elf32_Phdr)));
    const uint64_t ph_end = uint64_t(eh.e_phoff) + uint64_t(eh.e_phnum) * eh.e_phentsize;
    if (ph_end > file_size)
        reject(name, fmt::format("truncated: program headers end at byte {} but the file has {} "
                                 "bytes; rebuild the program",
                                 ph_end, file_size));
    if (eh.e_shnum != 0) {
        const uint64_t sh_end = uint64_t(eh.e_shoff) + uint64_t(eh.e_shnum) * eh.e_shentsize;
        if (eh.e_shentsize != sizeof(Elf32_Shdr) || sh_end > file_size)
            reject(name, fmt::format("truncated: section headers end at byte {} but the file "
                                     "has {} bytes; rebuild the program",
                                     sh_end, file_size));
    }
}

std::string permissions(const Segment& s) {
    return fmt::format("{}{}{}", s.readable ? 'r' : '-', s.writable ? 'w' : '-',
                       s.executable ? 'x' : '-');
}

void check_segment_placement(const Segment& s, const std::string& name) {
    using namespace trax::map;
    const uint64_t end = uint64_t(s.vaddr) + s.memsz;
    const std::string where =
        fmt::format("segment [{:#010x}, {:#010x}) ({})", s.vaddr, end, permissions(s));
    if (s.vaddr < kCodeBase)
        reject(name, fmt::format("{} lies below the code base {:#010x} (the null guard); link "
                                 "with the kernel linker script or -Ttext={:#x}",
                                 where, kCodeBase, kCodeBase));
    if (end > kGlobalBase)
        reject(name, fmt::format("{} reaches into global memory at {:#010x}; the program must fit "
                                 "in [{:#010x}, {:#010x}) — shrink static data",
                                 where, kGlobalBase, kCodeBase, kGlobalBase));
    if (s.executable && s.writable)
        reject(name, fmt::format("{} is writable and executable; tpsim decodes code once, so "
                                 "keep .text read-only (no self-modifying code)",
                                 where));
    if (s.executable && s.vaddr % 4 != 0)
        reject(name, fmt::format("executable {} is not 4-byte aligned; align .text to 4", where));
}

std::vector<Segment> read_segments(Elf* elf, const Elf32_Ehdr& eh, std::span<const uint8_t> image,
                                   const std::string& name) {
    std::vector<Segment> segments;
    for (size_t i = 0; i < eh.e_phnum; ++i) {
        GElf_Phdr ph;
        if (!gelf_getphdr(elf, int(i), &ph))
            reject(name, fmt::format("program header {} unreadable: {}", i, elf_errmsg(-1)));
        if (ph.p_type != PT_LOAD || ph.p_memsz == 0) continue;
        if (ph.p_filesz > ph.p_memsz)
            reject(name, fmt::format("program header {} has file size {} > memory size {}; the "
                                     "file is damaged",
                                     i, ph.p_filesz, ph.p_memsz));
        if (ph.p_offset + ph.p_filesz > image.size())
            reject(name, fmt::format("segment {} lies outside the file (bytes [{}, {}) of {}); the "
                                     "file is truncated or damaged",
                                     i, ph.p_offset, ph.p_offset + ph.p_filesz, image.size()));
        Segment s;
        s.vaddr = uint32_t(ph.p_vaddr);
        s.memsz = uint32_t(ph.p_memsz);
        s.readable = ph.p_flags & PF_R;
        s.writable = ph.p_flags & PF_W;
        s.executable = ph.p_flags & PF_X;
        const auto* from = image.data() + ph.p_offset;
        s.bytes.assign(from, from + ph.p_filesz);
        check_segment_placement(s, name);
        segments.push_back(std::move(s));
    }
    if (segments.empty()) reject(name, "no loadable segments; link it as a static executable");
    std::sort(segments.begin(), segments.end(),
              [](const Segment& a, const Segment& b) { return a.vaddr < b.vaddr; });
    for (size_t i = 1; i < segments.size(); ++i)
        if (segments[i].vaddr < segments[i - 1].end())
            reject(name, fmt::format("segments [{:#010x}, {:#010x}) and [{:#010x}, {:#010x}) "
                                     "overlap; fix the linker script",
                                     segments[i - 1].vaddr, segments[i - 1].end(),
                                     segments[i].vaddr, segments[i].end()));
    return segments;
}

/// Function symbols and bare code labels that lie in executable segments (program.functions),
/// and data objects that lie in writable ones (program.objects).
void read_symbols(Elf* elf, Program& program) {
    const auto in_segment = [&](uint32_t a, bool Segment::*kind) {
        return std::any_of(program.segments.begin(), program.segments.end(),
                           [&](const Segment& s) { return s.*kind && s.contains(a); });
    };
    for (Elf_Scn* scn = elf_nextscn(elf, nullptr); scn; scn = elf_nextscn(elf, scn)) {
        GElf_Shdr sh;
        if (!gelf_getshdr(scn, &sh) || sh.sh_type != SHT_SYMTAB || sh.sh_entsize == 0) continue;
        Elf_Data* data = elf_getdata(scn, nullptr);
        if (!data) continue;
        const size_t count = data->d_size / sh.sh_entsize;
        for (size_t i = 0; i < count; ++i) {
            GElf_Sym sym;
            if (!gelf_getsym(data, int(i), &sym) || sym.st_shndx == SHN_UNDEF) continue;
            const int type = GELF_ST_TYPE(sym.st_info);
            const char* n = elf_strptr(elf, sh.sh_link, sym.st_name);
            // Skip unnamed symbols, local labels (.L*) and RISC-V mapping symbols ($x, $d).
            if (!n || !*n || n[0] == '.' || n[0] == '$') continue;
            const Symbol symbol{n, uint32_t(sym.st_value), uint32_t(sym.st_size)};
            if ((type == STT_FUNC || type == STT_NOTYPE) &&
                in_segment(symbol.address, &Segment::executable))
                program.functions.push_back(symbol);
            else if (type == STT_OBJECT && in_segment(symbol.address, &Segment::writable))
                program.objects.push_back(symbol);
        }
    }
    // Sized (typed) symbols first at equal addresses, so lookups prefer them; then by name for
    // a deterministic order.
    std::sort(program.functions.begin(), program.functions.end(),
              [](const Symbol& a, const Symbol& b) {
                  if (a.address != b.address) return a.address < b.address;
                  if ((a.size != 0) != (b.size != 0)) return a.size != 0;
                  return a.name < b.name;
              });
    std::sort(program.objects.begin(), program.objects.end(), [](const Symbol& a, const Symbol& b) {
        return a.address != b.address ? a.address < b.address : a.name < b.name;
    });
}

/// Reads .stack_sizes: (4-byte address, ULEB128 size) pairs. A damaged section is read up to
/// the damage; the bound built on it then misses functions and says so.
std::vector<Program::FrameSize> read_frame_sizes(Elf* elf) {
    std::vector<Program::FrameSize> frames;
    size_t names = 0;
    if (elf_getshdrstrndx(elf, &names) != 0) return frames;
    for (Elf_Scn* scn = elf_nextscn(elf, nullptr); scn; scn = elf_nextscn(elf, scn)) {
        GElf_Shdr sh;
        const char* section = gelf_getshdr(scn, &sh) ? elf_strptr(elf, names, sh.sh_name) : nullptr;
        if (!section || std::strcmp(section, ".stack_sizes") != 0 || sh.sh_type == SHT_NOBITS)
            continue;
        const Elf_Data* data = elf_getdata(scn, nullptr);
        if (!data || !data->d_buf) continue;
        const auto* bytes = static_cast<const uint8_t*>(data->d_buf);
        for (size_t at = 0; at + 4 < data->d_size;) {
            uint32_t address = 0;
            std::memcpy(&address, bytes + at, 4);  // the ELF is little-endian (check_header)
            at += 4;
            uint64_t size = 0;
            int shift = 0;
            bool done = false;
            while (at < data->d_size && shift < 35 && !done) {
                size |= uint64_t(bytes[at] & 0x7f) << shift;
                done = (bytes[at++] & 0x80) == 0;
                shift += 7;
            }
            if (!done || size > UINT32_MAX) break;
            frames.push_back({address, uint32_t(size)});
        }
    }
    return frames;
}

/// A source file as DWARF names it: the file name alone (for messages) and the full path, which
/// libdw has already joined from DW_AT_comp_dir, the line table's directory and the name;
/// lexically_normal makes "dir/./x.hpp" and "dir/x.hpp" one file.
Program::SourceFile source_file(const char* dwarf_path) {
    std::string file = dwarf_path ? dwarf_path : "?";
    const std::string path = std::filesystem::path(file).lexically_normal().string();
    if (auto slash = file.rfind('/'); slash != std::string::npos) file = file.substr(slash + 1);
    return {file, path};
}

/// The name of an inlined function: its abstract instance (DW_AT_abstract_origin), or the
/// declaration that one points to (DW_AT_specification), carries it; dwarf_attr_integrate
/// follows both.
std::string inlined_function_name(Dwarf_Die* inlined) {
    Dwarf_Attribute attribute;
    if (const char* linkage =
            dwarf_formstring(dwarf_attr_integrate(inlined, DW_AT_linkage_name, &attribute)))
        return demangle(linkage);
    const char* name = dwarf_formstring(dwarf_attr_integrate(inlined, DW_AT_name, &attribute));
    return name ? name : "";
}

/// Collects the inlined calls below `die` (depth = nesting level) with their call sites.
/// Nesting beyond kMaxDepth (only a damaged file has it) is ignored, bounding the recursion.
void read_inlined_calls(Dwarf_Die* die, Dwarf_Files* files, uint32_t depth, Program& program) {
    constexpr uint32_t kMaxDepth = 64;
    Dwarf_Die child;
    if (depth > kMaxDepth || dwarf_child(die, &child) != 0) return;
    do {
        if (dwarf_tag(&child) == DW_TAG_inlined_subroutine) {
            Dwarf_Attribute attribute;
            Dwarf_Word file = 0, line = 0;
            const bool has_site =
                dwarf_formudata(dwarf_attr(&child, DW_AT_call_file, &attribute), &file) == 0 &&
                dwarf_formudata(dwarf_attr(&child, DW_AT_call_line, &attribute), &line) == 0;
            if (has_site && files) {
                const Program::SourceFile source =
                    source_file(dwarf_filesrc(files, file, nullptr, nullptr));
                const SourceLocation site{source.file, uint32_t(line), source.path};
                const std::string function = inlined_function_name(&child);
                Dwarf_Addr base = 0, low = 0, high = 0;
                for (ptrdiff_t at = 0; (at = dwarf_ranges(&child, at, &base, &low, &high)) > 0;)
                    program.inlined_calls.push_back(
                        {uint32_t(low), uint32_t(high), depth, site, function});
            }
        }
        read_inlined_calls(&child, files, depth + 1, program);
    } while (dwarf_siblingof(&child, &child) == 0);
}

/// Fills the line table from .debug_line when present; missing or unreadable DWARF just means
/// messages carry no file:line.
void read_lines(Elf* elf, Program& program) {
    Dwarf* dwarf = dwarf_begin_elf(elf, DWARF_C_READ, nullptr);
    if (!dwarf) return;
    std::map<std::string, uint32_t> file_index;
    Dwarf_Off offset = 0, next = 0;
    size_t header_size = 0;
    while (dwarf_nextcu(dwarf, offset, &next, &header_size, nullptr, nullptr, nullptr) == 0) {
        Dwarf_Die cu;
        Dwarf_Lines* lines = nullptr;
        size_t count = 0;
        if (dwarf_offdie(dwarf, offset + header_size, &cu) &&
            dwarf_getsrclines(&cu, &lines, &count) == 0) {
            for (size_t i = 0; i < count; ++i) {
                Dwarf_Line* line = dwarf_onesrcline(lines, i);
                Dwarf_Addr addr = 0;
                int lineno = 0;
                bool end = false;
                if (!line || dwarf_lineaddr(line, &addr) != 0 || dwarf_lineno(line, &lineno) != 0 ||
                    dwarf_lineendsequence(line, &end) != 0)
                    continue;
                Program::SourceFile file = source_file(dwarf_linesrc(line, nullptr, nullptr));
                auto [it, inserted] = file_index.try_emplace(file.path, program.line_files.size());
                if (inserted) program.line_files.push_back(std::move(file));
                program.line_rows.push_back({uint32_t(addr), uint32_t(lineno), it->second, end});
            }
        }
        Dwarf_Files* files = nullptr;
        size_t file_count = 0;
        if (dwarf_offdie(dwarf, offset + header_size, &cu) &&
            dwarf_getsrcfiles(&cu, &files, &file_count) == 0)
            read_inlined_calls(&cu, files, 0, program);
        offset = next;
    }
    dwarf_end(dwarf);
    // Stable: an end-of-sequence row and the next sequence's first row may share an address;
    // keeping emission order lets the later (real) row win in source_at's upper_bound.
    std::stable_sort(program.line_rows.begin(), program.line_rows.end(),
                     [](const auto& a, const auto& b) { return a.address < b.address; });
}

}  // namespace

const Symbol* Program::function_at(uint32_t pc) const {
    auto it = std::upper_bound(functions.begin(), functions.end(), pc,
                               [](uint32_t a, const Symbol& s) { return a < s.address; });
    if (it == functions.begin()) return nullptr;
    // Among symbols at the same address the sized one sorts first; walk back to it.
    const uint32_t address = std::prev(it)->address;
    while (it != functions.begin() && std::prev(it)->address == address)
        --it;
    const Symbol& s = *it;
    if (s.size != 0 && pc - s.address >= s.size) return nullptr;
    return &s;
}

std::string Program::describe_pc(uint32_t pc) const {
    const Symbol* s = function_at(pc);
    if (!s) return "";
    const std::string name = demangle(s->name);
    return pc == s->address ? name : fmt::format("{}+{:#x}", name, pc - s->address);
}

std::optional<SourceLocation> Program::source_at(uint32_t pc) const {
    auto it = std::upper_bound(line_rows.begin(), line_rows.end(), pc,
                               [](uint32_t a, const LineRow& r) { return a < r.address; });
    if (it == line_rows.begin()) return std::nullopt;
    // Line 0 marks code the compiler attributes to no line (e.g. a load scheduled between two
    // statements); report the closest line before it in the same sequence, as debuggers do.
    auto row = std::prev(it);
    while (row->line == 0 && !row->end_sequence && row != line_rows.begin())
        --row;
    if (row->end_sequence || row->line == 0) return std::nullopt;
    const SourceFile& file = line_files[row->file];
    return SourceLocation{file.file, row->line, file.path};
}

namespace {

/// The inlined calls whose ranges hold pc, innermost first.
std::vector<const Program::InlinedCall*>
inlined_around(const std::vector<Program::InlinedCall>& calls, uint32_t pc) {
    std::vector<const Program::InlinedCall*> around;
    for (const Program::InlinedCall& call : calls)
        if (pc >= call.low && pc < call.high) around.push_back(&call);
    std::stable_sort(around.begin(), around.end(),
                     [](const auto* a, const auto* b) { return a->depth > b->depth; });
    return around;
}

}  // namespace

std::vector<SourceLocation> Program::inlined_call_sites(uint32_t pc) const {
    std::vector<SourceLocation> sites;
    for (const InlinedCall* call : inlined_around(inlined_calls, pc))
        sites.push_back(call->call_site);
    return sites;
}

std::string Program::source_function_at(uint32_t pc) const {
    if (const auto around = inlined_around(inlined_calls, pc); !around.empty())
        return around.front()->function;
    const Symbol* symbol = function_at(pc);
    return symbol ? demangle(symbol->name) : "";
}

const Segment* Program::segment_at(uint32_t addr) const {
    for (const Segment& s : segments)
        if (s.contains(addr)) return &s;
    return nullptr;
}

Program load_elf(std::span<const uint8_t> image, const std::string& name) {
    check_identity(image, name);
    Elf32_Ehdr eh;
    std::memcpy(&eh, image.data(), sizeof eh);
    check_header(eh, image.size(), name);

    if (elf_version(EV_CURRENT) == EV_NONE)
        throw Error("libelf is out of date (elf_version failed); reinstall libelf");
    // libelf wants a mutable buffer; it stays alive until the handle is closed.
    std::vector<char> buffer(image.begin(), image.end());
    ElfHandle elf(elf_memory(buffer.data(), buffer.size()));
    if (!elf || elf_kind(elf.get()) != ELF_K_ELF)
        reject(name,
               fmt::format("libelf cannot read it ({}); the file is damaged", elf_errmsg(-1)));

    Program program;
    program.name = name;
    program.entry = eh.e_entry;
    program.segments = read_segments(elf.get(), eh, image, name);
    const Segment* entry_segment = program.segment_at(program.entry);
    if (program.entry == 0 || !entry_segment || !entry_segment->executable)
        reject(name, fmt::format("entry point {:#010x} is not in an executable segment; define "
                                 "_start (or pass -e to the linker)",
                                 program.entry));
    if (program.entry % 4 != 0)
        reject(name, fmt::format("entry point {:#010x} is not 4-byte aligned; align _start to 4",
                                 program.entry));
    read_symbols(elf.get(), program);
    read_lines(elf.get(), program);
    program.frame_sizes = read_frame_sizes(elf.get());
    return program;
}

Program load_elf(const std::string& path) {
    const std::string bytes = read_input_file(
        path, "kernel", kMaxElfBytes,
        "check that it is a kernel ELF, or strip its debug information (llvm-strip -g)");
    return load_elf({reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()}, path);
}

}  // namespace tpsim::core
