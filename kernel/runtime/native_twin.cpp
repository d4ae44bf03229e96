// The native twin's driver, linked into every libNAME_native.so: runs trax_main() once per
// thread id over the caller's memory image and turns kernel faults into an error message.
//
// Each thread runs as a fiber (ucontext) on its own stack, one at a time, so that a barrier or
// a semaphore can make one wait while the others run: a thread switches only where it waits,
// and the next to run is always the first ready one, so the schedule is the same every run.
#include <sys/mman.h>
#include <ucontext.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <deque>
#include <exception>
#include <mutex>
#include <string>
#include <vector>

#include "kernel_output.hpp"
#include "native_twin.h"
#include "trax.hpp"

namespace {

/// Stack bytes of each thread (reserved, touched only as deep as the kernel goes), above a
/// guard page that turns an overflow into SIGSEGV. Far more than the simulator's local store:
/// host frames are larger, and the twin is not where local-store overflows are found.
constexpr size_t kFiberStackBytes = size_t(1) << 18;

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
        return std::string("native twin: ") + std::to_string(ctx.num_threads) +
               std::string(" threads do not fit in ") + std::to_string(ctx.num_tms) +
               std::string(" TMs of ") + std::to_string(ctx.tm_size);
    return {};
}

/// "threads 0-3" / "thread 5": ascending ids, runs as ranges.
std::string threads_named(std::vector<uint32_t> ids) {
    std::sort(ids.begin(), ids.end());
    std::string text = ids.size() == 1 ? "thread " : "threads ";
    for (size_t i = 0; i < ids.size();) {
        size_t j = i;
        while (j + 1 < ids.size() && ids[j + 1] == ids[j] + 1)
            ++j;
        if (i != 0) text += ", ";
        text += std::to_string(ids[i]);
        if (j != i) {
            text += '-';
            text += std::to_string(ids[j]);
        }
        i = j + 1;
    }
    return text;
}

/// The threads of one run and their schedule.
class Scheduler {
public:
    Scheduler(const TraxNativeContext& ctx, uint32_t* global_registers)
        : threads_(ctx.num_threads), output_(ctx.num_threads, ctx.output_capacity),
          global_registers_(global_registers), live_(ctx.num_threads) {
        for (uint32_t id = 0; id < ctx.num_threads; ++id) {
            trax::native::ThreadContext& t = threads_[id].context;
            t.words = ctx.global_words;
            t.word_count = ctx.global_word_count;
            // The image starts with the scene header; everything before the framebuffer is
            // the scene, read-only as on the simulator.
            if (ctx.global_word_count >= sizeof(trax::layout::SceneHeader) / 4 &&
                ctx.global_words[trax::layout::kHeaderMagic] == trax::layout::kMagic)
                t.read_only_words =
                    std::clamp<int64_t>(int32_t(ctx.global_words[trax::layout::kHeaderFramebuffer]),
                                        0, ctx.global_word_count);
            t.global_registers = global_registers;
            t.num_threads = static_cast<int>(ctx.num_threads);
            t.num_tms = static_cast<int>(ctx.num_tms);
            t.tm_size = static_cast<int>(ctx.tm_size);
            t.thread_id = static_cast<int>(id);
            t.tm_id = static_cast<int>(id / ctx.tm_size);
            t.tp_id = static_cast<int>(id % ctx.tm_size);
            ready_.push_back(id);
        }
        holder_.fill(kNobody);
    }

    ~Scheduler() {
        for (Thread& t : threads_)
            release_stack(t);
        for (char* stack : free_stacks_)
            munmap(stack, kFiberStackBytes + page_bytes());
    }

    Scheduler(const Scheduler&) = delete;
    Scheduler& operator=(const Scheduler&) = delete;

    /// Runs every thread to its end; returns the first kernel fault's message, or "".
    std::string run() {
        while (!ready_.empty() && error_.empty()) {
            const uint32_t id = ready_.front();
            ready_.pop_front();
            resume(id);
        }
        return error_;
    }

    const trax::KernelOutput& output() const { return output_; }

    /// The run in progress (one at a time, see tpsim_native_run), for the kernel API's calls
    /// and the fibers' entry, which takes no argument.
    static inline Scheduler* active = nullptr;

    // The kernel API's calls, on the running thread's stack.
    void print(const char* bytes, int length) {
        if (length > 0) output_.append(running_, std::string_view(bytes, size_t(length)));
    }

