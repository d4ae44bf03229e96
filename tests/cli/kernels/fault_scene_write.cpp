// Writes into the scene (the camera record): the scene is read-only while a kernel runs, so the
// run must stop with a write-to-read-only fault (on the twin, a kernel fault naming the word).
#include "trax.hpp"

void trax_main() {
    storef(0.0f, trax_camera(), 0);
}
