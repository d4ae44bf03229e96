#include "sim/render/srgb.hpp"

#include <cmath>

namespace tpsim::render {

uint8_t encode_srgb(float linear) {
    if (!(linear > 0.f)) return 0;  // also maps NaN to black
    if (linear >= 1.f) return 255;
    const float v =
        linear <= 0.0031308f ? 12.92f * linear : 1.055f * std::pow(linear, 1.f / 2.4f) - 0.055f;
    return uint8_t(std::lround(v * 255.f));
}

float decode_srgb(uint8_t value) {
    const float v = float(value) / 255.f;
    return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

}  // namespace tpsim::render