    void barrier() {
        if (at_barrier_.size() + 1 == live_) {  // the last to arrive goes on with the others
            for (uint32_t waiter : at_barrier_)
                make_ready(waiter);
            at_barrier_.clear();
            return;
        }
        check_not_last_running("at the barrier");
        at_barrier_.push_back(running_);
        wait();
    }

    void sem_acquire(int reg) {
        check_register("trax_semacquire", reg);
        if (global_registers_[reg] == 0) {
            global_registers_[reg] = 1;
            holder_[size_t(reg)] = running_;
            return;
        }
        check_not_last_running(std::string("for semaphore ") + std::to_string(reg) + " (" +
                               holder_of(uint32_t(reg)) + ")");
        semaphore_waits_.push_back({uint32_t(reg), running_});
        wait();  // resumed holding it: the release handed it over
    }

    void sem_release(int reg) {
        check_register("trax_semrelease", reg);
        if (global_registers_[reg] != 1)
            throw trax::native::KernelFault(std::string("trax_semrelease(") + std::to_string(reg) +
                                            std::string(") in thread ") + std::to_string(running_) +
                                            std::string(": semaphore ") + std::to_string(reg) +
                                            std::string(" is not held (global register ") +
                                            std::to_string(reg) + std::string(" is ") +
                                            std::to_string(global_registers_[reg]) +
                                            ") — release only a semaphore the thread acquired");
        const auto first =
            std::find_if(semaphore_waits_.begin(), semaphore_waits_.end(),
                         [reg](const SemaphoreWait& w) { return w.reg == uint32_t(reg); });
        if (first == semaphore_waits_.end()) {
            global_registers_[reg] = 0;
            holder_[size_t(reg)] = kNobody;
            return;
        }
        holder_[size_t(reg)] = first->thread;
        make_ready(first->thread);
        semaphore_waits_.erase(first);
    }

private:
    static constexpr uint32_t kNobody = UINT32_MAX;
    enum class State : uint8_t { NotStarted, Ready, Running, Waiting, Done };
    struct Thread {
        trax::native::ThreadContext context;
        State state = State::NotStarted;
        ucontext_t fiber;
        char* stack = nullptr;  // the guard page's address; the stack is above it
    };
    struct SemaphoreWait {
        uint32_t reg, thread;
    };

    static size_t page_bytes() { return size_t(sysconf(_SC_PAGESIZE)); }

    static void entry() { active->run_thread(); }

    void run_thread() {
        const uint32_t id = running_;
        try {
            trax_main();
        } catch (const std::exception& e) {
            if (error_.empty()) error_ = e.what();
        }
        threads_[id].state = State::Done;
        --live_;
        // An exit lets the barrier's waiters go on if it was the last thread they waited for.
        if (!at_barrier_.empty() && at_barrier_.size() == live_) {
            for (uint32_t waiter : at_barrier_)
                make_ready(waiter);
            at_barrier_.clear();
        }
        if (error_.empty() && ready_.empty() && live_ != 0)
            error_ =
                std::string("deadlock: thread ") + std::to_string(id) +
                " exits while every other thread that has not exited waits: " + describe_waiting() +
                " — release every semaphore a thread acquires before it exits";
        // Returns to the scheduler through uc_link.
    }

    void resume(uint32_t id) {
        Thread& t = threads_[id];
        if (t.state == State::NotStarted) {
            t.stack = take_stack();
            getcontext(&t.fiber);
            t.fiber.uc_stack.ss_sp = t.stack + page_bytes();
            t.fiber.uc_stack.ss_size = kFiberStackBytes;
            t.fiber.uc_link = &scheduler_;
            makecontext(&t.fiber, &Scheduler::entry, 0);
        }
        t.state = State::Running;
        running_ = id;
        trax::native::current = &t.context;
        swapcontext(&scheduler_, &t.fiber);
        if (t.state == State::Done) release_stack(t);
    }

    /// Leaves the running thread waiting and runs the scheduler until a release readies it.
    void wait() {
        Thread& t = threads_[running_];
        const uint32_t id = running_;
        t.state = State::Waiting;
        swapcontext(&t.fiber, &scheduler_);
        running_ = id;  // resumed
    }

    void make_ready(uint32_t id) {
        threads_[id].state = State::Ready;
        ready_.push_back(id);
    }

    void check_register(const char* api, int reg) const {
        if (reg < 0 || reg >= trax::native::kGlobalRegisters)
            throw trax::native::KernelFault(std::string(api) + std::string("(") +
                                            std::to_string(reg) + std::string(") in thread ") +
                                            std::to_string(running_) +
                                            ": global registers are 0..255");
    }

