#include "sim/course/check.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <optional>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "sim/analysis/images.hpp"
#include "sim/core/error.hpp"
#include "sim/core/fault.hpp"
#include "sim/render/image_codec.hpp"
#include "sim/render/report.hpp"
#include "sim/render/srgb.hpp"
#include "sim/stats/registry.hpp"
#include "sim/stats/thousands.hpp"
#include "sim/timing/config.hpp"

namespace tpsim::course {
namespace {

using analysis::read_rgb8;
using analysis::Rgb8;
using analysis::write_rgb8;

/// Counts as a person reads them: 1,234,567 for large values, 3 digits for small ones.
std::string number(double v) {
    if (std::abs(v) >= 1000) return stats::with_thousands(fmt::format("{:.0f}", v));
    return fmt::format("{:.3g}", v);
}

std::string percent(double share) {
    return share > 0 && share < 0.001 ? "<0.1%" : fmt::format("{:.1f}%", 100 * share);
}

/// Simple mistakes that change a whole image in a way that can be undone.
enum class Mistake { upside_down, mirrored, red_blue_exchanged };

/// The image with `mistake` undone (each one is its own inverse).
Rgb8 undone(const Rgb8& image, Mistake mistake) {
    Rgb8 out = image;
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) {
            const int sx = mistake == Mistake::mirrored ? image.width - 1 - x : x;
            const int sy = mistake == Mistake::upside_down ? image.height - 1 - y : y;
            const uint8_t* s = &image.pixels[(size_t(sy) * image.width + sx) * 3];
            uint8_t* d = &out.pixels[(size_t(y) * image.width + x) * 3];
            const bool exchange = mistake == Mistake::red_blue_exchanged;
            d[0] = s[exchange ? 2 : 0];
            d[1] = s[1];
            d[2] = s[exchange ? 0 : 2];
        }
    return out;
}

/// The image with each block x block square (cut short at the right and bottom edges) replaced
/// by its average in linear light, as the comparison sees it when [image] block > 1.
Rgb8 block_averages(const Rgb8& image, int block) {
    Rgb8 out = image;
    for (int by = 0; by < image.height; by += block)
        for (int bx = 0; bx < image.width; bx += block) {
            const int ey = std::min(by + block, image.height);
            const int ex = std::min(bx + block, image.width);
            for (int c = 0; c < 3; ++c) {
                float sum = 0;
                for (int y = by; y < ey; ++y)
                    for (int x = bx; x < ex; ++x)
                        sum += render::decode_srgb(
                            image.pixels[(size_t(y) * image.width + x) * 3 + c]);
                const uint8_t mean = render::encode_srgb(sum / float((ey - by) * (ex - bx)));
                for (int y = by; y < ey; ++y)
                    for (int x = bx; x < ex; ++x)
                        out.pixels[(size_t(y) * image.width + x) * 3 + c] = mean;
            }
        }
    return out;
}

bool one_colour(const Rgb8& image) {
    for (size_t i = 3; i < image.pixels.size(); ++i)
        if (image.pixels[i] != image.pixels[i % 3]) return false;
    return true;
}

bool within(const ImageComparison& c, const ImageThresholds& t) {
    return c.psnr >= t.min_psnr && c.differing_share <= t.max_differing;
}

/// What the failed image most likely shows, in words: a simple mistake that would explain it
/// whole, or the assignment's hint for pixels that are too bright or too dark.
std::string likely_cause(const Rgb8& image, const Rgb8& ref, const ImageComparison& c,
                         const Assignment& a) {
    if (std::all_of(image.pixels.begin(), image.pixels.end(), [](uint8_t v) { return v == 0; }))
        return "the image is black: does the kernel write the framebuffer (storef at "
               "trax_framebuffer() + pixel * 3), and does it find anything to shade?";
    if (one_colour(image))
        return fmt::format("the image is one colour everywhere (sRGB {}, {}, {}): does any ray hit "
                           "anything?",
                           image.pixels[0], image.pixels[1], image.pixels[2]);
    const struct {
        Mistake mistake;
        const char* cause;
    } mistakes[] = {
        {Mistake::upside_down,
         "the image is upside down: row 0 of the framebuffer is the top of the image"},
        {Mistake::mirrored, "the image is mirrored left to right: x grows to the right"},
        {Mistake::red_blue_exchanged, "red and blue are exchanged: a pixel is stored as R, G, B"},
    };
    for (const auto& m : mistakes)
        if (within(compare_rgb8(undone(image, m.mistake).pixels, ref.pixels, a.image.tolerance),
                   a.image))
            return m.cause;
    if (c.brighter_share >= 0.75 && !a.hints.brighter.empty())
        return fmt::format("most of them are brighter than the reference: {}", a.hints.brighter);
    if (c.brighter_share <= 0.25 && !a.hints.darker.empty())
        return fmt::format("most of them are darker than the reference: {}", a.hints.darker);
    if (!a.hints.mixed.empty())
        return fmt::format("{} of them brighter, {} darker than the reference: {}",
                           percent(c.brighter_share), percent(1 - c.brighter_share), a.hints.mixed);
    return fmt::format("{} of them brighter, {} darker than the reference; see the difference "
                       "image",
                       percent(c.brighter_share), percent(1 - c.brighter_share));
}

render::RenderOptions render_options(const Assignment& a, const AssignmentScene& scene,
                                     const CheckOptions& o) {
    render::RenderOptions r;
    r.scene = scene.file;
    r.kernel = o.kernel;
    r.engine = render::Engine::timing;
    r.image_width = a.width;
    r.image_height = a.height;
    r.samples_per_pixel = a.samples_per_pixel;
    if (a.chip_config) r.chip = timing::load_config(a.chip_config->string());
    r.max_item_instructions = a.max_pixel_instructions;
    r.on_progress = o.on_progress;
    r.on_warning = o.on_warning;
    return r;
}

/// A render's statistics, for budgets.
class Statistics {
public:
    Statistics(const Assignment& a, const render::RenderResult& result) : a_(a) {
        stats::Registry registry;
        render::register_stats(result, registry);
        snapshot_ = stats::Snapshot(registry);
    }

