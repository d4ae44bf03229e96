// Modules: the code that needs a heavy library (OpenImageIO pulls in some 250 shared libraries,
// assimp a few more) lives in a shared module loaded on first use, so a command that never reads
// or writes an image or a mesh starts without them (docs/performance.md, "Start-up").
#pragma once

namespace tpsim {

/// The object that module `file` (in tpsim's build, beside the tpsim command) hands out through
/// its extern "C" function `entry`; `what` names it in messages ("the image module
/// (OpenImageIO)"). Call once per process (keep the reference): the module is never unloaded.
/// Throws tpsim::Error with the loader's reason when the module or a library it needs cannot be
/// loaded.
template <class Interface>
const Interface& load_module(const char* file, const char* entry, const char* what);

/// The untyped step of load_module.
const void* load_module_entry(const char* file, const char* entry, const char* what);

template <class Interface>
const Interface& load_module(const char* file, const char* entry, const char* what) {
    return *static_cast<const Interface*>(load_module_entry(file, entry, what));
}

}  // namespace tpsim
