// Images a statistics file names, for the analysis tools and the course checker: their
// difference in figures and as a picture, and PNG bytes to embed in a report.
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace tpsim::analysis {

/// How two images differ. When they cannot be compared (a file missing or unreadable, sizes or
/// channel counts differ), `note` says why in one line and the figures are zero.
struct ImageDifference {
    std::string note;
    double rmse = 0;                ///< over every channel of every pixel, values as stored
    double psnr = 0;                ///< dB against a peak of 1; infinite when identical
    uint64_t differing_pixels = 0;  ///< pixels with any channel not bit-equal
    uint64_t pixels = 0;
    bool compared() const { return note.empty(); }
    double differing_share() const {
        return pixels ? double(differing_pixels) / double(pixels) : 0;
    }
};

ImageDifference compare_images(const std::filesystem::path& a, const std::filesystem::path& b);

/// The image as PNG file bytes (a PNG file as it is; other formats converted through OIIO).
/// Throws tpsim::Error naming the file when it cannot be read.
std::string png_bytes(const std::filesystem::path& path);

/// An 8-bit RGB image.
struct Rgb8 {
    int width = 0, height = 0;
    std::vector<uint8_t> pixels;  ///< row-major, row 0 at the top, 3 bytes a pixel
};

/// Reads an image as 8-bit RGB (alpha dropped); throws tpsim::Error naming `what` and the file.
Rgb8 read_rgb8(const std::filesystem::path& path, std::string_view what);
void write_rgb8(const std::filesystem::path& path, const Rgb8& image);

/// Writes `image` against `ref` (same size) as a difference image at STEM.diff.png: pixels
/// within `tolerance` as a dim grey copy of the reference, the others red where `image` is
/// brighter and blue where it is darker, brighter the larger the difference. A small image also
/// gets an enlarged copy, STEM.diff-xN.png, about 512 pixels across. Returns the files written.
std::vector<std::filesystem::path> write_difference_images(const Rgb8& image, const Rgb8& ref,
                                                           int tolerance,
                                                           const std::filesystem::path& stem);

}  // namespace tpsim::analysis
