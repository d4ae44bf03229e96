#include "sim/core/input_file.hpp"

#include <algorithm>
#include <cerrno>
#include <cstring>

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>

#include "sim/core/error.hpp"

namespace tpsim {

namespace {

/// An open file descriptor, closed when it goes out of scope.
class FileDescriptor {
public:
    explicit FileDescriptor(int fd) : fd_(fd) {}
    ~FileDescriptor() {
        if (fd_ >= 0) ::close(fd_);
    }
    FileDescriptor(const FileDescriptor&) = delete;
    FileDescriptor& operator=(const FileDescriptor&) = delete;
    int get() const { return fd_; }

private:
    int fd_;
};

std::string not_regular(std::string_view what, const std::filesystem::path& path) {
    return fmt::format("cannot read {} '{}': not a regular file (a pipe, device or socket); save "
                       "the input to a file first",
                       what, path.string());
}

std::string too_big(std::string_view what, const std::filesystem::path& path, std::uintmax_t size,
                    std::uintmax_t max_bytes, std::string_view limit_hint) {
    return fmt::format("{} '{}' is {} bytes, more than the {} bytes tpsim reads{}{}", what,
                       path.string(), size, max_bytes, limit_hint.empty() ? "" : "; ", limit_hint);
}

}  // namespace

std::uintmax_t require_input_file(const std::filesystem::path& path, std::string_view what,
                                  std::uintmax_t max_bytes, std::string_view limit_hint) {
    namespace fs = std::filesystem;
    std::error_code ec;
    const fs::file_status status = fs::status(path, ec);
    if (!fs::exists(status)) {
        // A dangling link or a loop of links is named as such, not as a missing file.
        if (fs::is_symlink(fs::symlink_status(path, ec)))
            throw Error(fmt::format("cannot open {} '{}': a symbolic link to a missing file, or "
                                    "a loop of links",
                                    what, path.string()));
        throw Error(fmt::format("cannot open {} '{}': no such file", what, path.string()));
    }
    if (fs::is_directory(status))
        throw Error(fmt::format("cannot read {} '{}': it is a directory; give the path of a file",
                                what, path.string()));
    // A FIFO or a character device would block or never end; only a regular file has a size.
    if (!fs::is_regular_file(status)) throw Error(not_regular(what, path));
    const std::uintmax_t size = fs::file_size(path, ec);
    if (ec) throw Error(fmt::format("cannot read {} '{}': {}", what, path.string(), ec.message()));
    if (size > max_bytes) throw Error(too_big(what, path, size, max_bytes, limit_hint));
    return size;
}

std::string read_input_file(const std::filesystem::path& path, std::string_view what,
                            std::uintmax_t max_bytes, std::string_view limit_hint) {
    require_input_file(path, what, max_bytes, limit_hint);
    // The checks are repeated on the open descriptor, so a file swapped for a FIFO after the
    // check cannot block the read (O_NONBLOCK makes opening a FIFO return at once).
    const FileDescriptor fd(::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC));
    if (fd.get() < 0)
        throw Error(
            fmt::format("cannot open {} '{}': {}", what, path.string(), std::strerror(errno)));
    struct stat info {};
    if (::fstat(fd.get(), &info) != 0 || !S_ISREG(info.st_mode))
        throw Error(not_regular(what, path));
    // Read to the end rather than to the size stat gave: a file may grow, and some (in /proc)
    // report size 0. One byte past the limit is enough to know it is too big.
    std::string bytes;
    bytes.resize(static_cast<size_t>(std::min<std::uintmax_t>(info.st_size, max_bytes) + 1));
    size_t length = 0;
    for (;;) {
        if (length == bytes.size()) {
            if (length > max_bytes) break;
            bytes.resize(std::min<size_t>(2 * length, max_bytes + 1));
        }
        const ssize_t got = ::read(fd.get(), bytes.data() + length, bytes.size() - length);
        if (got < 0 && errno == EINTR) continue;
        if (got < 0)
            throw Error(
                fmt::format("cannot read {} '{}': {}", what, path.string(), std::strerror(errno)));
        if (got == 0) break;
        length += static_cast<size_t>(got);
    }
    if (length > max_bytes)  // it grew since it was measured
        throw Error(fmt::format("{} '{}' grew past the {} bytes tpsim reads", what, path.string(),
                                max_bytes));
    bytes.resize(length);
    return bytes;
}

}  // namespace tpsim
