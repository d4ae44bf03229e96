// Writes a rendered framebuffer to disk: a PNG with libpng, other formats through the image
// module (OpenImageIO).
#pragma once
#include <cstdint>
#include <filesystem>
#include <span>
#include <vector>

namespace tpsim::render {

/// Writes linear RGB floats (row 0 at the top). The file type follows the extension: float
/// formats (.exr, .hdr, .pfm, .tif) keep linear values; 8-bit formats (.png, .jpg, .ppm ...) get
/// the sRGB transfer curve, clamped to [0, 1]. Throws tpsim::Error naming the path on failure.
void write_image(const std::filesystem::path& path, std::span<const float> rgb, uint32_t width,
                 uint32_t height);

/// Throws tpsim::Error unless an image could be written at `path`: a known image extension and
/// an existing directory. Called before a render so a long run cannot end in a bad path.
void check_image_path(const std::filesystem::path& path);

/// Reads an image back as RGB floats exactly as stored (for tests and comparisons).
std::vector<float> read_image(const std::filesystem::path& path, uint32_t& width, uint32_t& height);

}  // namespace tpsim::render
