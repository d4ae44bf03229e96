// PNG with libpng, in tpsim itself: the format every render writes and every report embeds, so
// writing one need not load the image module (OpenImageIO and its ~260 libraries take ~0.35 s to
// load). 8 bits per channel; 1 to 4 channels (grey, grey and alpha, RGB, RGBA), marked sRGB.
// No time stamp: the same pixels always give the same bytes.
#pragma once
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>

#include "sim/render/image_codec.hpp"

namespace tpsim::render {

/// True if the path's extension is .png (any case).
bool is_png(const std::filesystem::path& path);

/// The pixels (`layout.channels` per pixel, row 0 at the top) as PNG file bytes; empty with
/// libpng's reason in `error` on failure.
std::string encode_png(const ImageLayout& layout, std::span<const uint8_t> pixels,
                       std::string& error);

/// Writes the pixels to a PNG file; false with the reason in `error` on failure.
bool write_png(const std::filesystem::path& path, const ImageLayout& layout,
               std::span<const uint8_t> pixels, std::string& error);

}  // namespace tpsim::render
