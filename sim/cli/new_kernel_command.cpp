// `tpsim new-kernel DIR`: starts a kernel in a folder of its own (outside the tpsim tree): writes
// a CMake project that finds this tpsim build as a package, a kernel (a working one from
// kernel/template, or an assignment's starter) and a README, then configures and builds it.

#include <algorithm>
#include <cctype>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "sim/cli/commands.hpp"
#include "sim/core/error.hpp"
#include "sim/core/input_file.hpp"
#include "sim/core/program.hpp"
#include "sim/course/assignment.hpp"

namespace tpsim::cli {
namespace {

namespace fs = std::filesystem;

const fs::path kSourceDir = TPSIM_SOURCE_DIR;
const fs::path kBuildDir = TPSIM_BUILD_DIR;
constexpr uintmax_t kMaxTemplateBytes = 1 << 20;

struct NewKernelOptions {
    std::string dir;
    std::string name;
    std::string assignment;
};

/// The default kernel name: the folder's name as a C identifier (CMake target and file name).
std::string name_from(const fs::path& dir) {
    std::string name = fs::absolute(dir).lexically_normal().filename().string();
    if (name.empty()) name = fs::absolute(dir).lexically_normal().parent_path().filename().string();
    for (char& c : name)
        if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_') c = '_';
    if (name.empty() || std::isdigit(static_cast<unsigned char>(name[0]))) name = "kernel_" + name;
    return name;
}

bool is_identifier(const std::string& name) {
    return !name.empty() && !std::isdigit(static_cast<unsigned char>(name[0])) &&
           std::all_of(name.begin(), name.end(), [](char c) {
               return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
           });
}

/// The assignments with a starter kernel, by folder name, sorted.
std::vector<std::string> available_assignments(const fs::path& root) {
    std::vector<std::string> names;
    std::error_code ec;
    for (const fs::directory_entry& entry : fs::directory_iterator(root, ec))
        if (fs::is_regular_file(entry.path() / "starter.cpp", ec))
            names.push_back(entry.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
}

fs::path starter_of(const std::string& assignment) {
    const fs::path root = kSourceDir / "course" / "assignments";
    const fs::path starter = root / assignment / "starter.cpp";
    std::error_code ec;
    if (assignment.find('/') == std::string::npos && fs::is_regular_file(starter, ec))
        return starter;
    const std::vector<std::string> names = available_assignments(root);
    throw Error(fmt::format("--assignment: no assignment '{}' with a starter kernel in {}; {}",
                            assignment, root.string(),
                            names.empty()
                                ? "there are none in this tpsim tree"
                                : "choose one of " + fmt::format("{}", fmt::join(names, ", "))));
}

std::string substitute(std::string text, const std::string& key, const std::string& value) {
    for (size_t at = text.find(key); at != std::string::npos;
         at = text.find(key, at + value.size()))
        text.replace(at, key.size(), value);
    return text;
}

/// Runs a command with the terminal's output (the student sees the compiler's messages);
/// true when it exits 0.
bool run(const std::vector<std::string>& args) {
    const ProgramExit ran = run_program(args);
    if (ran.start_error != 0)
        throw Error(fmt::format("cannot run {}: {}", args[0], std::strerror(ran.start_error)));
    return ran.succeeded();
}

/// What `render` needs to show the kernel's image: an assignment's first scene at the size its
/// checker renders, or the Cornell box. Absolute paths: the commands work from any folder.
std::string scene_arguments(const fs::path& starter, const std::string& assignment) {
    if (assignment.empty()) return (kSourceDir / "scenes" / "cornell.toml").string();
    const course::Assignment a = course::load_assignment(starter.parent_path() / "assignment.toml");
    std::string arguments = a.scenes.at(0).file.lexically_normal().string();
    if (a.width != 0) arguments += fmt::format(" --width {}", a.width);
    if (a.height != 0) arguments += fmt::format(" --height {}", a.height);
    if (a.samples_per_pixel != 0) arguments += fmt::format(" --spp {}", a.samples_per_pixel);
    return arguments;
}

int run_new_kernel(const NewKernelOptions& o) {
    const fs::path dir = o.dir;
    const std::string name = o.name.empty() ? name_from(dir) : o.name;
    if (!is_identifier(name))
        throw Error(fmt::format("--name '{}' is not a valid kernel name: use letters, digits and "
                                "'_', not starting with a digit",
                                name));
    const fs::path starter = o.assignment.empty()
                                 ? kSourceDir / "kernel" / "template" / "kernel.cpp"
                                 : starter_of(o.assignment);
    const std::string scene = scene_arguments(starter, o.assignment);
    std::error_code ec;
    if (fs::exists(dir, ec) && (!fs::is_directory(dir, ec) || !fs::is_empty(dir, ec)))
        throw Error(
            fmt::format("cannot make a kernel folder at '{}': it exists and is not an empty "
                        "directory; give a new folder name",
                        dir.string()));
    if (fs::create_directories(dir, ec); ec)
        throw Error(fmt::format("cannot create '{}': {}", dir.string(), ec.message()));

    const fs::path tpsim = kBuildDir / "sim" / "tpsim";
    auto fill = [&](const std::string& template_name) {
        std::string text = read_input_file(kSourceDir / "kernel" / "template" / template_name,
                                           "kernel template", kMaxTemplateBytes);
        text = substitute(text, "@NAME@", name);
        text = substitute(text, "@TPSIM_BUILD@", kBuildDir.string());
        text = substitute(text, "@SCENE@", scene);
        text = substitute(text, "@TPSIM_SOURCE@", kSourceDir.string());
        return substitute(text, "@TPSIM@", tpsim.string());
    };
    write_output(dir / "CMakeLists.txt", fill("CMakeLists.txt.in"), "the kernel's CMakeLists.txt");
    write_output(dir / "README.md", fill("README.md.in"), "the kernel's README.md");
    write_output(dir / "kernel.cpp", read_input_file(starter, "starter kernel", kMaxTemplateBytes),
                 "the kernel");

    const fs::path build = dir / "build";
    if (!run({TPSIM_CMAKE, "-S", dir.string(), "-B", build.string(), "-DCMAKE_BUILD_TYPE=Debug",
              "-Dtpsim_DIR=" + kBuildDir.string()}) ||
        !run({TPSIM_CMAKE, "--build", build.string()}))
        throw Error(fmt::format("the new kernel in '{}' did not build (the messages above say "
                                "why); fix it and rebuild with: cmake --build {}",
                                dir.string(), build.string()));

    const fs::path elf = build / "kernels" / (name + ".elf");
    fmt::print("\nkernel   {} (native twin {}), from {}\n", elf.string(),
               (build / "kernels" / ("lib" + name + "_native.so")).string(), starter.string());
    fmt::print("next     edit {}, then\n", (dir / "kernel.cpp").string());
    fmt::print("         cmake --build {}\n", build.string());
    fmt::print("         {} render {} --kernel {} -o {}.png\n", tpsim.string(), scene, elf.string(),
               name);
    if (!o.assignment.empty())
        fmt::print("         {} check {} --kernel {}\n", tpsim.string(), o.assignment,
                   elf.string());
    fmt::print("         (more in {})\n", (dir / "README.md").string());
    return 0;
}

}  // namespace

Command add_new_kernel_command(CLI::App& app) {
    auto* command = app.add_subcommand(
        "new-kernel", "Start a kernel in a new folder of its own: a CMake project using this "
                      "tpsim build, a kernel.cpp and a README; configure and build it");
    auto o = std::make_shared<NewKernelOptions>();
    command->add_option("dir", o->dir, "The folder to create (new or empty)")->required();
    command->add_option("--name", o->name,
                        "Kernel name: build/kernels/NAME.elf [default: the folder's name]");
    command->add_option("--assignment", o->assignment,
                        "Start from this assignment's starter kernel (course/assignments/, e.g. "
                        "1-gradient) instead of a working ray caster");
    return {command, [o] { return run_new_kernel(*o); }};
}

}  // namespace tpsim::cli
