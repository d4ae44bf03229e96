#include "sim/render/native_twin.hpp"

#include <dlfcn.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <memory>

#include <fmt/format.h>

#include "kernel/kernel_output.hpp"
#include "kernel/native_twin.h"
#include "sim/core/error.hpp"
#include "sim/core/fault.hpp"

namespace tpsim::render {
namespace {

constexpr size_t kErrorBytes = 1024;
/// The host has no instruction limit, so a twin stuck in an endless loop is stopped after this
/// long; real renders take seconds natively (the 1.5 M-triangle stress scene well under one).
constexpr unsigned kTimeLimitSeconds = 600;

/// Memory shared with the child process that runs the twin; unmapped when it goes.
class SharedMapping {
public:
    explicit SharedMapping(size_t bytes)
        : bytes_(std::max<size_t>(bytes, 1)),
          data_(mmap(nullptr, bytes_, PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0)) {
        if (data_ == MAP_FAILED)
            throw Error(fmt::format("cannot map {} bytes for the native twin: {}", bytes_,
                                    std::strerror(errno)));
    }
    ~SharedMapping() { munmap(data_, bytes_); }
    SharedMapping(const SharedMapping&) = delete;
    SharedMapping& operator=(const SharedMapping&) = delete;
    void* data() const { return data_; }

private:
    size_t bytes_;
    void* data_;
};

std::string describe_signal(int signal) {
    switch (signal) {
    case SIGSEGV:
        return "SIGSEGV: an invalid memory access (null or wild pointer, or a stack overflow "
               "from deep recursion)";
    case SIGBUS:
        return "SIGBUS: a misaligned or invalid memory access";
    case SIGFPE:
        return "SIGFPE: an integer division by zero";
    case SIGILL:
        return "SIGILL: an illegal instruction";
    case SIGABRT:
        return "SIGABRT: the kernel aborted";
    case SIGALRM:
        return fmt::format("no result after {} s (an endless loop? the simulator stops one "
                           "with --max-instructions and names where it is)",
                           kTimeLimitSeconds);
    default:
        return fmt::format("signal {} ({})", signal, strsignal(signal));
    }
}

/// The kernel's output as the twin left it: each thread's bytes one after another. The twin wrote
/// at most `limit` bytes; a corrupt length cannot read past them.
trax::KernelOutput collect_output(const char* output, const uint32_t* lengths, uint32_t num_threads,
                                  uint64_t limit, uint64_t dropped) {
    std::vector<std::string> threads(num_threads);
    for (size_t id = 0, at = 0; id < num_threads; ++id) {
        const size_t length = std::min<size_t>(lengths[id], limit - at);
        threads[id].assign(output + at, length);
        at += length;
    }
    return trax::KernelOutput::from_parts(std::move(threads), limit, dropped);
}

/// A fault the twin found and reported (a write into the scene, a global register that does not
/// exist, a deadlock ...), with what the kernel printed before it. (After a crash by a signal the
/// output is lost with the child's memory: the twin hands it over only when it ends by itself.)
core::KernelError twin_error(const char* error, size_t capacity, trax::KernelOutput printed) {
    return core::KernelError(error[0] != '\0' ? std::string(error, strnlen(error, capacity))
                                              : "the native twin failed without saying why",
                             std::move(printed));
}

}  // namespace

std::filesystem::path native_twin_of(const std::filesystem::path& kernel_elf) {
    return kernel_elf.parent_path() / ("lib" + kernel_elf.stem().string() + "_native.so");
}

trax::KernelOutput run_native_twin(const std::filesystem::path& library,
                                   std::vector<uint32_t>& global_words, uint32_t num_threads,
                                   uint32_t num_tms, uint32_t tm_size,
                                   const std::vector<KernelParam>& params, TwinProcess process) {
    // RTLD_LOCAL keeps each twin's copy of the trax runtime to itself.
    const std::unique_ptr<void, int (*)(void*)> handle(
        dlopen(std::filesystem::absolute(library).c_str(), RTLD_NOW | RTLD_LOCAL), dlclose);
    if (!handle)
        throw Error(fmt::format("cannot load native twin '{}': {} (build it with the kernel's "
                                "NAME_native target)",
                                library.string(), dlerror()));
    const auto run =
        reinterpret_cast<TpsimNativeRunFn>(dlsym(handle.get(), TPSIM_NATIVE_RUN_SYMBOL));
    if (run == nullptr)
        throw Error(fmt::format("'{}' is not a tpsim native twin (no {} symbol)", library.string(),
                                TPSIM_NATIVE_RUN_SYMBOL));
    // Written before the child is forked, so it inherits them.
    for (const KernelParam& param : params) {
        void* value = dlsym(handle.get(), param.symbol().c_str());
        if (value == nullptr)
            throw Error(fmt::format("native twin '{}' has no parameter {} (symbol {}) though its "
                                    "ELF has: rebuild the twin (target NAME_native)",
                                    library.string(), param.name, param.symbol()));
        std::memcpy(value, &param.bits, sizeof param.bits);
    }

    constexpr uint64_t kOutputLimit = trax::KernelOutput::kDefaultLimitBytes;
    if (process == TwinProcess::in_process) {
        // Straight on tpsim's memory: a crash is the debugger's to catch, and there is no time
        // limit, so a thread can stay at a breakpoint for as long as it takes.
        char error[kErrorBytes] = {};
        std::vector<char> output(kOutputLimit);
        std::vector<uint32_t> lengths(num_threads);
        uint64_t dropped = 0;
        const TraxNativeContext context{global_words.data(),
                                        uint32_t(global_words.size()),
                                        num_threads,
                                        num_tms,
                                        tm_size,
                                        error,
                                        kErrorBytes,
                                        output.data(),
                                        uint32_t(kOutputLimit),
                                        lengths.data(),
                                        &dropped};
        const int status = run(&context);
        trax::KernelOutput printed =
            collect_output(output.data(), lengths.data(), num_threads, kOutputLimit, dropped);
        if (status != 0) throw twin_error(error, kErrorBytes, std::move(printed));
        return printed;
    }

    // The twin is the student's code running on the host: a wild pointer or runaway recursion
    // there is a real SIGSEGV. It runs in a child process over shared memory so that such a
    // crash becomes an error message here instead of killing tpsim.
    // Shared: the error message, the kernel's output (dropped count, lengths, bytes) and the
    // memory image, each aligned for its type.
    const size_t image_bytes = global_words.size() * sizeof(uint32_t);
    const size_t lengths_bytes = size_t(num_threads) * sizeof(uint32_t);
    SharedMapping shared(kErrorBytes + sizeof(uint64_t) + lengths_bytes + image_bytes +
                         kOutputLimit);
    char* const error = static_cast<char*>(shared.data());
    auto* const dropped = reinterpret_cast<uint64_t*>(error + kErrorBytes);
    auto* const lengths = reinterpret_cast<uint32_t*>(dropped + 1);
    uint32_t* const words = lengths + num_threads;
    char* const output = reinterpret_cast<char*>(words + global_words.size());
    std::memcpy(words, global_words.data(), image_bytes);
    const TraxNativeContext context{
        words,  uint32_t(global_words.size()), num_threads, num_tms, tm_size, error, kErrorBytes,
        output, uint32_t(kOutputLimit),        lengths,     dropped};
    const pid_t child = fork();
    if (child < 0)
        throw Error(
            fmt::format("cannot start the native twin: fork failed: {}", std::strerror(errno)));
    if (child == 0) {
        alarm(kTimeLimitSeconds);
        _exit(run(&context) == 0 ? 0 : 1);
    }

    int status = 0;
    while (waitpid(child, &status, 0) < 0)
        if (errno != EINTR)
            throw Error(fmt::format("lost the native twin's process: {}", std::strerror(errno)));
    if (WIFSIGNALED(status))
        throw Error(fmt::format(
            "the native twin '{}' stopped: {}; run without --native to have the simulator "
            "name the thread, pc and source line, or run the twin in gdb with --no-fork "
            "(docs/debugging.md)",
            library.filename().string(), describe_signal(WTERMSIG(status))));
    trax::KernelOutput printed =
        collect_output(output, lengths, num_threads, kOutputLimit, *dropped);
    if (WEXITSTATUS(status) != 0) throw twin_error(error, kErrorBytes, std::move(printed));
    std::memcpy(global_words.data(), words, image_bytes);
    return printed;
}

}  // namespace tpsim::render