    /// The budget's statistic, divided by its `per` statistic when it has one.
    double of(const Budget& b) const {
        const double divisor = b.per.empty() ? 1.0 : value(b.per);
        return divisor > 0 ? value(b.stat) / divisor : 0.0;
    }

private:
    double value(const std::string& key) const {
        try {
            return snapshot_.value(key);
        } catch (const std::out_of_range&) {
            throw Error(fmt::format("{}: budget statistic '{}' is not a statistic of this render; "
                                    "see docs/statistics.md for the keys",
                                    (a_.dir / "assignment.toml").string(), key));
        }
    }

    const Assignment& a_;
    stats::Snapshot snapshot_;
};

/// "(3.1% over)" or "(2.1x over)": how far a measurement is beyond its limit.
std::string over_by(double measured, double limit) {
    return measured < 2 * limit ? fmt::format("{:.1f}% over", 100 * (measured / limit - 1))
                                : fmt::format("{:.1f}x over", measured / limit);
}

bool needs_baseline(const Assignment& a, const AssignmentScene& scene) {
    return std::any_of(a.budgets.begin(), a.budgets.end(), [&](const Budget& b) {
        return b.applies_to(scene.name) && (b.max_ratio || b.min_ratio);
    });
}

/// The budgets of one scene, checked against its statistics (and the baseline kernel's, for the
/// budgets with a ratio).
void check_budgets(const Assignment& a, const AssignmentScene& scene,
                   const render::RenderResult& result, const render::RenderResult* baseline,
                   std::vector<CheckResult>& results) {
    const Statistics kernel(a, result);
    std::optional<Statistics> base;
    if (baseline) base.emplace(a, *baseline);
    for (const Budget& b : a.budgets) {
        if (!b.applies_to(scene.name)) continue;
        const double measured = kernel.of(b);
        std::vector<std::string> broken, kept;
        if (b.max && measured > *b.max)
            broken.push_back(
                fmt::format("> {} allowed ({})", number(*b.max), over_by(measured, *b.max)));
        else if (b.min && measured < *b.min)
            broken.push_back(fmt::format("< {} required", number(*b.min)));
        else {
            if (b.min) kept.push_back(">= " + number(*b.min));
            if (b.max) kept.push_back("<= " + number(*b.max));
        }
        std::string relative;
        if (b.max_ratio || b.min_ratio) {
            const double reference = base->of(b);
            const double ratio = reference > 0 ? measured / reference : 0.0;
            relative =
                fmt::format(" = {:.1f}% of {}'s {}", 100 * ratio, a.baseline, number(reference));
            if (b.max_ratio && ratio > *b.max_ratio)
                broken.push_back(fmt::format("> {:g}% allowed", 100 * *b.max_ratio));
            else if (b.min_ratio && ratio < *b.min_ratio)
                broken.push_back(fmt::format("< {:g}% required", 100 * *b.min_ratio));
            else {
                if (b.min_ratio) kept.push_back(fmt::format(">= {:g}%", 100 * *b.min_ratio));
                if (b.max_ratio) kept.push_back(fmt::format("<= {:g}%", 100 * *b.max_ratio));
            }
        }
        CheckResult r{scene.name, "budget", broken.empty(), ""};
        const std::vector<std::string>& limits = broken.empty() ? kept : broken;
        r.detail = fmt::format("{} {}{}{}{}", b.label(), number(measured), relative,
                               limits.empty() ? "" : " ", fmt::join(limits, ", "));
        if (!r.passed && !b.hint.empty()) r.detail += " — " + b.hint;
        results.push_back(std::move(r));
    }
}

/// Bad input is found before the first (slow) render.
void check_inputs(const Assignment& a, const CheckOptions& o) {
    render::Kernel::load(o.kernel);
    if (!a.baseline.empty()) render::Kernel::load(o.baseline_kernel);
    if (o.update_references) return;
    for (const AssignmentScene& scene : a.scenes)
        if (!std::filesystem::is_regular_file(scene.reference))
            throw Error(fmt::format(
                "assignment {} has no reference image {} for scene '{}'; render it with the "
                "reference solution: tpsim check {} --kernel SOLUTION.elf --update-references",
                a.id, scene.reference.string(), scene.name, a.id));
}

}  // namespace

