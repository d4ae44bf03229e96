// PNG with libpng (sim/render/png_file.hpp): what it writes reads back through OpenImageIO pixel
// for pixel, the same pixels give the same bytes, bad layouts and paths give reasons, a render's
// PNG is written and a plain PNG read without loading the image module, and what libpng would
// convert is left to the module.
#include <fstream>
#include <iterator>
#include <numeric>

#include <fmt/format.h>

#include <OpenImageIO/imageio.h>
#include <catch2/catch.hpp>

#include "sim/render/image_file.hpp"
#include "sim/render/png_file.hpp"
#include "sim/render/srgb.hpp"
#include "tests/scratch.hpp"

using namespace tpsim::render;
using tpsim::testing::scratch_path;

namespace {

/// Bytes that differ from pixel to pixel and channel to channel.
std::vector<uint8_t> pattern(const ImageLayout& layout) {
    std::vector<uint8_t> pixels(size_t(layout.width) * layout.height * layout.channels);
    for (size_t i = 0; i < pixels.size(); ++i)
        pixels[i] = uint8_t(i * 37 + 11);
    return pixels;
}

std::string file_bytes(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), {}};
}

/// Whether the image module has been loaded into this process.
bool image_module_loaded() {
    std::ifstream maps("/proc/self/maps");
    const std::string all{std::istreambuf_iterator<char>(maps), {}};
    return all.find(kImageCodecModule) != std::string::npos;
}

}  // namespace

TEST_CASE("png: every channel count (grey to RGBA) reads back exactly through OpenImageIO") {
    for (int channels = 1; channels <= 4; ++channels) {
        CAPTURE(channels);
        const ImageLayout layout{5, 3, channels, PixelType::UInt8, {}, {}};
        const std::vector<uint8_t> pixels = pattern(layout);
        const auto path = scratch_path(fmt::format("c{}.png", channels));
        std::string error;
        REQUIRE(write_png(path, layout, pixels, error));
        // As stored: OpenImageIO would otherwise multiply the colours by the alpha.
        OIIO::ImageSpec config;
        config.attribute("oiio:UnassociatedAlpha", 1);
        auto in = OIIO::ImageInput::open(path.string(), &config);
        REQUIRE(in);
        CHECK(in->spec().width == 5);
        CHECK(in->spec().height == 3);
        REQUIRE(in->spec().nchannels == channels);
        std::vector<uint8_t> back(pixels.size());
        REQUIRE(in->read_image(0, 0, 0, channels, OIIO::TypeDesc::UINT8, back.data()));
        CHECK(back == pixels);
        CHECK(in->spec().get_string_attribute("oiio:ColorSpace") == "sRGB");
    }
}

TEST_CASE("png: the same pixels give the same bytes in memory and in a file") {
    const ImageLayout layout{16, 9, 3, PixelType::UInt8, {}, {}};
    const std::vector<uint8_t> pixels = pattern(layout);
    std::string error;
    const std::string once = encode_png(layout, pixels, error);
    REQUIRE(!once.empty());
    CHECK(once.compare(1, 3, "PNG") == 0);
    CHECK(encode_png(layout, pixels, error) == once);
    REQUIRE(write_png(scratch_path("same.png"), layout, pixels, error));
    CHECK(file_bytes(scratch_path("same.png")) == once);
}

TEST_CASE("png: a layout PNG cannot hold and a path that cannot be written give reasons") {
    std::string error;
    const std::vector<uint8_t> six(6);
    CHECK(encode_png({1, 1, 6, PixelType::UInt8, {}, {}}, six, error).empty());
    CHECK_THAT(error, Catch::Contains("1 to 4 channels"));
    error.clear();
    CHECK(encode_png({2, 2, 3, PixelType::UInt8, {}, {}}, six, error).empty());  // 12 bytes due
    CHECK_THAT(error, Catch::Contains("fill"));
    error.clear();
    const std::vector<uint8_t> rgb(3);
    CHECK_FALSE(
        write_png("/nonexistent-tpsim-dir/x.png", {1, 1, 3, PixelType::UInt8, {}, {}}, rgb, error));
    CHECK_THAT(error, Catch::Contains("No such file"));
}

