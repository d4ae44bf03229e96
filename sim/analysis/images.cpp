#include "sim/analysis/images.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <vector>

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imagebufalgo.h>
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
    std::optional<Pixels> pa = read_pixels(a, d.note);
    if (!pa) return d;
    std::optional<Pixels> pb = read_pixels(b, d.note);
    if (!pb) return d;
    if (pa->width != pb->width || pa->height != pb->height || pa->channels != pb->channels) {
        d.note = fmt::format("images differ in size: {} is {}x{} ({} channels), {} is {}x{} ({} "
                             "channels)",
                             a.filename().string(), pa->width, pa->height, pa->channels,
                             b.filename().string(), pb->width, pb->height, pb->channels);
        return d;
    }
    d.pixels = uint64_t(pa->width) * uint64_t(pa->height);
    // OpenImageIO's comparison over the pixels as read (wrapped, not copied). One thread: the
    // sums are then added in one order, so the same images always give the same figures. A
    // failure threshold of 0 counts the pixels with any channel not equal.
    const auto wrap = [](Pixels& p) {
        return OIIO::ImageBuf(OIIO::ImageSpec(p.width, p.height, p.channels, OIIO::TypeDesc::FLOAT),
                              p.values.data());
    };
    const OIIO::ImageBufAlgo::CompareResults r =
        OIIO::ImageBufAlgo::compare(wrap(*pa), wrap(*pb), 0.0f, 0.0f, OIIO::ROI::All(), 1);
    d.rmse = r.rms_error;
    d.psnr = d.rmse > 0 ? r.PSNR : std::numeric_limits<double>::infinity();
    d.differing_pixels = r.nfail;
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