ImageComparison compare_rgb8(const std::vector<uint8_t>& image, const std::vector<uint8_t>& ref,
                             int tolerance) {
    ImageComparison c;
    double squared = 0;
    uint64_t differing = 0, brighter = 0;
    for (size_t p = 0; p + 2 < ref.size(); p += 3) {
        int largest = 0, signed_sum = 0;
        for (int ch = 0; ch < 3; ++ch) {
            const int d = int(image[p + ch]) - int(ref[p + ch]);
            squared += double(d) * d;
            largest = std::max(largest, std::abs(d));
            signed_sum += d;
        }
        if (largest > tolerance) {
            ++differing;
            brighter += signed_sum > 0;
        }
    }
    const double samples = double(ref.size());
    const double rmse = samples > 0 ? std::sqrt(squared / samples) / 255.0 : 0.0;
    c.identical = squared == 0;
    c.psnr = c.identical ? std::numeric_limits<double>::infinity() : 20 * std::log10(1 / rmse);
    c.differing_share = samples > 0 ? double(differing) / (samples / 3) : 0.0;
    c.brighter_share = differing > 0 ? double(brighter) / double(differing) : 0.0;
    return c;
}

bool CheckReport::passed() const {
    return !results.empty() && std::all_of(results.begin(), results.end(),
                                           [](const CheckResult& r) { return r.passed; });
}

