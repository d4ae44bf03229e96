// PNG with libpng, in tpsim itself: the format every render writes, every report embeds and the
// course's reference images are in, so these need not load the image module (OpenImageIO and its
// ~260 libraries take ~0.35 s to load). Written: 8 bits per channel, 1 to 4 channels (grey, grey
// and alpha, RGB, RGBA), marked sRGB, no time stamp (the same pixels always give the same
// bytes). Read: the plain PNGs tpsim writes; the image module reads the others.
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

/// Reads a plain PNG — 8 bits, grey or RGB, no palette, no alpha, sRGB or no colour space said —
/// as stored (floats are the bytes / 255), as the image module reads it. Returns false, `image`
/// untouched, for any other file (another kind of PNG, not a PNG, unreadable): the image module
/// then reads it, or says what is wrong.
bool read_plain_png(const std::filesystem::path& path, PixelType in_memory, Image& image);

/// Writes the pixels to a PNG file; false with the reason in `error` on failure.
bool write_png(const std::filesystem::path& path, const ImageLayout& layout,
               std::span<const uint8_t> pixels, std::string& error);

}  // namespace tpsim::render
