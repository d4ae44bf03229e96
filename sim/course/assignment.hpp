// A course assignment as `tpsim check` sees it: course/assignments/<N-name>/assignment.toml
// (docs/course/README.md#assignmenttoml): the scenes a kernel is rendered on, how close its
// images must come to the committed references, and the budgets its statistics must meet.
#pragma once
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace tpsim::course {

/// One scene the kernel renders, and the image it must reproduce.
struct AssignmentScene {
    std::string name;                 ///< short, used in messages and output file names
    std::filesystem::path file;       ///< scene file (absolute once loaded)
    std::filesystem::path reference;  ///< committed reference PNG (absolute once loaded)
};

/// A statistic of the render that must stay within limits, e.g. at most so many cycles per pixel.
struct Budget {
    std::string stat;  ///< a statistics key (docs/statistics.md), e.g. "chip/cycles"
    std::string per;   ///< divide by this key ("image/pixels", "chip/instructions"), or empty
    std::optional<double> max, min;  ///< limits on the value
    /// Limits on the value divided by the baseline kernel's (Assignment::baseline) on the same
    /// scene and chip: 0.98 is 2 % less than the baseline. Budgets give at least one limit.
    std::optional<double> max_ratio, min_ratio;
    std::vector<std::string> scenes;  ///< scene names it applies to; empty: every scene
    std::string hint;                 ///< what a failure likely means
    bool applies_to(std::string_view scene) const;
    /// "chip/cycles per image/pixels" or "chip/cycles".
    std::string label() const;
};

/// How close an image must be to its reference: both conditions hold for a pass.
struct ImageThresholds {
    double min_psnr = 30;      ///< dB over every channel of the 8-bit sRGB images
    int tolerance = 4;         ///< a pixel differs when a channel is off by more than this /255
    double max_differing = 0;  ///< share of pixels allowed to differ
    /// Compare the images' averages over blocks of block x block pixels (in linear light)
    /// rather than single pixels: Monte Carlo noise averages away, a wrong light level does not.
    int block = 1;
};

/// Per-assignment explanations for the likely cause of a failed image.
struct ImageHints {
    std::string brighter;  ///< most differing pixels are brighter than the reference
    std::string darker;    ///< most differing pixels are darker than the reference
    std::string mixed;     ///< neither: the differing pixels are brighter and darker both
};

struct Assignment {
    std::string id;  ///< the folder name, e.g. "3-shadows"
    std::string title;
    std::filesystem::path dir;                         ///< the assignment's folder
    uint32_t width = 0, height = 0;                    ///< image size override (0: the scene's)
    uint32_t samples_per_pixel = 0;                    ///< override (0: the scene's)
    std::optional<std::filesystem::path> chip_config;  ///< absent: the default chip
    /// Instructions one pixel may take (the render's per-work-item limit); 0: tpsim's default.
    uint64_t max_pixel_instructions = 0;
    std::string slow_hint;  ///< what it means when a pixel exceeds max_pixel_instructions
    /// One of tpsim's own kernels by name (as `render --kernel NAME`), rendered on the same scenes
    /// and chip for the budgets with a ratio; empty when none has one.
    std::string baseline;
    ImageThresholds image;
    ImageHints hints;
    std::vector<AssignmentScene> scenes;
    std::vector<Budget> budgets;
};

/// Reads and validates an assignment.toml; relative paths in it are relative to its folder.
/// Throws tpsim::Error "FILE:LINE:COL: ..." for anything malformed or unknown.
Assignment load_assignment(const std::filesystem::path& toml_file);

/// The folder of `name` under `course_dir`/assignments: the folder name itself ("3-shadows")
/// or its number ("3"). Throws tpsim::Error listing the assignments when there is none.
std::filesystem::path find_assignment(const std::filesystem::path& course_dir,
                                      std::string_view name);

}  // namespace tpsim::course
