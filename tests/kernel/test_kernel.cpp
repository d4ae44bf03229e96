// Kernel side, checked from the host: the layout rule, the linked kernel ELFs, and the native
// twins (run through the same C entry point the simulator uses).
#include <dlfcn.h>
#include <gelf.h>
#include <libelf.h>

#include <fcntl.h>
#include <unistd.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "kernel/memory_map.hpp"
#include "kernel/native_twin.h"
#include "kernel/scene_layout.hpp"

namespace layout = trax::layout;

namespace {

const std::string kKernels = TPSIM_KERNELS_DIR;

const layout::SectionRef& section(const layout::SceneHeader& h, int i) {
    const layout::SectionRef* all[] = {&h.camera,    &h.lights,    &h.materials,
                                       &h.triangles, &h.bvh_nodes, &h.framebuffer};
    return *all[i];
}
constexpr int kRecordWords[] = {layout::kCameraWords,   layout::kPointLightWords,
                                layout::kMaterialWords, layout::kTriangleWords,
                                layout::kBvhNodeWords,  layout::kPixelWords};

/// A scene memory image built through the layout header, as the scene compiler would.
struct Image {
    layout::SceneHeader header{};
    std::vector<uint32_t> words;

    Image(int width, int height, int lights, int materials, int triangles) {
        header.magic = layout::kMagic;
        header.version = layout::kVersion;
        header.image_width = width;
        header.image_height = height;
        header.samples_per_pixel = 1;
        header.lights.count = lights;
        header.materials.count = materials;
        header.triangles.count = triangles;
        layout::place_sections(header);
        words.assign(header.total_words, 0);
        std::memcpy(words.data(), &header, sizeof header);
    }
    void sync_header() { std::memcpy(words.data(), &header, sizeof header); }
    template <class Record> void put(const layout::SectionRef& s, int index, const Record& r) {
        std::memcpy(&words[s.addr + index * sizeof(Record) / 4], &r, sizeof r);
    }
    float fb(int pixel, int channel) const {
        return std::bit_cast<float>(words[header.framebuffer.addr + pixel * 3 + channel]);
    }
};

/// One dlopen()ed native twin.
struct Twin {
    void* handle;
    TpsimNativeRunFn run;
    explicit Twin(const std::string& name) {
        const std::string path = kKernels + "/lib" + name + "_native.so";
        handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
        if (!handle) throw std::runtime_error(dlerror());
        run = reinterpret_cast<TpsimNativeRunFn>(dlsym(handle, TPSIM_NATIVE_RUN_SYMBOL));
        if (!run) throw std::runtime_error("no " TPSIM_NATIVE_RUN_SYMBOL " in " + path);
    }
    ~Twin() { dlclose(handle); }
    Twin(const Twin&) = delete;
    Twin& operator=(const Twin&) = delete;

    /// Runs the kernel; returns the error message ("" on success).
    std::string operator()(Image& image, uint32_t threads, uint32_t tms, uint32_t tm_size,
                           uint32_t word_count = 0) {
        char error[512] = "";
        const TraxNativeContext ctx{image.words.data(),
                                    word_count ? word_count : uint32_t(image.words.size()),
                                    threads,
                                    tms,
                                    tm_size,
                                    error,
                                    sizeof error,
                                    nullptr,
                                    0,
                                    nullptr,
                                    nullptr};
        const int status = run(&ctx);
        CHECK((status == 0) == (error[0] == '\0'));
        return error;
    }
};

}  // namespace

TEST_CASE("kernel: sections are placed in order, aligned, without overlap") {
    layout::SceneHeader h{};
    h.image_width = 7;
    h.image_height = 5;
    h.lights.count = 3;
    h.materials.count = 0;  // empty sections take no space
    h.triangles.count = 11;
    h.bvh_nodes.count = 0;
    layout::place_sections(h);

    CHECK(h.camera.count == 1);
    CHECK(h.framebuffer.count == 35);
    int end_of_previous = layout::kHeaderWords;
    for (int i = 0; i < 6; ++i) {
        const layout::SectionRef& s = section(h, i);
        INFO("section " << i);
        CHECK(s.addr % layout::kSectionAlignWords == 0);
        CHECK(s.addr >= end_of_previous);
        CHECK(s.addr - end_of_previous < layout::kSectionAlignWords);
        end_of_previous = s.addr + s.count * kRecordWords[i];
    }
    CHECK(h.materials.addr == h.triangles.addr);
    CHECK(h.bvh_nodes.addr == h.framebuffer.addr);
    CHECK(h.total_words >= end_of_previous);
    CHECK(h.total_words % layout::kSectionAlignWords == 0);
    // The image must fit in the guest's global memory window.
    CHECK(uint64_t(h.total_words) * 4 < trax::map::kLocalTop - trax::map::kGlobalBase);
}

