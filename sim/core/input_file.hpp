// The one way tpsim reads an input file (kernel ELF, chip config, scene, mesh): only regular
// files, and only up to a size limit checked before anything is allocated, so a FIFO, a device
// such as /dev/zero or a multi-gigabyte file is one clear error instead of a hang or bad_alloc.
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace tpsim {

/// Throws tpsim::Error unless `path` names an existing regular file (symbolic links followed) of
/// at most `max_bytes` bytes; returns its size. `what` names the input in the message ("kernel",
/// "chip config", "mesh"), `limit_hint` says how to get past the limit when that is possible.
std::uintmax_t require_input_file(const std::filesystem::path& path, std::string_view what,
                                  std::uintmax_t max_bytes, std::string_view limit_hint = {});

/// require_input_file, then the file's whole contents.
std::string read_input_file(const std::filesystem::path& path, std::string_view what,
                            std::uintmax_t max_bytes, std::string_view limit_hint = {});

}  // namespace tpsim
