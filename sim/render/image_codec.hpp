// The interface of the image module: what tpsim asks of OpenImageIO, loaded on first use
// (sim/core/module.hpp) so that commands without an image never load OpenImageIO's libraries,
// nor does a render that writes a PNG (png_file.hpp).
#pragma once
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace tpsim::render {

inline constexpr char kImageCodecModule[] = "libtpsim_oiio.so";
inline constexpr char kImageCodecEntry[] = "tpsim_image_codec";

enum class PixelType { UInt8, Float };

/// An image's size, channels and metadata. Pixels are row-major, row 0 at the top, channels
/// interleaved.
struct ImageLayout {
    int width = 0, height = 0, channels = 0;
    PixelType type = PixelType::Float;       ///< as stored in the file
    std::vector<std::string> channel_names;  ///< empty: the format's defaults (R, G, B ...)
    std::vector<std::pair<std::string, std::string>> attributes;  ///< e.g. oiio:ColorSpace
};

/// An image as read: every channel, in `floats` (8-bit values scaled to 0..1) or in `bytes`,
/// whichever the reader was asked for.
struct Image {
    ImageLayout layout;
    std::vector<float> floats;
    std::vector<uint8_t> bytes;
};

/// How two images of the same layout differ, over every channel of every pixel.
struct PixelDifference {
    double rms_error = 0;
    double psnr = 0;  ///< dB against a peak of 1
    uint64_t differing_pixels = 0;
};

enum class TextAlign { Left, Center, Right };

/// Operations return false (or an empty result) on failure with OpenImageIO's reason in `error`;
/// the callers say which file and what to do.
class ImageCodec {
public:
    /// True if a format with a writer has the file name's extension.
    virtual bool can_write(const std::string& path) const = 0;
    virtual bool read(const std::string& path, PixelType in_memory, Image& image,
                      std::string& error) const = 0;
    /// Writes the pixels (`file.channels` per pixel) converted to `file.type`. Files carry no
    /// time stamp, so the same pixels always give the same bytes.
    virtual bool write(const std::string& path, const ImageLayout& file,
                       std::span<const float> pixels, std::string& error) const = 0;
    virtual bool write(const std::string& path, const ImageLayout& file,
                       std::span<const uint8_t> pixels, std::string& error) const = 0;
    /// Both images hold floats in the same layout. One thread, so the sums are always added in
    /// the same order.
    virtual PixelDifference compare(const Image& a, const Image& b) const = 0;
    /// Width in pixels of `text` in font `font` at `size`; 0 when the font cannot be loaded.
    virtual int text_width(const std::string& text, int size, const std::string& font) const = 0;
    /// Draws `text` into float RGB pixels, its baseline at y, anchored at x per `align`.
    virtual bool draw_text(std::span<float> rgb, int width, int height, int x, int y,
                           const std::string& text, int size, const std::string& font,
                           const std::array<float, 3>& colour, TextAlign align,
                           std::string& error) const = 0;
    virtual std::string base64(std::string_view bytes) const = 0;

protected:
    ~ImageCodec() = default;
};

/// The image module, loaded on the first call; throws tpsim::Error if it cannot be loaded.
const ImageCodec& image_codec();

/// Reads an image as ImageCodec::read does: a plain PNG with libpng (png_file.hpp), without
/// loading the image module; any other file through the module.
bool read_image_file(const std::string& path, PixelType in_memory, Image& image,
                     std::string& error);
/// Whether an image can be written at `path` (its extension): a PNG always (png_file.hpp),
/// another format if the image module has a writer for it.
bool can_write_image(const std::string& path);
/// Writes 8-bit pixels as ImageCodec::write does: a PNG with libpng, without loading the image
/// module; another format through the module.
bool write_image_bytes(const std::string& path, const ImageLayout& file,
                       std::span<const uint8_t> pixels, std::string& error);

}  // namespace tpsim::render