namespace {

struct ElfFile {
    int fd;
    Elf* elf;
    explicit ElfFile(const std::string& path) {
        elf_version(EV_CURRENT);
        fd = open(path.c_str(), O_RDONLY);
        if (fd < 0) throw std::runtime_error("cannot open " + path);
        elf = elf_begin(fd, ELF_C_READ, nullptr);
        if (!elf) throw std::runtime_error("not an ELF: " + path);
    }
    ~ElfFile() {
        elf_end(elf);
        close(fd);
    }
    ElfFile(const ElfFile&) = delete;
    ElfFile& operator=(const ElfFile&) = delete;
};

}  // namespace

TEST_CASE("kernel: kernel ELFs are RV32 executables with only the expected sections and no "
          "undefined symbols") {
    const auto name = GENERATE(as<std::string>{}, "hello", "primary_brute");
    INFO("kernel " << name);
    ElfFile f(kKernels + "/" + name + ".elf");

    GElf_Ehdr eh;
    REQUIRE(gelf_getehdr(f.elf, &eh));
    CHECK(eh.e_ident[EI_CLASS] == ELFCLASS32);
    CHECK(eh.e_machine == EM_RISCV);
    CHECK(eh.e_type == ET_EXEC);
    CHECK(eh.e_entry == trax::map::kCodeBase);  // _start is placed first

    size_t segments = 0;
    REQUIRE(elf_getphdrnum(f.elf, &segments) == 0);
    for (size_t i = 0; i < segments; ++i) {
        GElf_Phdr ph;
        REQUIRE(gelf_getphdr(f.elf, int(i), &ph));
        if (ph.p_type != PT_LOAD) continue;
        CHECK(ph.p_vaddr >= trax::map::kCodeBase);
        CHECK(ph.p_vaddr + ph.p_memsz <= trax::map::kGlobalBase);
        CHECK_FALSE(((ph.p_flags & PF_W) && (ph.p_flags & PF_X)));
    }

    size_t shstrndx = 0;
    REQUIRE(elf_getshdrstrndx(f.elf, &shstrndx) == 0);
    // .stack_sizes: every function's frame, for the stack bound (sim/core/stack_bound.hpp).
    const std::set<std::string> allowed = {".text",     ".rodata",           ".data",
                                           ".bss",      ".symtab",           ".strtab",
                                           ".shstrtab", ".riscv.attributes", ".stack_sizes"};
    bool has_text = false;
    for (Elf_Scn* scn = elf_nextscn(f.elf, nullptr); scn; scn = elf_nextscn(f.elf, scn)) {
        GElf_Shdr sh;
        REQUIRE(gelf_getshdr(scn, &sh));
        const std::string section_name = elf_strptr(f.elf, shstrndx, sh.sh_name);
        INFO("section " << section_name);
        CHECK((allowed.count(section_name) || section_name.rfind(".debug_", 0) == 0));
        has_text |= section_name == ".text";
        if (sh.sh_type != SHT_SYMTAB) continue;
        Elf_Data* data = elf_getdata(scn, nullptr);
        for (size_t i = 1; i < sh.sh_size / sh.sh_entsize; ++i) {
            GElf_Sym sym;
            REQUIRE(gelf_getsym(data, int(i), &sym));
            INFO("symbol " << elf_strptr(f.elf, sh.sh_link, sym.st_name));
            CHECK(sym.st_shndx != SHN_UNDEF);
        }
    }
    CHECK(has_text);
}

TEST_CASE("kernel: the native twin runs every thread once with its ids") {
    Twin hello("hello");
    Image image(4, 3, 0, 0, 0);  // 12 pixels, 10 threads: the last two pixels stay untouched
    REQUIRE(hello(image, 10, 3, 4) == "");
    for (int t = 0; t < 12; ++t) {
        INFO("pixel " << t);
        const uint32_t* px = &image.words[image.header.framebuffer.addr + 3 * t];
        if (t < 10) {
            CHECK(px[0] == uint32_t(t));
            CHECK(px[1] == uint32_t(t / 4));
            CHECK(px[2] == uint32_t(t % 4));
        } else {
            CHECK((px[0] | px[1] | px[2]) == 0);
        }
    }
}

TEST_CASE("kernel: the native twin reports bad accesses and bad contexts instead of crashing") {
    Twin hello("hello");
    Image image(4, 3, 0, 0, 0);
    // Cut global memory off in the middle of the framebuffer: thread 5's store is outside.
    const uint32_t words = image.header.framebuffer.addr + 5 * 3;
    const std::string error = hello(image, 10, 3, 4, words);
    CHECK_THAT(error, Catch::Contains("storei(") && Catch::Contains("in thread 5") &&
                          Catch::Contains("outside global memory"));

    CHECK_THAT(hello(image, 0, 1, 1), Catch::Contains("at least 1"));
    CHECK_THAT(hello(image, 9, 2, 4), Catch::Contains("do not fit"));
    char message[64] = "";
    const TraxNativeContext no_memory{nullptr,        0,       1, 1,       1,      message,
                                      sizeof message, nullptr, 0, nullptr, nullptr};
    CHECK(hello.run(&no_memory) != 0);
    CHECK_THAT(std::string(message), Catch::Contains("no global memory"));
}

