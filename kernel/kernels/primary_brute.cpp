// Primary-ray casting by brute force: every ray is tested against every triangle. The reference
// the BVH tracer is checked against: same shading (kernel/rt.hpp), no acceleration structure,
// so the memory image holds no BVH.
#include "rt.hpp"

void trax_main() {
    trax::rt::render_image(trax::rt::BruteForce::from_scene());
}
