#include "sim/scene/cells.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>

namespace tpsim::scene {

Aabb padded_cells_box(std::span<const Triangle> triangles, std::string_view structure) {
    if (triangles.empty())
        throw std::invalid_argument(fmt::format("{}: the scene has no triangles", structure));
    glm::vec3 lo(std::numeric_limits<float>::infinity()), hi(-lo);
    for (const Triangle& t : triangles)
        for (const glm::vec3& v : {t.v0, t.v1, t.v2}) {
            if (!glm::all(glm::lessThanEqual(glm::abs(v), glm::vec3(1e18f))))
                throw std::invalid_argument(
                    fmt::format("{}: a vertex is beyond +-1e18 (or NaN)", structure));
            lo = glm::min(lo, v);
            hi = glm::max(hi, v);
        }
    const glm::vec3 extent = hi - lo;
    const float longest = std::max({extent.x, extent.y, extent.z});
    const float pad = longest > 0 ? longest * 1e-4f : 1.0f;
    Aabb box;
    box.lo = lo - glm::vec3(pad) - glm::abs(lo) * 1e-6f;
    box.hi = hi + glm::vec3(pad) + glm::abs(hi) * 1e-6f;
    return box;
}

}  // namespace tpsim::scene
