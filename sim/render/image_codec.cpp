#include "sim/render/image_codec.hpp"

#include "sim/core/module.hpp"
#include "sim/render/png_file.hpp"

namespace tpsim::render {

const ImageCodec& image_codec() {
    static const ImageCodec& codec = load_module<ImageCodec>(kImageCodecModule, kImageCodecEntry,
                                                             "the image module (OpenImageIO)");
    return codec;
}

bool read_image_file(const std::string& path, PixelType in_memory, Image& image,
                     std::string& error) {
    return read_plain_png(path, in_memory, image) ||
           image_codec().read(path, in_memory, image, error);
}

bool can_write_image(const std::string& path) {
    return is_png(path) || image_codec().can_write(path);
}

bool write_image_bytes(const std::string& path, const ImageLayout& file,
                       std::span<const uint8_t> pixels, std::string& error) {
    return is_png(path) ? write_png(path, file, pixels, error)
                        : image_codec().write(path, file, pixels, error);
}

}  // namespace tpsim::render
