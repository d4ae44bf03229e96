#include "sim/render/png_file.hpp"

#include <png.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>

namespace tpsim::render {
namespace {

/// libpng's simplified API: a description of the pixels, or false for a layout PNG cannot hold.
bool describe(const ImageLayout& layout, std::span<const uint8_t> pixels, png_image& image,
              std::string& error) {
    static constexpr png_uint_32 kFormats[] = {PNG_FORMAT_GRAY, PNG_FORMAT_GA, PNG_FORMAT_RGB,
                                               PNG_FORMAT_RGBA};
    if (layout.channels < 1 || layout.channels > 4 || layout.width <= 0 || layout.height <= 0 ||
        pixels.size() != size_t(layout.width) * size_t(layout.height) * size_t(layout.channels)) {
        error = "PNG holds 1 to 4 channels of at least one pixel, and the pixels must fill it";
        return false;
    }
    image = png_image{};
    image.version = PNG_IMAGE_VERSION;
    image.width = png_uint_32(layout.width);
    image.height = png_uint_32(layout.height);
    image.format = kFormats[layout.channels - 1];
    return true;
}

}  // namespace

bool is_png(const std::filesystem::path& path) {
    std::string extension = path.extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return extension == ".png";
}

std::string encode_png(const ImageLayout& layout, std::span<const uint8_t> pixels,
                       std::string& error) {
    png_image image;
    if (!describe(layout, pixels, image, error)) return {};
    // First the size, then the bytes (libpng's two-call form).
    png_alloc_size_t bytes = 0;
    if (png_image_write_to_memory(&image, nullptr, &bytes, 0, pixels.data(), 0, nullptr)) {
        std::string png(bytes, '\0');
        if (png_image_write_to_memory(&image, png.data(), &bytes, 0, pixels.data(), 0, nullptr)) {
            png.resize(bytes);
            return png;
        }
    }
    error = image.message;
    return {};
}

bool write_png(const std::filesystem::path& path, const ImageLayout& layout,
               std::span<const uint8_t> pixels, std::string& error) {
    const std::string png = encode_png(layout, pixels, error);
    if (png.empty()) return false;
    const std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "wb"),
                                                               std::fclose);
    if (!file || std::fwrite(png.data(), 1, png.size(), file.get()) != png.size() ||
        std::fflush(file.get()) != 0) {
        error = std::strerror(errno);
        return false;
    }
    return true;
}

}  // namespace tpsim::render
