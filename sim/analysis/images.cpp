#include "sim/analysis/images.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <vector>

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>
#include <fmt/format.h>

#include "sim/core/error.hpp"

namespace tpsim::analysis {
namespace {

struct Pixels {
    int width = 0, height = 0, channels = 0;
    bool linear = false;  ///< stored as floats (linear light), not as 8/16-bit encoded values
    std::vector<float> values;
};

/// Reads an image as floats exactly as stored (8-bit values scaled to 0..1); an error message
/// instead when it cannot be read.
std::optional<Pixels> read_pixels(const std::filesystem::path& path, std::string& error) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) {
        error = fmt::format("image {} does not exist", path.string());
        return std::nullopt;
    }
    auto in = OIIO::ImageInput::open(path.string());
    if (!in) {
        error = fmt::format("cannot read image {}: {}", path.string(), OIIO::geterror());
        return std::nullopt;
    }
    const OIIO::ImageSpec& spec = in->spec();
    Pixels p{spec.width, spec.height, spec.nchannels, spec.format.is_floating_point(), {}};
    p.values.resize(size_t(p.width) * p.height * p.channels);
    if (!in->read_image(0, 0, 0, p.channels, OIIO::TypeDesc::FLOAT, p.values.data())) {
        error = fmt::format("cannot read image {}: {}", path.string(), in->geterror());
        return std::nullopt;
    }
    return p;
}

}  // namespace

ImageDifference compare_images(const std::filesystem::path& a, const std::filesystem::path& b) {
    ImageDifference d;
    const std::optional<Pixels> pa = read_pixels(a, d.note);
    if (!pa) return d;
    const std::optional<Pixels> pb = read_pixels(b, d.note);
    if (!pb) return d;
    if (pa->width != pb->width || pa->height != pb->height || pa->channels != pb->channels) {
        d.note = fmt::format("images differ in size: {} is {}x{} ({} channels), {} is {}x{} ({} "
                             "channels)",
                             a.filename().string(), pa->width, pa->height, pa->channels,
                             b.filename().string(), pb->width, pb->height, pb->channels);
        return d;
    }
    d.pixels = uint64_t(pa->width) * uint64_t(pa->height);
    double squared_error = 0;
    for (uint64_t pixel = 0; pixel < d.pixels; ++pixel) {
        bool differs = false;
        for (int c = 0; c < pa->channels; ++c) {
            const size_t i = pixel * pa->channels + c;
            const double error = double(pa->values[i]) - double(pb->values[i]);
            squared_error += error * error;
            differs |= pa->values[i] != pb->values[i];
        }
        d.differing_pixels += differs;
    }
    const double samples = double(d.pixels) * pa->channels;
    d.rmse = samples > 0 ? std::sqrt(squared_error / samples) : 0;
    d.psnr = d.rmse > 0 ? 20 * std::log10(1 / d.rmse) : std::numeric_limits<double>::infinity();
    return d;
}

std::string png_bytes(const std::filesystem::path& path) {
    std::string error;
    if (path.extension() == ".png") {
        std::ifstream in(path, std::ios::binary);
        std::ostringstream bytes;
        bytes << in.rdbuf();
        if (in) return bytes.str();
    }
    const std::optional<Pixels> pixels = read_pixels(path, error);
    if (!pixels) throw Error(error);
    std::vector<unsigned char> out;
    OIIO::Filesystem::IOVecOutput proxy(out);
    OIIO::ImageSpec spec(pixels->width, pixels->height, pixels->channels, OIIO::TypeDesc::UINT8);
    auto writer = OIIO::ImageOutput::create("png");
    // Float images are linear: the PNG gets the sRGB curve, as `tpsim render` writes them.
    std::vector<unsigned char> encoded(pixels->values.size());
    for (size_t i = 0; i < encoded.size(); ++i) {
        float v = std::clamp(pixels->values[i], 0.0f, 1.0f);
        if (pixels->linear)
            v = v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1 / 2.4f) - 0.055f;
        encoded[i] = static_cast<unsigned char>(std::lround(v * 255));
    }
    if (!writer || !writer->set_ioproxy(&proxy) || !writer->open("image.png", spec) ||
        !writer->write_image(OIIO::TypeDesc::UINT8, encoded.data()) || !writer->close())
        throw Error(fmt::format("cannot convert image {} to PNG", path.string()));
    return std::string(out.begin(), out.end());
}

}  // namespace tpsim::analysis
