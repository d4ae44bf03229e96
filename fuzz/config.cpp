// Fuzzes the chip-config parser (sim/timing/config.cpp): the input as a config file's text, and
// each of its first lines as a --set override.
#include <algorithm>
#include <cstdint>
#include <string_view>

#include "sim/core/error.hpp"
#include "sim/timing/config.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    try {
        tpsim::timing::parse_config(text, "fuzz.toml");
    } catch (const tpsim::Error&) {
        // A clean rejection: the expected outcome for almost every input.
    }
    tpsim::timing::ChipConfig config;
    size_t start = 0;
    for (int line = 0; line < 8 && start < text.size(); ++line) {
        const size_t end = std::min(text.find('\n', start), text.size());
        try {
            tpsim::timing::apply_override(config, text.substr(start, end - start));
        } catch (const tpsim::Error&) {
        }
        start = end + 1;
    }
    return 0;
}
