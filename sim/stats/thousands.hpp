// Counts as a person reads them in reports: "1,234,567".
#pragma once
#include <string>
#include <string_view>

namespace tpsim::stats {

/// `integer` (digits with an optional leading '-') with a ',' between groups of three digits.
inline std::string with_thousands(std::string_view integer) {
    const size_t sign = !integer.empty() && integer[0] == '-' ? 1 : 0;
    const size_t digits = integer.size() - sign;
    std::string grouped(integer.substr(0, sign));
    for (size_t i = 0; i < digits; ++i) {
        if (i > 0 && (digits - i) % 3 == 0) grouped += ',';
        grouped += integer[sign + i];
    }
    return grouped;
}

}  // namespace tpsim::stats
