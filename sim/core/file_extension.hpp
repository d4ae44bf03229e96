// A file name's extension as the formats are matched: lower case (".PNG" is a PNG).
#pragma once
#include <algorithm>
#include <cctype>
#include <filesystem>
#include <string>

namespace tpsim {

/// The extension of `path` with its dot, in lower case; empty if it has none.
inline std::string lower_extension(const std::filesystem::path& path) {
    std::string extension = path.extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return extension;
}

}  // namespace tpsim
