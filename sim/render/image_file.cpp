#include "sim/render/image_file.hpp"

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "sim/core/error.hpp"
#include "sim/core/file_extension.hpp"
#include "sim/core/output_directory.hpp"
#include "sim/render/image_codec.hpp"
#include "sim/render/srgb.hpp"

namespace tpsim::render {
namespace {

bool is_float_format(const std::filesystem::path& path) {
    const std::string extension = lower_extension(path);
    return extension == ".exr" || extension == ".hdr" || extension == ".pfm" ||
           extension == ".tif" || extension == ".tiff";
}

}  // namespace

void check_image_path(const std::filesystem::path& path) {
    if (!can_write_image(path.string())) {
        throw Error(fmt::format(
            "cannot write image '{}': {}; use .png, .exr, .tif, .ppm ...", path.string(),
            path.has_extension()
                ? fmt::format("no image format has the extension '{}'", path.extension().string())
                : std::string("the name has no image extension")));
    }
    require_output_directory(path, fmt::format("cannot write image '{}'", path.string()));
}

void write_image(const std::filesystem::path& path, std::span<const float> rgb, uint32_t width,
                 uint32_t height) {
    const bool linear = is_float_format(path);
    const ImageLayout file{int(width), int(height),
                           3,          linear ? PixelType::Float : PixelType::UInt8,
                           {},         {{"oiio:ColorSpace", linear ? "linear" : "sRGB"}}};
    std::string error;
    bool ok;
    if (linear) {
        ok = image_codec().write(path.string(), file, rgb, error);
    } else {
        std::vector<uint8_t> bytes(rgb.size());
        std::transform(rgb.begin(), rgb.end(), bytes.begin(), encode_srgb);
        ok = write_image_bytes(path.string(), file, std::span<const uint8_t>(bytes), error);
    }
    if (!ok) throw Error(fmt::format("cannot write image '{}': {}", path.string(), error));
}

std::vector<float> read_image(const std::filesystem::path& path, uint32_t& width,
                              uint32_t& height) {
    Image image;
    std::string error;
    if (!read_image_file(path.string(), PixelType::Float, image, error))
        throw Error(fmt::format("cannot read image '{}': {}", path.string(), error));
    const ImageLayout& layout = image.layout;
    if (layout.channels < 3)
        throw Error(fmt::format("cannot read image '{}': it has {} channels, not RGB",
                                path.string(), layout.channels));
    width = uint32_t(layout.width);
    height = uint32_t(layout.height);
    // The first three channels (alpha and beyond dropped).
    std::vector<float> rgb(size_t(width) * height * 3);
    for (size_t pixel = 0; pixel < size_t(width) * height; ++pixel)
        std::copy_n(image.floats.begin() + pixel * layout.channels, 3, rgb.begin() + pixel * 3);
    return rgb;
}

}  // namespace tpsim::render
