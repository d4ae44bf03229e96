// The one exception type of tpsim: a single line saying what went wrong, where, and how to fix it.
#pragma once
#include <stdexcept>
#include <string>

namespace tpsim {

/// Thrown for every user-facing error (bad input files, bad options, guest faults).
/// what() is one line without a trailing newline; the command prefixes it with "tpsim: ".
class Error : public std::runtime_error {
public:
    explicit Error(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace tpsim
