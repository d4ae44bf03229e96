#include "sim/render/kernel_params.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <string_view>

#include <fmt/format.h>

#include "sim/core/error.hpp"

namespace tpsim::render {
namespace {

constexpr std::string_view kPrefix = "trax_param_";

/// The bytes of `address` in the program's writable segments (zero past the file bytes: .bss).
uint8_t* param_bytes(core::Program& program, uint32_t address) {
    for (core::Segment& segment : program.segments)
        if (segment.writable && segment.contains(address) && segment.contains(address + 3)) {
            const size_t end = size_t(address - segment.vaddr) + 4;
            if (segment.bytes.size() < end) segment.bytes.resize(end, 0);
            return segment.bytes.data() + (address - segment.vaddr);
        }
    return nullptr;
}

std::string listing(const std::vector<KernelParam>& params) {
    std::string text;
    for (const KernelParam& p : params)
        text += fmt::format("{}{} ({}, default {})", text.empty() ? "" : ", ", p.name,
                            p.type_name(), p.text(p.default_bits));
    return text;
}

/// Reads `value` as a number of the parameter's type into `bits`; false when it is not one.
bool parse_value(const KernelParam& p, std::string_view value, uint32_t& bits) {
    const char* end = value.data() + value.size();
    if (p.type == KernelParam::Type::float32) {
        float f = 0;
        const auto [at, error] = std::from_chars(value.data(), end, f);
        if (error != std::errc{} || at != end || !std::isfinite(f)) return false;
        std::memcpy(&bits, &f, 4);
        return true;
    }
    int32_t i = 0;
    const auto [at, error] = std::from_chars(value.data(), end, i);
    if (error != std::errc{} || at != end) return false;
    std::memcpy(&bits, &i, 4);
    return true;
}

}  // namespace

std::string KernelParam::symbol() const {
    return fmt::format("{}{}_{}", kPrefix, type_name(), name);
}

std::string KernelParam::text(uint32_t value_bits) const {
    if (type == Type::int32) return std::to_string(int32_t(value_bits));
    float f;
    std::memcpy(&f, &value_bits, 4);
    return fmt::format("{}", f);
}

std::vector<KernelParam> kernel_params(const core::Program& program) {
    std::vector<KernelParam> params;
    for (const core::Symbol& symbol : program.objects) {
        if (!symbol.name.starts_with(kPrefix)) continue;
        const std::string_view rest = std::string_view(symbol.name).substr(kPrefix.size());
        KernelParam p;
        const bool is_float = rest.starts_with("float_"), is_int = rest.starts_with("int_");
        p.type = is_float ? KernelParam::Type::float32 : KernelParam::Type::int32;
        p.name = std::string(rest.substr(is_float ? 6 : 4));
        p.address = symbol.address;
        const core::Segment* segment = program.segment_at(symbol.address);
        if ((!is_float && !is_int) || p.name.empty() || symbol.size != 4 ||
            symbol.address % 4 != 0 || !segment || !segment->contains(symbol.address + 3))
            throw Error(fmt::format("{}: symbol {} looks like a kernel parameter but is not one "
                                    "TRAX_PARAM makes (4 aligned bytes named "
                                    "trax_param_float_NAME or trax_param_int_NAME); declare "
                                    "parameters with TRAX_PARAM(float|int, NAME, DEFAULT)",
                                    program.name, symbol.name));
        const size_t offset = symbol.address - segment->vaddr;
        if (offset + 4 <= segment->bytes.size())
            std::memcpy(&p.default_bits, segment->bytes.data() + offset, 4);
        p.bits = p.default_bits;
        params.push_back(std::move(p));
    }
    std::sort(params.begin(), params.end(),
              [](const KernelParam& a, const KernelParam& b) { return a.name < b.name; });
    return params;
}

void set_params(std::vector<KernelParam>& params, const std::vector<std::string>& assignments,
                const std::string& kernel) {
    std::vector<std::string> given;
    for (const std::string& assignment : assignments) {
        const size_t equals = assignment.find('=');
        if (equals == std::string::npos || equals == 0)
            throw Error(fmt::format("kernel parameter '{}': write NAME=VALUE, e.g. "
                                    "threshold=0.02",
                                    assignment));
        const std::string name = assignment.substr(0, equals);
        const std::string_view value = std::string_view(assignment).substr(equals + 1);
        const auto p = std::find_if(params.begin(), params.end(),
                                    [&](const KernelParam& q) { return q.name == name; });
        if (p == params.end())
            throw Error(fmt::format(
                "kernel parameter {}: {} has no parameter '{}'; {}", assignment, kernel, name,
                params.empty() ? "it declares none (TRAX_PARAM in kernel/trax.hpp, "
                                 "docs/kernel-api.md)"
                               : "its parameters: " + listing(params)));
        if (std::find(given.begin(), given.end(), name) != given.end())
            throw Error(fmt::format("kernel parameter '{}' is given twice; give it once", name));
        given.push_back(name);
        if (!parse_value(*p, value, p->bits))
            throw Error(fmt::format("kernel parameter {}: '{}' of {} is {}, got '{}'; e.g. {}={}",
                                    assignment, name, kernel,
                                    p->type == KernelParam::Type::float32
                                        ? "a float: give a finite number"
                                        : "an int: give a whole number in "
                                          "[-2147483648, 2147483647]",
                                    value, name, p->text(p->default_bits)));
        p->set = true;
    }
}

void write_params(core::Program& program, const std::vector<KernelParam>& params) {
    for (const KernelParam& p : params) {
        uint8_t* bytes = param_bytes(program, p.address);
        if (bytes == nullptr)
            throw Error(fmt::format("{}: parameter {} at {:#010x} is not in a writable segment",
                                    program.name, p.name, p.address));
        std::memcpy(bytes, &p.bits, 4);
    }
}

std::string describe_params(const std::vector<KernelParam>& params) {
    std::string text;
    for (const KernelParam& p : params)
        text += fmt::format("{}{}={}", text.empty() ? "" : ", ", p.name, p.text());
    return text;
}

}  // namespace tpsim::render
