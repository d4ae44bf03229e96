// The native twin's driver, linked into every libNAME_native.so: runs trax_main() once per
// thread id over the caller's memory image and turns kernel faults into an error message.
#include <algorithm>
#include <cstring>
#include <exception>
#include <mutex>
#include <string>

#include "native_twin.h"
#include "trax.hpp"

namespace {

void report(const TraxNativeContext& ctx, const std::string& message) {
    if (ctx.error == nullptr || ctx.error_capacity == 0) return;
    const size_t n = std::min<size_t>(message.size(), ctx.error_capacity - 1);
    std::memcpy(ctx.error, message.data(), n);
    ctx.error[n] = '\0';
}

std::string check(const TraxNativeContext& ctx) {
    if (ctx.global_words == nullptr || ctx.global_word_count == 0)
        return "native twin: no global memory given (global_words is null or empty)";
    if (ctx.num_threads == 0 || ctx.num_tms == 0 || ctx.tm_size == 0)
        return "native twin: num_threads, num_tms and tm_size must all be at least 1";
    if (uint64_t{ctx.num_tms} * ctx.tm_size < ctx.num_threads)
        return "native twin: " + std::to_string(ctx.num_threads) + " threads do not fit in " +
               std::to_string(ctx.num_tms) + " TMs of " + std::to_string(ctx.tm_size);
    return {};
}

}  // namespace

extern "C" __attribute__((visibility("default"))) int
tpsim_native_run(const TraxNativeContext* ctx) {
    if (ctx == nullptr) return 1;
    if (const std::string problem = check(*ctx); !problem.empty()) {
        report(*ctx, problem);
        return 1;
    }
    // The API reaches the running thread through one pointer per library: one run at a time.
    static std::mutex one_run_at_a_time;
    const std::lock_guard lock(one_run_at_a_time);

    uint32_t global_registers[trax::native::kGlobalRegisters] = {};
    trax::native::ThreadContext thread;
    thread.words = ctx->global_words;
    thread.word_count = ctx->global_word_count;
    // The image starts with the scene header; everything before the framebuffer is the scene,
    // read-only as on the simulator.
    if (ctx->global_word_count >= sizeof(trax::layout::SceneHeader) / 4 &&
        ctx->global_words[trax::layout::kHeaderMagic] == trax::layout::kMagic)
        thread.read_only_words =
            std::clamp<int64_t>(int32_t(ctx->global_words[trax::layout::kHeaderFramebuffer]), 0,
                                ctx->global_word_count);
    thread.global_registers = global_registers;
    thread.num_threads = static_cast<int>(ctx->num_threads);
    thread.num_tms = static_cast<int>(ctx->num_tms);
    thread.tm_size = static_cast<int>(ctx->tm_size);
    trax::native::current = &thread;
    int status = 0;
    try {
        for (uint32_t id = 0; id < ctx->num_threads; ++id) {
            thread.thread_id = static_cast<int>(id);
            thread.tm_id = static_cast<int>(id / ctx->tm_size);
            thread.tp_id = static_cast<int>(id % ctx->tm_size);
            thread.rand_state = 0;  // a new thread: trax_rand() seeds itself on its first draw
            trax_main();
        }
    } catch (const std::exception& e) {
        report(*ctx, e.what());
        status = 1;
    }
    trax::native::current = nullptr;
    return status;
}
