// Rejected: virtual functions need vtables (indirect calls TRaX kernels do not have).
#include "trax.hpp"

struct Shape {
    virtual float area() const = 0;
};
struct Square : Shape {
    float side = 2.0f;
    float area() const override { return side * side; }
};

// noinline keeps the call virtual, as it would be in a real kernel with several shapes.
__attribute__((noinline)) float area_of(const Shape& s) {
    return s.area();
}

void trax_main() {
    Square square;
    storef(area_of(square), trax_framebuffer());
}
