// The image module (libtpsim_oiio.so): reads, writes, compares and annotates images with
// OpenImageIO. Loaded on first use through image_codec() (image_codec.cpp).
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>
#include <OpenImageIO/strutil.h>

#include "sim/render/image_codec.hpp"

namespace tpsim::render {
namespace {

OIIO::TypeDesc type_desc(PixelType type) {
    return type == PixelType::Float ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8;
}

OIIO::ImageSpec spec_of(const ImageLayout& layout) {
    OIIO::ImageSpec spec(layout.width, layout.height, layout.channels, type_desc(layout.type));
    if (!layout.channel_names.empty()) spec.channelnames = layout.channel_names;
    for (const auto& [name, value] : layout.attributes)
        spec.attribute(name, value);
    // OpenImageIO stamps TIFF and EXR files with the current time unless DateTime is given;
    // empty leaves it out, so the same pixels give the same bytes.
    spec.attribute("DateTime", "");
    return spec;
}

class OiioImageCodec final : public ImageCodec {
public:
    bool can_write(const std::string& path) const override {
        const bool known = OIIO::ImageOutput::create(path) != nullptr;
        if (!known) OIIO::geterror();  // consumed: the caller's message says it better
        return known;
    }

    bool read(const std::string& path, PixelType in_memory, Image& image,
              std::string& error) const override {
        auto in = OIIO::ImageInput::open(path);
        if (!in) {
            error = OIIO::geterror();
            return false;
        }
        const OIIO::ImageSpec& spec = in->spec();
        image.layout =
            ImageLayout{spec.width,
                        spec.height,
                        spec.nchannels,
                        spec.format.is_floating_point() ? PixelType::Float : PixelType::UInt8,
                        {},
                        {}};
        const size_t values = size_t(spec.width) * spec.height * spec.nchannels;
        void* pixels;
        if (in_memory == PixelType::Float) {
            image.floats.resize(values);
            pixels = image.floats.data();
        } else {
            image.bytes.resize(values);
            pixels = image.bytes.data();
        }
        if (!in->read_image(0, 0, 0, spec.nchannels, type_desc(in_memory), pixels)) {
            error = in->geterror();
            return false;
        }
        return true;
    }

    bool write(const std::string& path, const ImageLayout& file, std::span<const float> pixels,
               std::string& error) const override {
        return write_pixels(path, file, OIIO::TypeDesc::FLOAT, pixels.data(), error);
    }

    bool write(const std::string& path, const ImageLayout& file, std::span<const uint8_t> pixels,
               std::string& error) const override {
        return write_pixels(path, file, OIIO::TypeDesc::UINT8, pixels.data(), error);
    }

    PixelDifference compare(const Image& a, const Image& b) const override {
        // Wrapped, not copied. A failure threshold of 0 counts the pixels with any channel not
        // equal.
        const auto wrap = [](const Image& image) {
            const ImageLayout& l = image.layout;
            return OIIO::ImageBuf(
                OIIO::ImageSpec(l.width, l.height, l.channels, OIIO::TypeDesc::FLOAT),
                const_cast<float*>(image.floats.data()));
        };
        const OIIO::ImageBufAlgo::CompareResults r =
            OIIO::ImageBufAlgo::compare(wrap(a), wrap(b), 0.0f, 0.0f, OIIO::ROI::All(), 1);
        return {r.rms_error, r.PSNR, uint64_t(r.nfail)};
    }

    int text_width(const std::string& text, int size, const std::string& font) const override {
        const OIIO::ROI roi = OIIO::ImageBufAlgo::text_size(text, size, font);
        return roi.defined() ? roi.width() : 0;
    }

    bool draw_text(std::span<float> rgb, int width, int height, int x, int y,
                   const std::string& text, int size, const std::string& font,
                   const std::array<float, 3>& colour, TextAlign align,
                   std::string& error) const override {
        OIIO::ImageBuf canvas(OIIO::ImageSpec(width, height, 3, OIIO::TypeDesc::FLOAT), rgb.data());
        const auto align_x = align == TextAlign::Left     ? OIIO::ImageBufAlgo::TextAlignX::Left
                             : align == TextAlign::Center ? OIIO::ImageBufAlgo::TextAlignX::Center
                                                          : OIIO::ImageBufAlgo::TextAlignX::Right;
        if (OIIO::ImageBufAlgo::render_text(canvas, x, y, text, size, font, colour, align_x))
            return true;
        error = canvas.geterror();
        return false;
    }

    std::string base64(std::string_view bytes) const override {
        return OIIO::Strutil::base64_encode(bytes);
    }

private:
    static bool write_pixels(const std::string& path, const ImageLayout& file,
                             OIIO::TypeDesc in_memory, const void* pixels, std::string& error) {
        auto out = OIIO::ImageOutput::create(path);
        if (!out) {
            error = OIIO::geterror();
            return false;
        }
        if (!out->open(path, spec_of(file)) || !out->write_image(in_memory, pixels) ||
            !out->close()) {
            error = out->geterror();
            return false;
        }
        return true;
    }
};

}  // namespace
}  // namespace tpsim::render

extern "C" const void* tpsim_image_codec() {
    static const tpsim::render::OiioImageCodec codec;
    return &codec;
}
