#include "sim/core/module.hpp"

#include <dlfcn.h>
#include <fmt/format.h>

#include "sim/core/error.hpp"

namespace tpsim {

const void* load_module_entry(const char* file, const char* entry, const char* what) {
    const std::string path = fmt::format("{}/{}", TPSIM_MODULE_DIR, file);
    // RTLD_LOCAL: the module's libraries stay out of the global namespace; RTLD_NOW: a missing
    // symbol is an error here, once, not a crash later.
    void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle)
        throw Error(fmt::format("cannot load {}: {}; rebuild tpsim (cmake --build build) or "
                                "install its Debian packages (scripts/setup)",
                                what, dlerror()));
    using Entry = const void* (*)();
    const auto make = reinterpret_cast<Entry>(dlsym(handle, entry));
    if (!make)
        throw Error(fmt::format("cannot load {}: {} has no function {}; rebuild tpsim (cmake "
                                "--build build)",
                                what, path, entry));
    return make();
}

}  // namespace tpsim
