// What kernels print (trax_printf): each thread's bytes, collected by the simulator and by the
// native twin's driver alike, and shown after the run in thread order, each line tagged with its
// thread. Host code only (the kernel side formats in trax.hpp and hands over bytes).
#pragma once
#include <algorithm>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace trax {

/// Each thread's output in the order it printed, bounded: of the output in (thread, sequence)
/// order, the first limit() bytes are kept and the rest is counted in dropped(). What is kept
/// depends only on what each thread printed, not on the order threads ran in, so every engine
/// keeps the same bytes, and a kernel printing in an endless loop holds at most limit() bytes.
class KernelOutput {
public:
    static constexpr uint64_t kDefaultLimitBytes = uint64_t(1) << 20;

    KernelOutput() = default;
    explicit KernelOutput(uint32_t threads, uint64_t limit = kDefaultLimitBytes)
        : threads_(threads), cut_(threads), limit_(limit) {}

    void append(uint32_t thread, std::string_view bytes) {
        // Bytes after the cut in thread order are dropped: a thread past the cut thread, or
        // the cut thread itself, whose kept bytes end at the cut.
        if (thread >= cut_) {
            dropped_ += bytes.size();
            return;
        }
        threads_[thread] += bytes;
        kept_ += bytes.size();
        // Over the limit: drop bytes from the end of the output in thread order, which is in
        // the cut thread or before it.
        for (uint32_t last = std::min<uint32_t>(cut_ + 1, threads()); kept_ > limit_;) {
            while (threads_[--last].empty()) {
            }
            std::string& tail = threads_[last];
            const uint64_t drop = std::min<uint64_t>(kept_ - limit_, tail.size());
            tail.resize(tail.size() - drop);
            kept_ -= drop;
            dropped_ += drop;
            cut_ = last;
        }
    }

    uint32_t threads() const { return uint32_t(threads_.size()); }
    const std::string& of(uint32_t thread) const { return threads_.at(thread); }
    uint64_t limit() const { return limit_; }
    uint64_t kept() const { return kept_; }
    /// Bytes printed past the limit and not kept.
    uint64_t dropped() const { return dropped_; }
    bool empty() const { return kept_ == 0 && dropped_ == 0; }

    /// Every kept line as "[thread N] text\n", threads in id order, each thread's lines in the
    /// order it printed them (an unfinished last line is ended).
    std::string tagged() const {
        std::string text;
        for (uint32_t t = 0; t < threads_.size(); ++t) {
            const std::string_view bytes = threads_[t];
            for (size_t begin = 0; begin < bytes.size();) {
                const size_t newline = bytes.find('\n', begin);
                const size_t end = newline == std::string_view::npos ? bytes.size() : newline;
                text += "[thread " + std::to_string(t) + "] ";
                text += bytes.substr(begin, end - begin);
                text += '\n';
                begin = end + 1;
            }
        }
        return text;
    }

    /// One line saying how much was dropped, or "" if nothing was.
    std::string truncation_note() const {
        if (dropped_ == 0) return {};
        return "kernel output truncated: kept the first " + std::to_string(limit_) +
               " bytes in thread order, dropped " + std::to_string(dropped_) + " more";
    }

    /// Rebuilds an output from its parts (the native twin hands them across processes).
    static KernelOutput from_parts(std::vector<std::string> threads, uint64_t limit,
                                   uint64_t dropped) {
        KernelOutput output(0, limit);
        for (const std::string& bytes : threads)
            output.kept_ += bytes.size();
        output.threads_ = std::move(threads);
        output.cut_ = uint32_t(output.threads_.size());
        output.dropped_ = dropped;
        return output;
    }

private:
    std::vector<std::string> threads_;
    uint32_t cut_ = 0;  ///< threads at or past it keep nothing more (see append)
    uint64_t limit_ = kDefaultLimitBytes;
    uint64_t kept_ = 0, dropped_ = 0;
};

}  // namespace trax
