#include "sim/core/input_file.hpp"

#include <fstream>

#include <fmt/format.h>

#include "sim/core/error.hpp"

namespace tpsim {

std::uintmax_t require_input_file(const std::filesystem::path& path, std::string_view what,
                                  std::uintmax_t max_bytes, std::string_view limit_hint) {
    namespace fs = std::filesystem;
    std::error_code ec;
    const fs::file_status status = fs::status(path, ec);
    if (!fs::exists(status))
        throw Error(fmt::format("cannot open {} '{}': no such file", what, path.string()));
    if (fs::is_directory(status))
        throw Error(fmt::format("cannot read {} '{}': it is a directory; give the path of a file",
                                what, path.string()));
    // A FIFO or a character device would block or never end; only a regular file has a size.
    if (!fs::is_regular_file(status))
        throw Error(fmt::format("cannot read {} '{}': not a regular file (a pipe, device or "
                                "socket); save the input to a file first",
                                what, path.string()));
    const std::uintmax_t size = fs::file_size(path, ec);
    if (ec) throw Error(fmt::format("cannot read {} '{}': {}", what, path.string(), ec.message()));
    if (size > max_bytes)
        throw Error(fmt::format("{} '{}' is {} bytes, more than the {} bytes tpsim reads{}{}", what,
                                path.string(), size, max_bytes, limit_hint.empty() ? "" : "; ",
                                limit_hint));
    return size;
}

std::string read_input_file(const std::filesystem::path& path, std::string_view what,
                            std::uintmax_t max_bytes, std::string_view limit_hint) {
    const std::uintmax_t size = require_input_file(path, what, max_bytes, limit_hint);
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(fmt::format("cannot open {} '{}': not readable", what, path.string()));
    std::string bytes(static_cast<size_t>(size), '\0');
    in.read(bytes.data(), static_cast<std::streamsize>(size));
    // The file may have shrunk since it was measured; what was read is what there is.
    bytes.resize(static_cast<size_t>(in.gcount()));
    if (in.bad()) throw Error(fmt::format("cannot read {} '{}': I/O error", what, path.string()));
    return bytes;
}

}  // namespace tpsim
