// Assignment 7: the uniform grid (docs/course/7-grid.md).
//
// tpsim builds the grid when the kernel says TRAX_USES_GRID: the scene's box cut into
// res[0] x res[1] x res[2] equal cells, each listing the triangles whose bounding box overlaps
// it. The shading, the triangle test and the pixel loop are rt.hpp's (as in assignment 4);
// reading the grid, clipping the ray to its box and testing one cell's triangles are given.
// `trace` is yours: as given it tests every cell of the grid for every ray (right, and far too
// slow). Make it walk only the cells the ray crosses, in the order it crosses them: the 3D-DDA
// of Amanatides and Woo.
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
        [[maybe_unused]] const float d[3] = {dir.x, dir.y, dir.z};  // for the walk
        const float inv[3] = {1.0f / dir.x, 1.0f / dir.y, 1.0f / dir.z};
        // The part of the ray inside the grid's box: t in [t_enter, t_leave].
        float t_enter = 0.0f, t_leave = t_max;
        if (!clip_to_box(o, inv, lo, hi, t_enter, t_leave)) return hit;
        const ShearedRay ray = shear(origin, dir);

        // TODO 1: find the cell the ray enters at t_enter. On each axis it is
        //   (o + d * t_enter - lo) * scale, clamped to [0, res - 1] while still a float (rounding
        //   may put the point a hair outside the box), then converted to int.
        // TODO 2: walk cell by cell. On each axis: step = +1, -1 or 0 by the sign of d, and
        //   t_next = where the ray leaves the current cell through its face on that axis,
        //   (face - o) * inv, the face at lo + (cell + 1) / scale going up, lo + cell / scale
        //   going down. Test the cell; then step on the axis with the smallest t_next; stop when
        //   that leaves the grid (cell < 0 or cell >= res) or t_next > t_leave.
        // TODO 3: stop early: once the closest hit so far lies before the current cell's exit
        //   (t_next >= hit.t on the axis you would step on), no later cell can hold a nearer one.
        for (int z = 0; z < res[2]; ++z)
            for (int y = 0; y < res[1]; ++y)
                for (int x = 0; x < res[0]; ++x)
                    if (test_cell<kAnyHit>(x, y, z, ray, hit, stats)) return hit;
        return hit;
    }
};

void trax_main() {
    render_image(Grid::from_scene());
}
