// Images a statistics file names, for the analysis tools: their difference, and PNG bytes to
// embed in a report.
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>

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

}  // namespace tpsim::analysis
