#include "sim/core/held_stores.hpp"

#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>

#include "sim/core/memory.hpp"

namespace tpsim::core {

HeldStores::HeldStores(uint32_t producers) : queues_(new Queue[producers]), producers_(producers) {}

void HeldStores::hold(uint32_t producer, const HeldStore& store) {
    Queue& queue = queues_[producer];
    std::lock_guard hold(queue.lock);
    if (!queue.stores.empty() && queue.stores.back().position > store.position)
        throw std::logic_error(
            fmt::format("HeldStores: producer {} holds a store at position {} after one at {}",
                        producer, store.position, queue.stores.back().position));
    queue.stores.push_back(store);
}

void HeldStores::write_through(uint64_t position, Memory& memory) {
    std::lock_guard writing(writing_);
    batch_.clear();
    for (uint32_t p = 0; p < producers_; ++p) {
        Queue& queue = queues_[p];
        std::lock_guard hold(queue.lock);
        const auto end =
            std::find_if(queue.stores.begin(), queue.stores.end(),
                         [&](const HeldStore& store) { return store.position > position; });
        batch_.insert(batch_.end(), queue.stores.begin(), end);
        queue.stores.erase(queue.stores.begin(), end);
    }
    // Stable: a producer's stores at one position stay in the order they were held.
    std::stable_sort(batch_.begin(), batch_.end(), [](const HeldStore& a, const HeldStore& b) {
        return a.position < b.position;
    });
    for (const HeldStore& store : batch_)
        memory.write(store.address, store.bytes, store.value);
}

size_t HeldStores::size() const {
    size_t held = 0;
    for (uint32_t p = 0; p < producers_; ++p) {
        std::lock_guard hold(queues_[p].lock);
        held += queues_[p].stores.size();
    }
    return held;
}

}  // namespace tpsim::core
