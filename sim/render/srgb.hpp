// The sRGB transfer curve (IEC 61966-2-1) of 8-bit images: what every 8-bit image tpsim writes
// (renders, check verdicts, report pages) gets from linear values, and what reads undo.
#pragma once
#include <cstdint>

namespace tpsim::render {

/// Linear [0, 1] to 8 bits (clamped; NaN is black), and back.
uint8_t encode_srgb(float linear);
float decode_srgb(uint8_t value);

}  // namespace tpsim::render
