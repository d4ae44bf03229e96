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

}  // namespace tpsim::analysis
