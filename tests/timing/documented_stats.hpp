// The statistic keys docs/statistics.md documents, for the tests that every registered key is
// documented.
#pragma once
#include <fstream>
#include <regex>
#include <string>
#include <vector>

/// Every backticked key containing '/' in docs/statistics.md, as a regex in which a
/// <placeholder> segment matches any one segment. Empty if the file cannot be read.
inline std::vector<std::regex> documented_stat_patterns() {
    std::ifstream doc(std::string(TPSIM_DOCS_DIR) + "/statistics.md");
    std::vector<std::regex> documented;
    const std::regex quoted("`([A-Za-z0-9_<>.-]+/[A-Za-z0-9_<>/.-]+)`");
    for (std::string line; std::getline(doc, line);)
        for (std::sregex_iterator m(line.begin(), line.end(), quoted), end; m != end; ++m)
            documented.emplace_back(
                std::regex_replace((*m)[1].str(), std::regex("<[^>]+>"), "[^/]+"));
    return documented;
}