TEST_CASE("png: a render's PNG is checked and written without loading the image module") {
    CHECK(is_png("frame.PNG"));
    CHECK_FALSE(is_png("frame.exr"));
    const auto path = scratch_path("render.png");
    check_image_path(path);
    std::vector<float> rgb(4 * 2 * 3);
    std::iota(rgb.begin(), rgb.end(), 0.f);
    for (float& v : rgb)
        v /= float(rgb.size());
    write_image(path, rgb, 4, 2);
    // Read back: the sRGB curve of each value.
    uint32_t width = 0, height = 0;
    const std::vector<float> back = read_image(path, width, height);
    REQUIRE((width == 4 && height == 2));
    for (size_t i = 0; i < rgb.size(); ++i)
        CHECK(back[i] == Approx(float(encode_srgb(rgb[i])) / 255.f));
    CHECK_FALSE(image_module_loaded());
}

TEST_CASE("png: a plain PNG reads back as stored without loading the image module") {
    for (int channels : {1, 3}) {
        CAPTURE(channels);
        const ImageLayout layout{7, 2, channels, PixelType::UInt8, {}, {}};
        const std::vector<uint8_t> pixels = pattern(layout);
        const auto path = scratch_path(fmt::format("plain{}.png", channels));
        std::string error;
        REQUIRE(write_png(path, layout, pixels, error));
        Image bytes, floats;
        REQUIRE(read_image_file(path.string(), PixelType::UInt8, bytes, error));
        REQUIRE(read_image_file(path.string(), PixelType::Float, floats, error));
        CHECK((bytes.layout.width == 7 && bytes.layout.height == 2));
        CHECK(bytes.layout.channels == channels);
        CHECK(bytes.layout.type == PixelType::UInt8);
        CHECK(bytes.bytes == pixels);
        REQUIRE(floats.floats.size() == pixels.size());
        for (size_t i = 0; i < pixels.size(); ++i)
            CHECK(floats.floats[i] == float(pixels[i]) / 255.f);
    }
    CHECK_FALSE(image_module_loaded());
}

TEST_CASE("png: what libpng would convert is read by the image module, values as stored") {
    // RGBA (libpng's simplified reader would keep the alpha apart; the module is the reference),
    // and a PNG written by OpenImageIO (gAMA, cHRM and sRGB chunks: still read by libpng) whose
    // values must equal the module's.
    const ImageLayout rgba{3, 3, 4, PixelType::UInt8, {}, {}};
    const auto rgba_path = scratch_path("rgba.png");
    std::string error;
    REQUIRE(write_png(rgba_path, rgba, pattern(rgba), error));
    Image image;
    CHECK_FALSE(read_plain_png(rgba_path, PixelType::UInt8, image));
    CHECK(image.layout.width == 0);  // untouched
    CHECK_FALSE(read_plain_png(scratch_path("missing.png"), PixelType::UInt8, image));

    const ImageLayout rgb{4, 4, 3, PixelType::UInt8, {}, {}};
    const std::vector<uint8_t> pixels = pattern(rgb);
    const auto oiio_path = scratch_path("oiio.png");
    auto out = OIIO::ImageOutput::create(oiio_path.string());
    REQUIRE(out);
    OIIO::ImageSpec spec(4, 4, 3, OIIO::TypeDesc::UINT8);
    spec.attribute("oiio:ColorSpace", "sRGB");
    REQUIRE(out->open(oiio_path.string(), spec));
    REQUIRE(out->write_image(OIIO::TypeDesc::UINT8, pixels.data()));
    REQUIRE(out->close());
    REQUIRE(read_plain_png(oiio_path, PixelType::UInt8, image));
    CHECK(image.bytes == pixels);
    Image through_module;
    REQUIRE(image_codec().read(oiio_path.string(), PixelType::UInt8, through_module, error));
    CHECK(through_module.bytes == image.bytes);
}
