#include "sim/render/png_file.hpp"

#include <png.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>
#include <vector>

#include "sim/core/file_extension.hpp"

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
    return lower_extension(path) == ".png";
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

bool read_plain_png(const std::filesystem::path& path, PixelType in_memory, Image& image) {
    png_image file{};
    file.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_file(&file, path.c_str())) return false;
    // Read as stored: anything libpng would convert (16 bits, alpha, a palette, a colour space
    // other than sRGB) is left to the image module, which reads the values unconverted.
    const bool plain = (file.format == PNG_FORMAT_GRAY || file.format == PNG_FORMAT_RGB) &&
                       (file.flags & PNG_IMAGE_FLAG_COLORSPACE_NOT_sRGB) == 0;
    const int channels = file.format == PNG_FORMAT_RGB ? 3 : 1;
    std::vector<uint8_t> bytes(plain ? PNG_IMAGE_SIZE(file) : 0);
    if (!plain || !png_image_finish_read(&file, nullptr, bytes.data(), 0, nullptr)) {
        png_image_free(&file);
        return false;
    }
    image.layout =
        ImageLayout{int(file.width), int(file.height), channels, PixelType::UInt8, {}, {}};
    if (in_memory == PixelType::Float) {
        image.floats.resize(bytes.size());
        std::transform(bytes.begin(), bytes.end(), image.floats.begin(),
                       [](uint8_t b) { return float(b) / 255.f; });
        image.bytes.clear();
    } else {
        image.bytes = std::move(bytes);
        image.floats.clear();
    }
    return true;
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