namespace {

/// Camera at the origin looking down -z; the image plane z = -1 spans [-1, 1]^2.
/// A large triangle in z = -2 fills all but the top-left corner of a 4x4 image.
Image lit_triangle_scene(uint32_t flags, bool with_occluder) {
    Image image(4, 4, 1, 1, with_occluder ? 2 : 1);
    image.header.flags = flags;
    const float ambient[3] = {0.1f, 0.2f, 0.3f}, background[3] = {0.25f, 0.5f, 0.75f};
    std::memcpy(image.header.ambient, ambient, sizeof ambient);
    std::memcpy(image.header.background, background, sizeof background);
    image.sync_header();
    image.put(image.header.camera, 0,
              layout::Camera{{0, 0, 0}, {-1, 1, -1}, {2, 0, 0}, {0, -2, 0}});
    image.put(image.header.lights, 0, layout::PointLight{{2, 0.5f, -1}, {1, 1, 1}});
    image.put(image.header.materials, 0, layout::Material{{0.5f, 0.25f, 1.0f}});
    image.put(image.header.triangles, 0,
              layout::Triangle{{-4, -4, -2}, {4, -4, -2}, {0, 4, -2}, 0});
    // Halfway between pixel (1,1)'s hit point (-0.5, 0.5, -2) and the light, off its camera ray.
    if (with_occluder)
        image.put(
            image.header.triangles, 1,
            layout::Triangle{{0.5f, 0.25f, -1.5f}, {1, 0.25f, -1.5f}, {0.75f, 0.9f, -1.5f}, 0});
    return image;
}

}  // namespace

TEST_CASE("kernel: the brute-force kernel shades, shadows and misses as the layout says") {
    Twin kernel("primary_brute");
    const double albedo[3] = {0.5, 0.25, 1.0}, ambient[3] = {0.1, 0.2, 0.3};
    // Pixel (1,1): centre ray (-0.25, 0.25, -1) hits z = -2 at p = (-0.5, 0.5, -2), normal +z.
    // To the light (2.5, 0, 1): cosine 1 / sqrt(7.25), squared distance 7.25.
    const double cosine = 1.0 / std::sqrt(7.25);
    const int pixel = 1 * 4 + 1;

    SECTION("Lambert plus ambient, and background for the miss") {
        Image image = lit_triangle_scene(0, false);
        REQUIRE(kernel(image, 3, 1, 4) == "");
        for (int c = 0; c < 3; ++c) {
            CHECK(image.fb(pixel, c) == Approx(albedo[c] * (ambient[c] + cosine)).epsilon(1e-5));
            CHECK(image.fb(0, c) == image.header.background[c]);  // top-left ray misses
        }
    }
    SECTION("distance falloff") {
        Image image = lit_triangle_scene(layout::kFeatureLightFalloff, false);
        REQUIRE(kernel(image, 1, 1, 1) == "");
        for (int c = 0; c < 3; ++c)
            CHECK(image.fb(pixel, c) ==
                  Approx(albedo[c] * (ambient[c] + cosine / 7.25)).epsilon(1e-5));
    }
    SECTION("an occluder only matters with shadows on") {
        Image unshadowed = lit_triangle_scene(0, true);
        Image shadowed = lit_triangle_scene(layout::kFeatureShadows, true);
        REQUIRE(kernel(unshadowed, 2, 1, 2) == "");
        REQUIRE(kernel(shadowed, 2, 1, 2) == "");
        for (int c = 0; c < 3; ++c) {
            CHECK(unshadowed.fb(pixel, c) ==
                  Approx(albedo[c] * (ambient[c] + cosine)).epsilon(1e-5));
            CHECK(shadowed.fb(pixel, c) == Approx(albedo[c] * ambient[c]).epsilon(1e-5));
        }
    }
    SECTION("the image does not depend on the thread count") {
        Image one = lit_triangle_scene(layout::kFeatureShadows, true);
        Image many = lit_triangle_scene(layout::kFeatureShadows, true);
        one.header.samples_per_pixel = many.header.samples_per_pixel = 4;
        one.sync_header();
        many.sync_header();
        REQUIRE(kernel(one, 1, 1, 1) == "");
        REQUIRE(kernel(many, 64, 2, 32) == "");
        CHECK(one.words == many.words);
    }
}