CheckReport check(const Assignment& a, const CheckOptions& o) {
    CheckReport report;
    check_inputs(a, o);
    for (size_t i = 0; i < a.scenes.size(); ++i) {
        const AssignmentScene& scene = a.scenes[i];
        if (o.on_scene) o.on_scene(i, scene);
        render::RenderResult result;
        try {
            result = render::render(render_options(a, scene, o));
        } catch (const core::Fault& fault) {
            // The kernel's own mistake: the assignment fails, with the simulator's words.
            const bool runaway = fault.kind() == core::FaultKind::InstructionLimit;
            std::string detail = fmt::format("the kernel stopped: {}", fault.what());
            // The fault's own hint (raise the limit with a render flag) does not apply: the
            // assignment sets the limit.
            if (runaway && a.max_pixel_instructions != 0)
                detail =
                    fmt::format("a pixel took more than {} instructions, the assignment's "
                                "limit{}; {}",
                                number(double(a.max_pixel_instructions)),
                                a.slow_hint.empty() ? "" : " — " + a.slow_hint, fault.problem());
            report.results.push_back({scene.name, "run", false, detail});
            continue;
        }
        const std::string stem = fmt::format("check-{}-{}", a.id, scene.name);
        const std::filesystem::path image_path =
            o.update_references ? scene.reference : o.output_dir / (stem + ".png");
        // 8-bit sRGB, as a render's PNG; compared from memory, so another check writing the
        // same file name cannot change what this one compares.
        Rgb8 image{int(result.scene.width), int(result.scene.height),
                   std::vector<uint8_t>(result.rgb.size())};
        std::transform(result.rgb.begin(), result.rgb.end(), image.pixels.begin(),
                       render::encode_srgb);
        write_rgb8(image_path, image);
        report.files.push_back(image_path);
        if (o.update_references) {
            report.results.push_back({scene.name, "image", true,
                                      fmt::format("reference written: {}", image_path.string())});
        } else {
            Rgb8 ref = read_rgb8(scene.reference, "reference image");
            if (ref.width != image.width || ref.height != image.height)
                throw Error(fmt::format("reference image {} is {}x{} but the assignment renders "
                                        "{}x{}; render it again with --update-references",
                                        scene.reference.string(), ref.width, ref.height,
                                        image.width, image.height));
            const int block = a.image.block;
            if (block > 1) {
                image = block_averages(image, block);
                ref = block_averages(ref, block);
            }
            const ImageComparison c = compare_rgb8(image.pixels, ref.pixels, a.image.tolerance);
            CheckResult r{scene.name, "image", within(c, a.image), ""};
            const std::string psnr =
                c.identical
                    ? "identical to the reference"
                    : fmt::format("PSNR {:.1f} dB {} {:g} dB required", c.psnr,
                                  c.psnr >= a.image.min_psnr ? ">=" : "<", a.image.min_psnr);
            r.detail = fmt::format(
                "{}{}; {} of pixels differ by more than {}/255 ({} allowed)",
                block > 1 ? fmt::format("{}x{}-pixel averages: ", block, block) : "", psnr,
                percent(c.differing_share), a.image.tolerance, percent(a.image.max_differing));
            if (!r.passed) r.detail += " — " + likely_cause(image, ref, c, a);
            report.results.push_back(std::move(r));
            for (std::filesystem::path& file : analysis::write_difference_images(
                     image, ref, a.image.tolerance, o.output_dir / stem))
                report.files.push_back(std::move(file));
        }
        std::optional<render::RenderResult> baseline;
        if (needs_baseline(a, scene)) {
            if (o.on_baseline) o.on_baseline(scene);
            render::RenderOptions options = render_options(a, scene, o);
            options.kernel = o.baseline_kernel;
            baseline = render::render(options);
        }
        check_budgets(a, scene, result, baseline ? &*baseline : nullptr, report.results);
    }
    return report;
}

}  // namespace tpsim::course
