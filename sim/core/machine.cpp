#include "sim/core/machine.hpp"

#include <algorithm>
#include <atomic>
#include <bit>
#include <exception>
#include <thread>
#include <type_traits>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "isa/csr.hpp"
#include "sim/core/error.hpp"
#include "sim/core/held_stores.hpp"
#include "sim/core/ordered_turns.hpp"
#include "sim/core/thread_env.hpp"

namespace tpsim::core {

void MachineConfig::validate() const {
    MemoryConfig{global_bytes, read_only_global_bytes, local_store_bytes, threads}.validate();
    if (threads_per_tm == 0) throw Error("threads per TM must be at least 1");
    if (quantum == 0) throw Error("scheduler quantum must be at least 1 instruction");
    if (max_instructions == 0) throw Error("--max-instructions must be at least 1");
}

Machine::Machine(Program program, const MachineConfig& config)
    : program_(std::move(program)), config_(config),
      memory_(program_, MemoryConfig{config.global_bytes, config.read_only_global_bytes,
                                     config.local_store_bytes, config.threads}) {
    config_.validate();
    // Decode the file-backed words of each executable segment once, and nothing else: no
    // other segment's bytes can run, and a zero-filled tail (memsz beyond filesz) is not
    // decoded, so a huge bogus memsz or a wide gap between code segments costs nothing (see
    // fetch_fault).
    for (const Segment& s : program_.segments) {
        if (!s.executable) continue;
        const CodeRange range{s.vaddr, uint32_t(s.bytes.size() / 4), uint32_t(decoded_.size())};
        for (uint32_t word = 0; word < range.words; ++word) {
            const isa::Decoded d = isa::decode(memory_.code_word(s.vaddr + 4 * word));
            // The run loops skip the target test of pc-relative jumps; the rare one with a
            // misaligned offset takes the illegal-instruction path, which runs it with the test.
            decoded_.push_back(isa::has_misaligned_offset(d) ? isa::Decoded{} : d);
        }
        code_.push_back(range);
    }
    // The loader guarantees the entry lies in an executable segment; its words may still be
    // zero fill, which the first fetch reports.
    if (const CodeRange* entry = code_range_at(program_.entry & ~3u)) entry_code_ = *entry;
    privacy_.reserve(decoded_.size());
    for (const isa::Decoded& d : decoded_) {
        switch (isa::info(d.op).fu) {
        case isa::FuClass::Load:
            privacy_.push_back(Privacy::Load);
            break;
        case isa::FuClass::Store:
            privacy_.push_back(Privacy::Store);
            break;
        case isa::FuClass::Atomic:
        case isa::FuClass::System:
        case isa::FuClass::Sync:
        case isa::FuClass::Print:  // another thread's fault reports the output printed before it
            privacy_.push_back(Privacy::Never);
            break;
        default:
            privacy_.push_back(Privacy::Always);
            break;
        }
    }

    threads_.resize(config_.threads);
    counter_lanes_.resize((config_.threads + config_.threads_per_tm - 1) / config_.threads_per_tm);
    running_threads_ = live_threads_ = config_.threads;
    semaphore_holder_.fill(kNoThread);
    output_ = trax::KernelOutput(config_.threads);
    for (Thread& t : threads_) {
        t.hart.pc = program_.entry;
        t.hart.reg[detail::kSp] =
            trax::map::kLocalTop;  // the runtime may set it again; asm tests need not
    }
}

Machine::Machine(Machine&&) noexcept = default;
Machine::~Machine() = default;

void Machine::fault(uint32_t id, uint32_t pc, const GuestFault& what) {
    threads_[id].state = ThreadState::Faulted;
    std::string where = program_.describe_pc(pc);
    if (auto source = program_.source_at(pc)) {
        where += fmt::format("{}{}:{}", where.empty() ? "" : ", ", source->file, source->line);
        // In an inlined function (e.g. the kernel API's storef), name the lines that called it.
        for (const SourceLocation& site : program_.inlined_call_sites(pc))
            where += fmt::format(", called from {}:{}", site.file, site.line);
    }
    // Name the instruction that did it, unless there is none: no code there, an undecodable
    // word (the detail shows it), or a limit that stopped the thread before this instruction.
    const Segment* segment = program_.segment_at(pc);
    const uint32_t word = memory_.code_word(pc);
    const bool show = segment && segment->executable && isa::decode(word).op != isa::Op::Illegal &&
                      what.kind != FaultKind::InstructionLimit;
    const std::string instruction = show ? isa::disassemble(word, pc) + " " : "";
    throw Fault(what.kind, id, pc,
                fmt::format("{} in thread {} at pc {:#010x}{}: {}{}", to_string(what.kind), id, pc,
                            where.empty() ? "" : " (" + where + ")", instruction, what.detail),
                what.hint, output_);
}

void Machine::fetch_fault(uint32_t id, uint32_t pc) {
    const Segment* segment = program_.segment_at(pc);
    if (pc % 4 == 0 && segment && segment->executable)  // the zero-filled tail of a code segment
        fault(id, pc,
              {FaultKind::IllegalInstruction,
               "word 0x00000000 (zero fill past the end of the code) is not an RV32IMF "
               "instruction",
               "the pc ran off the end of the code; check the linker script"});
    std::string ranges;
    for (const CodeRange& range : code_)
        ranges += fmt::format("{}[{:#010x}, {:#010x})", ranges.empty() ? "" : " ", range.base,
                              uint64_t(range.base) + 4 * uint64_t(range.words));
    fault(id, pc,
          {FaultKind::FetchOutsideCode,
           fmt::format("fetch from {:#010x}, outside the code {}", pc, ranges),
           "a return address or function pointer is null or corrupt (stack smashed?)"});
}

const Machine::CodeRange* Machine::code_range_at(uint32_t pc) const {
    if (pc % 4 != 0) return nullptr;
    for (const CodeRange& range : code_)
        if ((pc - range.base) / 4 < range.words) return &range;
    return nullptr;
}

void Machine::limit_fault(uint32_t id) {
    const Thread& t = threads_[id];
    if (t.executed < config_.max_instructions)
        fault(id, t.hart.pc,
              {FaultKind::InstructionLimit,
               fmt::format("the thread ran {} instructions on one work item (since its last "
                           "atomicinc(0)), the limit for this scene, without finishing it",
                           config_.max_item_instructions),
               "look for an endless loop, or raise the limit with --max-item-instructions"});
    fault(id, t.hart.pc,
          {FaultKind::InstructionLimit,
           fmt::format("the thread ran {} instructions (the limit) without exiting",
                       config_.max_instructions),
           "raise it with --max-instructions, or look for an endless loop"});
}

namespace {

/// run_quantum's turn on one host thread: nothing to wait for.
struct NoTurn {
    void operator()() const {}
};

}  // namespace

template <class Turn>
void Machine::run_quantum(uint32_t id, uint64_t budget, Counters& counters, Turn&& turn) {
    // Until its turn, a quantum on several host threads checks each instruction for privacy.
    bool my_turn = std::is_same_v<std::decay_t<Turn>, NoTurn>;
    Thread& t = threads_[id];
    isa::Hart& h = t.hart;
    ThreadEnv<false> env(*this, id);
    uint64_t* per_op = counters.per_op.data();
    uint64_t done = 0;
    uint32_t pc = h.pc;
    const CodeRange* range = &entry_code_;
    for (;;) {
        // Locals, not members: stores through the hart's registers could alias members, and the
        // compiler would reload them every instruction. Constant while the pc stays in `range`.
        const isa::Decoded* decoded = decoded_.data() + range->first;
        const uint32_t text_base = range->base;
        const uint32_t text_words = range->words;
        try {
            for (; done < budget; ++done) {
                pc = h.pc;
                // One compare checks range and alignment: rotating moves misaligned low bits to
                // the top. An exited thread's pc is parked at kParkedPc, so it fails here too
                // and the loop needs no per-instruction exit test.
                const uint32_t index = std::rotr(pc - text_base, 2);
                if (index >= text_words) [[unlikely]]
                    break;
                if (!my_turn && !is_private(h, index, text_words, range->first)) {
                    turn();
                    my_turn = true;
                }
                const isa::Decoded& d = decoded[index];
                ++per_op[size_t(d.op)];
                isa::execute<ThreadEnv<false>, false>(d, h, env);
            }
        } catch (const ThreadSuspended&) {
            ++done;  // the instruction completed; the thread waits, so its quantum ends
            break;
        } catch (const GuestFault& f) {
            if (!take_trap(h, f)) {
                t.executed += done;
                counters.instructions += done;
                fault(id, pc, f);
            }
            // A load or store fault the handler takes: the quantum goes on at the handler.
            ++done;
            continue;
        }
        if (done == budget || t.state != ThreadState::Running) break;
        if (!my_turn) {  // a fetch fault reads nothing shared, but must come in its turn
            turn();
            my_turn = true;
        }
        range = code_range_at(pc);  // the pc left the range: another one, or a fetch fault
        if (!range) fetch_fault(id, pc);
    }
    t.executed += done;
    counters.instructions += done;
}

void Machine::clock_by(const uint64_t* cycles, uint32_t stride) {
    if (held_) held_->write_through(UINT64_MAX, memory_);
    cycle_counters_ = cycles;
    cycle_stride_ = stride;
    held_ = cycles ? std::make_unique<HeldStores>(uint32_t(counter_lanes_.size())) : nullptr;
}

void Machine::hold_store(uint32_t id, const StepRecord& store) {
    held_->hold(id / config_.threads_per_tm,
                {position_of(id), store.mem_address, store.value, store.mem_bytes});
}

void Machine::write_held_before_step(uint32_t id) {
    if (!next_is_private(id)) held_->write_through(position_of(id), memory_);
}

void Machine::write_held_before(uint64_t cycle) {
    if (held_ && cycle != 0) held_->write_through(position(cycle, 0) - 1, memory_);
}

Counters Machine::counters() const {
    Counters sum;
    for (const CounterLane& lane : counter_lanes_) {
        sum.instructions += lane.counters.instructions;
        for (size_t op = 0; op < sum.per_op.size(); ++op)
            sum.per_op[op] += lane.counters.per_op[op];
    }
    return sum;
}

void Machine::run(uint32_t host_threads) {
    const uint32_t lanes = std::min(host_threads, thread_count());
    if (lanes > 1) return run_lanes(lanes);
    // Waiting threads are passed over; one that goes on runs again in its turn. The loop ends
    // when no thread is left running: suspend() and exited() report a deadlock before then.
    while (running_threads_ != 0)
        for (uint32_t id = 0; id < thread_count(); ++id) {
            Thread& t = threads_[id];
            if (t.state != ThreadState::Running) continue;
            const uint64_t left = instructions_left(t);
            if (left == 0) limit_fault(id);
            run_quantum(id, std::min<uint64_t>(left, config_.quantum), counters_of(id), NoTurn{});
        }
}

// run()'s rounds on `lanes` host threads: lane l takes threads l, l + lanes, ...
// Thread `id`'s quantum in round r has position r * threads + id in the order of run()'s
// single loop; what it does that others can see waits for that turn (OrderedTurns).
void Machine::run_lanes(uint32_t lanes) {
    OrderedTurns turns(lanes);
    const uint64_t threads = thread_count();
    // Each lane counts in its own lane of counters, added to the TM lanes' at the end.
    std::vector<CounterLane> counters(lanes);
    bool more_rounds = running_threads_ != 0;
    // Between rounds, one look at running_threads_ decides for every lane.
    std::atomic<uint64_t> first_failure{OrderedTurns::kDone};
    SpinBarrier round_end(lanes, [&]() noexcept {
        more_rounds = running_threads_ != 0 && first_failure.load() == OrderedTurns::kDone;
    });
    // Whether each thread waits (at the barrier, for a semaphore), as its own lane last saw it.
    std::vector<uint8_t> waiting(threads, 0);
    std::vector<std::exception_ptr> failures(lanes);
    std::vector<uint64_t> failed_at(lanes, OrderedTurns::kDone);
    const auto lane_work = [&](uint32_t lane) {
        uint64_t position = 0;
        try {
            for (uint64_t round = 0; more_rounds; ++round) {
                for (uint32_t id = lane; id < threads; id += lanes) {
                    Thread& t = threads_[id];
                    position = round * threads + id;
                    turns.reach(lane, position);
                    const auto wait_turn = [&] {
                        turns.wait_turn(lane, position);
                        if (first_failure.load() < position) throw OrderedTurns::Abandoned{};
                    };
                    // Only this lane runs the thread, but a waiting thread is let go by
                    // another's instruction: its state is read in turn.
                    if (waiting[id]) {
                        wait_turn();
                        waiting[id] = t.state == ThreadState::Waiting;
                    }
                    if (t.state != ThreadState::Running) continue;
                    const uint64_t left = instructions_left(t);
                    if (left == 0) {
                        wait_turn();
                        limit_fault(id);
                    }
                    run_quantum(id, std::min<uint64_t>(left, config_.quantum),
                                counters[lane].counters, wait_turn);
                    waiting[id] = t.state == ThreadState::Waiting;
                }
                turns.reach(lane, (round + 1) * threads);
                round_end.arrive_and_wait();
            }
            turns.reach(lane, OrderedTurns::kDone);
            return;
        } catch (const OrderedTurns::Abandoned&) {
        } catch (...) {
            // The first failure in the order is the one run() on one host thread reports, with
            // the output printed before it.
            turns.wait_turn(lane, position);
            std::exception_ptr error = std::current_exception();
            try {
                throw;
            } catch (const Fault& f) {
                error = std::make_exception_ptr(f.with_output(output_));
            } catch (...) {
            }
            failures[lane] = error;
            failed_at[lane] = position;
            uint64_t earliest = first_failure.load();
            while (position < earliest &&
                   !first_failure.compare_exchange_weak(earliest, position)) {
            }
        }
        turns.reach(lane, OrderedTurns::kDone);
        round_end.arrive_and_drop();
    };
    std::vector<std::thread> helpers;
    for (uint32_t lane = 1; lane < lanes; ++lane)
        helpers.emplace_back(lane_work, lane);
    lane_work(0);
    for (std::thread& helper : helpers)
        helper.join();
    for (const CounterLane& lane : counters) {
        Counters& sum = counter_lanes_[0].counters;
        sum.instructions += lane.counters.instructions;
        for (size_t op = 0; op < sum.per_op.size(); ++op)
            sum.per_op[op] += lane.counters.per_op[op];
    }
    if (first_failure.load() == OrderedTurns::kDone) return;
    for (uint32_t lane = 0; lane < lanes; ++lane)
        if (failed_at[lane] == first_failure.load()) std::rethrow_exception(failures[lane]);
}

// Out of line: CSR reads are rare, and inlined into the flattened step they would only add
// register pressure.
bool Machine::read_csr(uint32_t id, uint32_t csr, uint32_t& value) const {
    namespace c = isa::csr;
    const uint32_t per_tm = config_.threads_per_tm;
    // Functionally every instruction takes one cycle, so cycle = instret; the timing model
    // supplies real cycles (clock_by). (instret itself is the hart's.)
    const uint64_t cycles =
        cycle_counters_ ? cycle_counters_[id / per_tm * cycle_stride_] : threads_[id].hart.instret;
    switch (csr) {
    case c::kMhartid:
        value = id;
        return true;
    case c::kNthreads:
        value = thread_count();
        return true;
    case c::kTmid:
        value = id / per_tm;
        return true;
    case c::kNtms:
        value = (thread_count() + per_tm - 1) / per_tm;
        return true;
    case c::kTpid:
        value = id % per_tm;
        return true;
    case c::kTmsize:
        value = per_tm;
        return true;
    case c::kCycle:
    case c::kMcycle:
    case c::kTime:
        value = uint32_t(cycles);
        return true;
    case c::kCycleH:
    case c::kMcycleH:
    case c::kTimeH:
        value = uint32_t(cycles >> 32);
        return true;
    default:
        return false;
    }
}

void Machine::illegal(uint32_t id, isa::Hart& h, const isa::Decoded& d) {
    const uint32_t word = memory_.code_word(h.pc);
    if (const isa::Decoded jump = isa::decode(word); isa::has_misaligned_offset(jump)) {
        ThreadEnv<false> env(*this, id);
        return isa::execute<ThreadEnv<false>, true>(jump, h, env);
    }
    if (h.mtvec != 0) return isa::trap(h, isa::cause::kIllegal, word);
    if (d.op == isa::Op::Illegal)
        throw GuestFault{FaultKind::IllegalInstruction,
                         fmt::format("word {:#010x} is not an RV32IMF instruction", word),
                         "the pc ran into data, or the program uses an extension tpsim lacks "
                         "(compile with -march=rv32imf)"};
    const isa::Format format = isa::info(d.op).format;
    if (format == isa::Format::Csr || format == isa::Format::CsrImm)
        throw GuestFault{FaultKind::IllegalInstruction,
                         fmt::format("accesses CSR {:#05x}, which tpsim does not implement "
                                     "or which is read-only",
                                     uint32_t(d.imm)),
                         "use only the CSRs listed in docs/isa.md"};
    throw GuestFault{FaultKind::IllegalInstruction,
                     fmt::format("has no valid rounding mode (frm = {})", h.frm),
                     "set frm to 0..4 (fsrm) or give the instruction a static rounding mode"};
}

namespace {

/// "0-3, 5, 9-12": ascending ids with runs as ranges, at most a few dozen shown.
std::string id_ranges(std::vector<uint32_t> ids) {
    std::sort(ids.begin(), ids.end());
    std::string text;
    size_t shown = 0;
    for (size_t i = 0; i < ids.size();) {
        size_t j = i;
        while (j + 1 < ids.size() && ids[j + 1] == ids[j] + 1)
            ++j;
        if (++shown > 24) {
            text += ", ...";
            break;
        }
        text += (text.empty() ? "" : ", ") +
                (j == i ? std::to_string(ids[i]) : fmt::format("{}-{}", ids[i], ids[j]));
        i = j + 1;
    }
    return text;
}

std::string threads_named(const std::vector<uint32_t>& ids) {
    return (ids.size() == 1 ? "thread " : "threads ") + id_ranges(ids);
}

}  // namespace

std::string Machine::describe_waiting() const {
    std::vector<std::string> parts;
    if (!at_barrier_.empty()) parts.push_back(threads_named(at_barrier_) + " at the barrier");
    std::vector<uint32_t> regs;
    for (const SemaphoreWait& w : semaphore_waits_)
        if (std::find(regs.begin(), regs.end(), w.reg) == regs.end()) regs.push_back(w.reg);
    std::sort(regs.begin(), regs.end());
    for (uint32_t reg : regs) {
        std::vector<uint32_t> ids;
        for (const SemaphoreWait& w : semaphore_waits_)
            if (w.reg == reg) ids.push_back(w.thread);
        parts.push_back(fmt::format("{} for semaphore {} ({})", threads_named(ids), reg,
                                    semaphore_holder(reg)));
    }
    return fmt::format("{}", fmt::join(parts, "; "));
}

std::string Machine::semaphore_holder(uint32_t reg) const {
    const uint32_t holder = semaphore_holder_[reg];
    if (holder == kNoThread)
        return fmt::format("no thread acquired it, but global register {} is {}: is it used by "
                           "atomicinc too?",
                           reg, global_registers_[reg]);
    const bool gone = threads_[holder].state == ThreadState::Exited;
    return fmt::format("held by thread {}{}", holder, gone ? ", which exited" : "");
}

void Machine::check_not_last_running(const std::string& waits) const {
    if (running_threads_ == 1)
        throw GuestFault{FaultKind::Deadlock,
                         fmt::format("waits {}, but every other thread that has not exited "
                                     "waits too: {}",
                                     waits, describe_waiting()),
                         "release every semaphore a thread acquires before it waits at the "
                         "barrier or exits, and acquire semaphores in the same order everywhere"};
}

void Machine::suspend(uint32_t id, isa::Hart& h) {
    isa::complete(h);
    threads_[id].state = ThreadState::Waiting;
    --running_threads_;
    throw ThreadSuspended{};
}

uint32_t Machine::release_barrier() {
    if (at_barrier_.empty() || at_barrier_.size() != live_threads_) return 0;
    for (uint32_t waiter : at_barrier_)
        threads_[waiter].state = ThreadState::Running;
    const auto released = uint32_t(at_barrier_.size());
    running_threads_ += released;
    at_barrier_.clear();
    return released;
}

uint32_t Machine::barrier(uint32_t id, isa::Hart& h) {
    // The last thread to arrive does not wait: it goes on with those that did.
    if (at_barrier_.size() + 1 == live_threads_) {
        isa::complete(h);
        at_barrier_.push_back(id);
        threads_[id].state = ThreadState::Waiting;  // as release_barrier() expects
        --running_threads_;
        return release_barrier();
    }
    check_not_last_running("at the barrier");
    at_barrier_.push_back(id);
    suspend(id, h);
}

void Machine::check_semaphore(uint32_t reg) const {
    if (reg >= kGlobalRegisters)
        throw GuestFault{FaultKind::BadGlobalRegister,
                         fmt::format("uses global register {} as a semaphore, but there are only "
                                     "{} (0..{})",
                                     reg, kGlobalRegisters, kGlobalRegisters - 1),
                         "use a register index below 256"};
}

uint32_t Machine::sem_acquire(uint32_t id, isa::Hart& h, uint32_t reg) {
    check_semaphore(reg);
    if (global_registers_[reg] == 0) {
        global_registers_[reg] = 1;
        semaphore_holder_[reg] = id;
        isa::complete(h);
        return 1;
    }
    check_not_last_running(fmt::format("for semaphore {} ({})", reg, semaphore_holder(reg)));
    semaphore_waits_.push_back({reg, id});
    suspend(id, h);
}

uint32_t Machine::sem_release(uint32_t, isa::Hart& h, uint32_t reg) {
    check_semaphore(reg);
    if (global_registers_[reg] != 1)
        throw GuestFault{
            FaultKind::SemaphoreNotHeld,
            fmt::format("releases semaphore {}, which is not held (global register {} is {})", reg,
                        reg, global_registers_[reg]),
            "release only a semaphore the thread acquired, and use the register for nothing else"};
    isa::complete(h);
    // Handed over to the first waiter, which then holds it: the register stays 1.
    const auto first = std::find_if(semaphore_waits_.begin(), semaphore_waits_.end(),
                                    [reg](const SemaphoreWait& w) { return w.reg == reg; });
    if (first == semaphore_waits_.end()) {
        global_registers_[reg] = 0;
        semaphore_holder_[reg] = kNoThread;
        return 0;
    }
    const uint32_t next = first->thread;
    semaphore_waits_.erase(first);
    semaphore_holder_[reg] = next;
    threads_[next].state = ThreadState::Running;
    ++running_threads_;
    return next + 1;
}

uint32_t Machine::exited(uint32_t) {
    --live_threads_;
    --running_threads_;
    const uint32_t released = release_barrier();
    if (running_threads_ == 0 && live_threads_ != 0)
        throw GuestFault{FaultKind::Deadlock,
                         fmt::format("exits while every other thread that has not exited waits: {}",
                                     describe_waiting()),
                         "release every semaphore a thread acquires before it exits"};
    return released;
}

void Machine::print(uint32_t id, uint32_t address, uint32_t length, uint8_t* local) {
    if (length > kMaxPrintBytes)
        throw GuestFault{FaultKind::IllegalInstruction,
                         fmt::format("prints {} bytes at once; tp.print takes at most {}", length,
                                     kMaxPrintBytes),
                         "print through trax_printf, which hands over its text in pieces"};
    std::string bytes(length, '\0');
    for (uint32_t i = 0; i < length; ++i)
        bytes[i] = char(memory_.load<uint8_t>(address + i, local));
    output_.append(id, bytes);
}

void Machine::refuse_step(uint32_t id) {
    if (id >= thread_count())
        throw Error(
            fmt::format("step(): there is no thread {} (the machine has {})", id, thread_count()));
    if (threads_[id].state != ThreadState::Running)
        throw Error(fmt::format("step(): thread {} is not running; the timing model must stop "
                                "issuing from exited threads",
                                id));
    limit_fault(id);
}

StepRecord Machine::step(uint32_t id) {
    StepRecord record;
    uint32_t done = 0, first_held = 0;
    run_ahead(id, &record, 1, done, first_held);
    if (first_held == 0) hold_store(id, record);  // timing mode: a store happens at its step
    return record;
}

}  // namespace tpsim::core
