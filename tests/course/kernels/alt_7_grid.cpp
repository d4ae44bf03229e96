// A second solution of assignment 7, written from the starter's TODOs as a student would
// (course/assignments/7-grid/starter.cpp, its walk filled in), so the checker's budget is seen
// to accept a correct 3D-DDA that is not tpsim's own: its cell faces are lo + cell / scale, not
// lo + cell * cell size, and it tests the cell's triangles in its own loop.
#include "rt.hpp"

TRAX_USES_GRID;

using namespace trax::rt;

struct Grid {
    int triangles, cells, refs;
    float lo[3], hi[3];
    float scale[3];  // cells per unit length: res / (hi - lo)
    int res[3];

    static Grid from_scene() {
        const int record = loadi(0, kHeaderAccel);
        Grid g;
        g.triangles = trax_triangles();
        g.cells = loadi(record, kAccelNodes);
        g.refs = loadi(record, kAccelRefs);
        for (int axis = 0; axis < 3; ++axis) {
            g.lo[axis] = loadf(record, kAccelBoundsMin + axis);
            g.hi[axis] = loadf(record, kAccelBoundsMax + axis);
            g.scale[axis] = loadf(record, kAccelScale + axis);
            g.res[axis] = loadi(record, kAccelResolution + axis);
        }
        return g;
    }

    /// Tests the triangles of cell (x, y, z), number x + res[0] * (y + res[1] * z), keeping the
    /// closest hit in `hit`. True when kAnyHit and one was found: the ray is done.
    template <bool kAnyHit>
    bool test_cell(int x, int y, int z, const ShearedRay& ray, Hit& hit, RayStats& stats) const {
        ++stats.nodes_visited;
        const int cell = cells + x + res[0] * (y + res[1] * z);
        const int end = loadi(cell, 1);
        for (int i = loadi(cell, 0); i < end; ++i) {
            const int triangle = loadi(refs + i, 0);
            ++stats.triangles_tested;
            TriangleHit found;
            if (intersect(ray, triangles + triangle * kTriangleWords, hit.t, found)) {
                record<kAnyHit>(hit, triangle, found);
                if (kAnyHit) return true;
            }
        }
        return false;
    }

    /// The closest hit with 0 < t < t_max (kAnyHit: any hit) of origin + t * dir.
    template <bool kAnyHit> Hit trace(Vec3 origin, Vec3 dir, float t_max, RayStats& stats) const {
        Hit hit;
        hit.t = t_max;
        if (!valid_ray(origin, dir, t_max)) return hit;
        const float o[3] = {origin.x, origin.y, origin.z};
        const float d[3] = {dir.x, dir.y, dir.z};
        const float inv[3] = {1.0f / dir.x, 1.0f / dir.y, 1.0f / dir.z};
        // The part of the ray inside the grid's box: t in [t_enter, t_leave].
        float t_enter = 0.0f, t_leave = t_max;
        if (!clip_to_box(o, inv, lo, hi, t_enter, t_leave)) return hit;
        const ShearedRay ray = shear(origin, dir);

        int cell[3], step[3];
        float t_next[3];
        for (int axis = 0; axis < 3; ++axis) {
            float f = (o[axis] + d[axis] * t_enter - lo[axis]) * scale[axis];
            const float last = static_cast<float>(res[axis] - 1);
            f = f < 0.0f ? 0.0f : f > last ? last : f;
            cell[axis] = static_cast<int>(f);
            step[axis] = d[axis] > 0.0f ? 1 : d[axis] < 0.0f ? -1 : 0;
            t_next[axis] =
                step[axis] == 0 ? 3.0e38f : exit_of(axis, cell[axis], step[axis], o, inv);
        }
        for (;;) {
            if (test_cell<kAnyHit>(cell[0], cell[1], cell[2], ray, hit, stats)) return hit;
            int axis = 0;
            if (t_next[1] < t_next[axis]) axis = 1;
            if (t_next[2] < t_next[axis]) axis = 2;
            if (t_next[axis] >= hit.t || t_next[axis] > t_leave) return hit;
            cell[axis] += step[axis];
            if (cell[axis] < 0 || cell[axis] >= res[axis]) return hit;
            t_next[axis] = exit_of(axis, cell[axis], step[axis], o, inv);
        }
    }

    /// Where the ray leaves cell `c` on `axis`, going the way `step` says.
    float exit_of(int axis, int c, int step, const float* o, const float* inv) const {
        const float face = lo[axis] + static_cast<float>(step > 0 ? c + 1 : c) / scale[axis];
        return (face - o[axis]) * inv[axis];
    }
};

void trax_main() {
    render_image(Grid::from_scene());
}
