// `tpsim check`: renders a kernel on an assignment's scenes on the simulated chip, compares each
// image with the committed reference, checks the budgets, and says what passed and why not.
#pragma once
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "sim/course/assignment.hpp"
#include "sim/render/render.hpp"

namespace tpsim::course {

/// One verdict: an image comparison or a budget, on one scene.
struct CheckResult {
    std::string scene;
    std::string what;  ///< "image", "budget", "run"
    bool passed = false;
    std::string detail;  ///< the measurement against the requirement, and the likely cause
};

struct CheckOptions {
    std::filesystem::path kernel;
    /// The ELF of the assignment's baseline kernel (Assignment::baseline), when it names one.
    std::filesystem::path baseline_kernel;
    std::filesystem::path output_dir = ".";  ///< the kernel's images and the difference images
    /// Write the kernel's images as the assignment's references instead of comparing (for the
    /// instructor, with the reference solution).
    bool update_references = false;
    /// Called when a scene starts rendering (index from 0) ...
    std::function<void(size_t index, const AssignmentScene&)> on_scene;
    /// ... when the baseline kernel starts rendering it (for budgets with a ratio) ...
    std::function<void(const AssignmentScene&)> on_baseline;
    /// ... while either renders on the chip model ...
    render::ProgressCallback on_progress;
    /// ... and for what the renders warn of (a scene's, an ELF older than its source).
    std::function<void(const std::string&)> on_warning;
};

struct CheckReport {
    std::vector<CheckResult> results;
    /// Files written, in order: the kernel's image and the difference image of each scene.
    std::vector<std::filesystem::path> files;
    bool passed() const;
};

/// How an image compares with its reference, on 8-bit sRGB values.
struct ImageComparison {
    double psnr = 0;             ///< dB; infinite when identical
    double differing_share = 0;  ///< pixels with a channel off by more than the tolerance
    double brighter_share = 0;   ///< of the differing pixels, those brighter than reference
    bool identical = false;
};

/// Compares two 8-bit RGB images of the same size (row-major, 3 bytes a pixel).
ImageComparison compare_rgb8(const std::vector<uint8_t>& image, const std::vector<uint8_t>& ref,
                             int tolerance);

/// Runs the whole check. Throws tpsim::Error for bad input (the kernel, the baseline kernel or a
/// scene cannot be loaded, a reference is missing or unreadable), the kernels and the references
/// before the first render; a kernel that faults or runs away fails.
CheckReport check(const Assignment& assignment, const CheckOptions& options);

}  // namespace tpsim::course
