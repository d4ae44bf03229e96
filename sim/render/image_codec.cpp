#include "sim/render/image_codec.hpp"

#include "sim/core/module.hpp"

namespace tpsim::render {

const ImageCodec& image_codec() {
    static const ImageCodec& codec = load_module<ImageCodec>(kImageCodecModule, kImageCodecEntry,
                                                             "the image module (OpenImageIO)");
    return codec;
}

}  // namespace tpsim::render