    /// Throws the deadlock fault if no other thread could end the wait about to begin.
    void check_not_last_running(const std::string& waits) const {
        if (!ready_.empty()) return;
        throw trax::native::KernelFault(
            std::string("deadlock: thread ") + std::to_string(running_) + " waits " + waits +
            ", but every other thread that has not exited waits too: " + describe_waiting() +
            " — release every semaphore a thread acquires before it waits at the barrier or "
            "exits, and acquire semaphores in the same order everywhere");
    }

    std::string describe_waiting() const {
        std::string text;
        const auto add = [&](const std::string& part) {
            text += (text.empty() ? "" : "; ") + part;
        };
        if (!at_barrier_.empty()) add(threads_named(at_barrier_) + " at the barrier");
        std::vector<uint32_t> regs;
        for (const SemaphoreWait& w : semaphore_waits_)
            if (std::find(regs.begin(), regs.end(), w.reg) == regs.end()) regs.push_back(w.reg);
        std::sort(regs.begin(), regs.end());
        for (uint32_t reg : regs) {
            std::vector<uint32_t> ids;
            for (const SemaphoreWait& w : semaphore_waits_)
                if (w.reg == reg) ids.push_back(w.thread);
            add(threads_named(ids) + std::string(" for semaphore ") + std::to_string(reg) + " (" +
                holder_of(reg) + ")");
        }
        return text;
    }

    /// "held by thread 2" and the like, as the simulator says it.
    std::string holder_of(uint32_t reg) const {
        const uint32_t holder = holder_[reg];
        if (holder == kNobody)
            return std::string("no thread acquired it, but global register ") +
                   std::to_string(reg) + " is " + std::to_string(global_registers_[reg]) +
                   ": is it used by atomicinc too?";
        return std::string("held by thread ") + std::to_string(holder) +
               (threads_[holder].state == State::Done ? ", which exited" : "");
    }

    char* take_stack() {
        if (!free_stacks_.empty()) {
            char* stack = free_stacks_.back();
            free_stacks_.pop_back();
            return stack;
        }
        void* memory = mmap(nullptr, kFiberStackBytes + page_bytes(), PROT_READ | PROT_WRITE,
                            MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE | MAP_STACK, -1, 0);
        if (memory == MAP_FAILED)
            throw trax::native::KernelFault(
                std::string("native twin: cannot map a thread stack of ") +
                std::to_string(kFiberStackBytes) + " bytes");
        mprotect(memory, page_bytes(), PROT_NONE);
        return static_cast<char*>(memory);
    }

    void release_stack(Thread& t) {
        if (t.stack != nullptr) free_stacks_.push_back(t.stack);
        t.stack = nullptr;
    }

    std::vector<Thread> threads_;
    std::deque<uint32_t> ready_;  // threads to run, in order
    std::vector<uint32_t> at_barrier_;
    std::vector<SemaphoreWait> semaphore_waits_;  // in arrival order (FIFO hand-over)
    std::array<uint32_t, trax::native::kGlobalRegisters> holder_;
    std::vector<char*> free_stacks_;
    trax::KernelOutput output_;
    uint32_t* global_registers_;
    uint32_t live_;  // threads not done
    uint32_t running_ = 0;
    ucontext_t scheduler_;
    std::string error_;
};

void hand_over_output(const TraxNativeContext& ctx, const trax::KernelOutput& output) {
    if (ctx.output == nullptr || ctx.output_lengths == nullptr) return;
    size_t at = 0;
    for (uint32_t id = 0; id < output.threads(); ++id) {
        const std::string& bytes = output.of(id);
        std::memcpy(ctx.output + at, bytes.data(), bytes.size());
        at += bytes.size();
        ctx.output_lengths[id] = uint32_t(bytes.size());
    }
    if (ctx.output_dropped != nullptr) *ctx.output_dropped = output.dropped();
}

}  // namespace

void trax::native::print_bytes(const char* bytes, int length) {
    Scheduler::active->print(bytes, length);
}
void trax::native::barrier() {
    Scheduler::active->barrier();
}
void trax::native::sem_acquire(int reg) {
    Scheduler::active->sem_acquire(reg);
}
void trax::native::sem_release(int reg) {
    Scheduler::active->sem_release(reg);
}

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
    std::string problem;
    try {
        Scheduler run(*ctx, global_registers);
        Scheduler::active = &run;
        problem = run.run();
        hand_over_output(*ctx, run.output());
    } catch (const std::exception& e) {
        problem = e.what();
    }
    Scheduler::active = nullptr;
    trax::native::current = nullptr;
    if (problem.empty()) return 0;
    report(*ctx, problem);
    return 1;
}
