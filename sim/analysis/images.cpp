#include "sim/analysis/images.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <vector>

#include <fmt/format.h>

#include "sim/core/error.hpp"
#include "sim/render/image_codec.hpp"
#include "sim/render/png_file.hpp"
#include "sim/render/srgb.hpp"

namespace tpsim::analysis {
namespace {

using render::Image;

/// Reads an image as floats exactly as stored (8-bit values scaled to 0..1); an error message
/// instead when it cannot be read.
std::optional<Image> read_pixels(const std::filesystem::path& path, std::string& error) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) {
        error = fmt::format("image {} does not exist", path.string());
        return std::nullopt;
    }
    Image image;
    std::string why;
    if (!render::read_image_file(path.string(), render::PixelType::Float, image, why)) {
        error = fmt::format("cannot read image {}: {}", path.string(), why);
        return std::nullopt;
    }
    return image;
}

/// The difference image write_difference_images writes.
Rgb8 difference_image(const Rgb8& image, const Rgb8& ref, int tolerance) {
    Rgb8 out{ref.width, ref.height, std::vector<uint8_t>(ref.pixels.size())};
    for (size_t p = 0; p < ref.pixels.size(); p += 3) {
        int largest = 0, signed_sum = 0, grey = 0;
        for (int c = 0; c < 3; ++c) {
            const int d = int(image.pixels[p + c]) - int(ref.pixels[p + c]);
            largest = std::max(largest, std::abs(d));
            signed_sum += d;
            grey += ref.pixels[p + c];
        }
        uint8_t* d = &out.pixels[p];
        if (largest <= tolerance) {
            d[0] = d[1] = d[2] = uint8_t(grey / 3 / 4);
            continue;
        }
        const uint8_t strength = uint8_t(std::min(255, 128 + largest));
        d[0] = signed_sum > 0 ? strength : 0;
        d[1] = 0;
        d[2] = signed_sum > 0 ? 0 : strength;
    }
    return out;
}

/// The image with each pixel a `factor` x `factor` square, to see single pixels of a small
/// image on a screen.
Rgb8 enlarged(const Rgb8& image, int factor) {
    Rgb8 out{image.width * factor, image.height * factor, {}};
    out.pixels.resize(size_t(out.width) * out.height * 3);
    for (int y = 0; y < out.height; ++y)
        for (int x = 0; x < out.width; ++x)
            std::copy_n(&image.pixels[(size_t(y / factor) * image.width + x / factor) * 3], 3,
                        &out.pixels[(size_t(y) * out.width + x) * 3]);
    return out;
}

/// Difference images are enlarged to about this many pixels across.
constexpr int kEnlargedWidth = 512;

}  // namespace

ImageDifference compare_images(const std::filesystem::path& a, const std::filesystem::path& b) {
    ImageDifference d;
    const std::optional<Image> ia = read_pixels(a, d.note);
    if (!ia) return d;
    const std::optional<Image> ib = read_pixels(b, d.note);
    if (!ib) return d;
    const render::ImageLayout *pa = &ia->layout, *pb = &ib->layout;
    if (pa->width != pb->width || pa->height != pb->height || pa->channels != pb->channels) {
        d.note = fmt::format("images differ in size: {} is {}x{} ({} channels), {} is {}x{} ({} "
                             "channels)",
                             a.filename().string(), pa->width, pa->height, pa->channels,
                             b.filename().string(), pb->width, pb->height, pb->channels);
        return d;
    }
    d.pixels = uint64_t(pa->width) * uint64_t(pa->height);
    // OpenImageIO's comparison over the pixels as read.
    const render::PixelDifference r = render::image_codec().compare(*ia, *ib);
    d.rmse = r.rms_error;
    d.psnr = d.rmse > 0 ? r.psnr : std::numeric_limits<double>::infinity();
    d.differing_pixels = r.differing_pixels;
    return d;
}

std::string png_bytes(const std::filesystem::path& path) {
    std::string error;
    if (render::is_png(path)) {
        std::ifstream in(path, std::ios::binary);
        std::ostringstream bytes;
        bytes << in.rdbuf();
        if (in) return bytes.str();
    }
    const std::optional<Image> pixels = read_pixels(path, error);
    if (!pixels) throw Error(error);
    // Float images are linear: the PNG gets the sRGB curve, as `tpsim render` writes them.
    const bool linear = pixels->layout.type == render::PixelType::Float;
    std::vector<uint8_t> encoded(pixels->floats.size());
    for (size_t i = 0; i < encoded.size(); ++i) {
        const float v = pixels->floats[i];
        encoded[i] =
            linear ? render::encode_srgb(v) : uint8_t(std::lround(std::clamp(v, 0.0f, 1.0f) * 255));
    }
    std::string png = render::encode_png(pixels->layout, encoded, error);
    if (png.empty())
        throw Error(fmt::format("cannot convert image {} to PNG: {}", path.string(), error));
    return png;
}

Rgb8 read_rgb8(const std::filesystem::path& path, std::string_view what) {
    render::Image file;
    std::string error;
    if (!render::read_image_file(path.string(), render::PixelType::UInt8, file, error))
        throw Error(fmt::format("cannot read {} {}: {}", what, path.string(), error));
    const int channels = file.layout.channels;
    if (channels < 3)
        throw Error(fmt::format("cannot read {} {}: it must be an RGB image", what, path.string()));
    // Channels past the third (alpha) are dropped.
    Rgb8 image{file.layout.width, file.layout.height, {}};
    image.pixels.resize(size_t(image.width) * image.height * 3);
    for (size_t pixel = 0; pixel < size_t(image.width) * image.height; ++pixel)
        std::copy_n(file.bytes.begin() + pixel * channels, 3, image.pixels.begin() + pixel * 3);
    return image;
}

void write_rgb8(const std::filesystem::path& path, const Rgb8& image) {
    const render::ImageLayout layout{image.width, image.height, 3, render::PixelType::UInt8, {},
                                     {}};
    std::string error;
    if (!render::write_image_bytes(path.string(), layout, std::span<const uint8_t>(image.pixels),
                                   error))
        throw Error(fmt::format("cannot write image '{}': {}", path.string(), error));
}

std::vector<std::filesystem::path> write_difference_images(const Rgb8& image, const Rgb8& ref,
                                                           int tolerance,
                                                           const std::filesystem::path& stem) {
    const Rgb8 difference = difference_image(image, ref, tolerance);
    std::vector<std::filesystem::path> files{stem.string() + ".diff.png"};
    write_rgb8(files.back(), difference);
    if (const int factor = kEnlargedWidth / std::max(image.width, image.height); factor > 1) {
        files.push_back(fmt::format("{}.diff-x{}.png", stem.string(), factor));
        write_rgb8(files.back(), enlarged(difference, factor));
    }
    return files;
}

}  // namespace tpsim::analysis
