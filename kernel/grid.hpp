// Uniform-grid traversal: the 3D-DDA of Amanatides and Woo, "A Fast Voxel Traversal Algorithm
// for Ray Tracing" (Eurographics 1987), over the grid tpsim lays out for kernels that declare
// TRAX_USES_GRID (scene_layout.hpp AccelRecord, kAccelGrid). A drop-in for BvhTraversal: the
// same trace(), the same watertight triangle test, so the image is the BVH tracer's.
#pragma once
#include "rt.hpp"

namespace trax::rt {

/// kStopAtHit = false is the course experiment without the early stop: every ray walks on to
/// the far side of the grid, whatever it hit (course/experiments/grid_no_early_stop.cpp).
template <bool kStopAtHit = true> struct BasicGridTraversal {
    int triangles, cells, refs;
    Vec3 lo, hi, scale, cell_size;
    int res_x, res_y, res_z;

    static BasicGridTraversal from_scene() {
        const int record = loadi(0, kHeaderAccel);
        BasicGridTraversal g;
        g.triangles = trax_triangles();
        g.cells = loadi(record, kAccelNodes);
        g.refs = loadi(record, kAccelRefs);
        g.lo = load_vec3(record, kAccelBoundsMin);
        g.hi = load_vec3(record, kAccelBoundsMax);
        g.scale = load_vec3(record, kAccelScale);
        g.res_x = loadi(record, kAccelResolution);
        g.res_y = loadi(record, kAccelResolution + 1);
        g.res_z = loadi(record, kAccelResolution + 2);
        g.cell_size = {(g.hi.x - g.lo.x) / static_cast<float>(g.res_x),
                       (g.hi.y - g.lo.y) / static_cast<float>(g.res_y),
                       (g.hi.z - g.lo.z) / static_cast<float>(g.res_z)};
        return g;
    }

    /// The closest (or any) hit with 0 < t < t_max. The ray is clipped to the grid's box with
    /// the robust slab test (rt.hpp), then walks the cells it crosses in order, testing each
    /// cell's triangles; it stops once the closest hit so far lies before the current cell's
    /// exit. A triangle in several cells is tested in each (no mailbox: a thread has no memory
    /// to spare for one). Each cell face's distance is computed from the face's position rather
    /// than by adding the cell's width along the ray (the paper's tDelta), so rounding does not
    /// accumulate over a long walk; the rest of the rounding (where the ray enters, which face it
    /// leaves by) is covered by the builder listing each triangle in the cells within a margin
    /// of its box (sim/scene/grid.hpp). RayStats::nodes_visited counts the cells visited.
    template <bool kAnyHit> Hit trace(Vec3 origin, Vec3 dir, float t_max, RayStats& stats) const {
        Hit hit;
        hit.t = t_max;
        if (!valid_ray(origin, dir, t_max)) return hit;
        const Vec3 inverse{1.0f / dir.x, 1.0f / dir.y, 1.0f / dir.z};
        // The segment inside the box, [t_enter, t_leave].
        float t_enter = 0.0f, t_leave = t_max;
        const float o[3] = {origin.x, origin.y, origin.z};
        const float d[3] = {dir.x, dir.y, dir.z};
        const float inv[3] = {inverse.x, inverse.y, inverse.z};
        const float box_lo[3] = {lo.x, lo.y, lo.z}, box_hi[3] = {hi.x, hi.y, hi.z};
        if (!clip_to_box(o, inv, box_lo, box_hi, t_enter, t_leave)) return hit;

        const ShearedRay r = shear(origin, dir);
        const float sc[3] = {scale.x, scale.y, scale.z};
        const int res[3] = {res_x, res_y, res_z};
        int cell[3], step[3];
        float t_next[3];
        for (int axis = 0; axis < 3; ++axis) {
            // Clamped as a float, so an infinite or NaN position (an infinite origin) converts to
            // the same cell on the simulator and on the host.
            const float last = static_cast<float>(res[axis] - 1);
            float f = (o[axis] + d[axis] * t_enter - box_lo[axis]) * sc[axis];
            f = f > 0.0f ? f : 0.0f;
            f = f < last ? f : last;
            const int c = static_cast<int>(f);
            cell[axis] = c;
            step[axis] = d[axis] > 0.0f ? 1 : d[axis] < 0.0f ? -1 : 0;
            t_next[axis] = step[axis] == 0 ? 3.0e38f : face_distance(axis, c, step[axis], o, inv);
        }
        for (;;) {
            ++stats.nodes_visited;
            const int index = cell[0] + res[0] * (cell[1] + res[1] * cell[2]);
            const int end = loadi(cells + index, 1);
            for (int i = loadi(cells + index, 0); i < end; ++i) {
                const int triangle = loadi(refs + i, 0);
                ++stats.triangles_tested;
                TriangleHit found;
                if (intersect(r, triangles + triangle * kTriangleWords, hit.t, found)) {
                    record<kAnyHit>(hit, triangle, found);
                    if (kAnyHit) return hit;
                }
            }
            const int axis = t_next[0] < t_next[1] ? (t_next[0] < t_next[2] ? 0 : 2)
                                                   : (t_next[1] < t_next[2] ? 1 : 2);
            const float t_exit = t_next[axis];
            // Done when the closest hit so far lies in this cell (or no nearer cell can hold
            // one), or the segment ends in it. A NaN distance never stops the walk early; the
            // walk still ends, as every step moves one cell towards the box's far side.
            if ((kStopAtHit && t_exit >= hit.t) || t_exit > t_leave) return hit;
            cell[axis] += step[axis];
            if (cell[axis] < 0 || cell[axis] >= res[axis]) return hit;
            t_next[axis] = face_distance(axis, cell[axis], step[axis], o, inv);
        }
    }

private:
    /// Distance along the ray to the face through which it leaves cell `c` on `axis`.
    [[gnu::always_inline]] float face_distance(int axis, int c, int step, const float* o,
                                               const float* inv) const {
        const float box_lo = axis == 0 ? lo.x : axis == 1 ? lo.y : lo.z;
        const float size = axis == 0 ? cell_size.x : axis == 1 ? cell_size.y : cell_size.z;
        const float face = box_lo + static_cast<float>(step > 0 ? c + 1 : c) * size;
        return (face - o[axis]) * inv[axis];
    }
};

using GridTraversal = BasicGridTraversal<>;

}  // namespace trax::rt
