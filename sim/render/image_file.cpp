#include "sim/render/image_file.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>
#include <fmt/format.h>

#include "sim/core/error.hpp"
#include "sim/core/output_directory.hpp"

namespace tpsim::render {
namespace {

bool is_float_format(std::string extension) {
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return extension == ".exr" || extension == ".hdr" || extension == ".pfm" ||
           extension == ".tif" || extension == ".tiff";
}

}  // namespace

uint8_t encode_srgb(float linear) {
    if (!(linear > 0.f)) return 0;  // also maps NaN to black
    if (linear >= 1.f) return 255;
    const float v =
        linear <= 0.0031308f ? 12.92f * linear : 1.055f * std::pow(linear, 1.f / 2.4f) - 0.055f;
    return uint8_t(std::lround(v * 255.f));
}

float decode_srgb(uint8_t value) {
    const float v = float(value) / 255.f;
    return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

void check_image_path(const std::filesystem::path& path) {
    if (!OIIO::ImageOutput::create(path.string())) {
        OIIO::geterror();  // consumed here: the message below says it better
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
    auto out = OIIO::ImageOutput::create(path.string());
    if (!out)
        throw Error(fmt::format("cannot write image '{}': {} (use .png, .exr, .tif, .ppm ...)",
                                path.string(), OIIO::geterror()));
    const bool linear = is_float_format(path.extension().string());
    OIIO::ImageSpec spec(int(width), int(height), 3,
                         linear ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8);
    spec.attribute("oiio:ColorSpace", linear ? "linear" : "sRGB");
    // OpenImageIO stamps TIFF and EXR files with the current time unless DateTime is given;
    // empty leaves it out, so the same render gives the same bytes.
    spec.attribute("DateTime", "");
    bool ok = out->open(path.string(), spec);
    if (ok && linear) {
        ok = out->write_image(OIIO::TypeDesc::FLOAT, rgb.data());
    } else if (ok) {
        std::vector<uint8_t> bytes(rgb.size());
        std::transform(rgb.begin(), rgb.end(), bytes.begin(), encode_srgb);
        ok = out->write_image(OIIO::TypeDesc::UINT8, bytes.data());
    }
    if (!ok || !out->close())
        throw Error(fmt::format("cannot write image '{}': {}", path.string(), out->geterror()));
}

std::vector<float> read_image(const std::filesystem::path& path, uint32_t& width,
                              uint32_t& height) {
    auto in = OIIO::ImageInput::open(path.string());
    if (!in)
        throw Error(fmt::format("cannot read image '{}': {}", path.string(), OIIO::geterror()));
    const OIIO::ImageSpec& spec = in->spec();
    width = uint32_t(spec.width);
    height = uint32_t(spec.height);
    std::vector<float> rgb(size_t(width) * height * 3);
    if (!in->read_image(0, 0, 0, 3, OIIO::TypeDesc::FLOAT, rgb.data()))
        throw Error(fmt::format("cannot read image '{}': {}", path.string(), in->geterror()));
    return rgb;
}

}  // namespace tpsim::render
