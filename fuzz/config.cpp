// Fuzzes the chip-config parser (sim/timing/config.cpp) with the input as a config file's text.
#include <cstdint>
#include <string_view>

#include "sim/core/error.hpp"
#include "sim/timing/config.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    try {
        tpsim::timing::parse_config(std::string_view(reinterpret_cast<const char*>(data), size),
                                    "fuzz.toml");
    } catch (const tpsim::Error&) {
        // A clean rejection: the expected outcome for almost every input.
    }
    return 0;
}
